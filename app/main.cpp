// pneufem command-line interface (CLI11). Each subcommand validates its options at parse time
// and reports bad input as "error: ..." with the file/line/key and what to do (exit code 2);
// physics failures (inversion, limit point) exit with code 3 after writing what was computed.
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>

#include <CLI/CLI.hpp>

#include "app/compare/cli.h"
#include "app/diagnose/cli.h"
#include "app/simulate/command.h"
#include "app/sweep/command.h"
#include "app/synth/command.h"
#include "core/atomic_file.h"
#include "core/errors.h"
#include "core/version.h"
#include "engine/assembly.h"
#include "scenes/build_model.h"
#include "scenes/calculix_deck.h"
#include "viz/vtk_output.h"

namespace fs = std::filesystem;
using namespace pneufem;

namespace {

std::string join_args(int argc, char** argv) {
  std::string s;
  for (int i = 0; i < argc; ++i) s += (i ? " " : "") + std::string(argv[i]);
  return s;
}

int cmd_mesh(const std::string& scene_path, const std::vector<std::string>& sets, const std::string& out) {
  const Scene scene = Scene::load(scene_path, sets);
  const std::string ext = fs::path(out).extension().string();
  if (ext == ".inp") {
    std::unique_ptr<BuiltModel> bm = build_model(scene);
    write_file_atomic(out, calculix_deck(scene, *bm));
  } else if (ext == ".vtu") {
    std::unique_ptr<BuiltModel> bm = build_model(scene);
    const Assembler asmb(bm->model);
    const Eigen::VectorXd u = Eigen::VectorXd::Zero(bm->model.num_dofs());
    write_vtu(out, bm->model, compute_fields(asmb, u, asmb.initial_state()), 0.0, 0, 0.0, 0.0);
  } else {
    throw InputError("--out " + out + ": the mesh file must end in .vtu (ParaView) or .inp (Abaqus/CalculiX)");
  }
  const MeshStats st = compute_stats(build_mesh(scene));
  std::printf("wrote %s: %d nodes, %d %s elements\n", out.c_str(), st.nodes, st.elements, st.element_type.c_str());
  return 0;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"pneufem: simulate pneumatic soft actuators (pneu-nets), their fatigue, and why a model "
               "disagrees with measurements.\nUnits: SI inside; scene keys carry their unit in the name."};
  app.set_version_flag("--version", version_string());
  app.require_subcommand(1);

  std::string scene_path, out_dir, mesh_out;
  std::vector<std::string> sets;
  int threads = 0;

  CLI::App* sim = app.add_subcommand("simulate", "Run a scene (default: the built-in pneu-net) and write a run directory");
  sim->add_option("scene", scene_path, "Scene file (TOML); omit for the built-in default pneu-net")->check(CLI::ExistingFile);
  sim->add_option("--out", out_dir, "Output directory (created if needed)");
  sim->add_option("--set", sets, "Override a scene key, e.g. --set load.trials=10 (repeatable)");
  sim->add_option("--threads", threads, "Worker threads (default: all cores); results do not depend on it")
      ->check(CLI::Range(1, 1024));
  std::string resume_dir;
  double ckpt_every = 30.0;
  int abort_after = -1;
  sim->add_option("--resume", resume_dir,
                  "Continue a killed run in this directory from its checkpoint (uses its scene.toml; the final "
                  "results equal an uninterrupted run)");
  sim->add_option("--checkpoint-every", ckpt_every, "Wall-clock seconds between checkpoints (0 = after every segment)")
      ->check(CLI::NonNegativeNumber);
  sim->add_option("--abort-after-checkpoints", abort_after, "Testing aid: exit abruptly after N checkpoints")
      ->group("");
  std::string ideal_cache;
  sim->add_option("--ideal-cache", ideal_cache,
                  "Share the ideal elastic model of metrics.json between runs through this directory (keyed by "
                  "pneufem version, mesh and every scene key but the inelastic ones): the first run computes it, "
                  "later runs of the same actuator read it (pneufem sweep gives its points one)");

  CLI::App* mesh = app.add_subcommand("mesh", "Write the scene's mesh as .vtu (ParaView) or a runnable CalculiX deck .inp");
  mesh->add_option("scene", scene_path, "Scene file (TOML); omit for the built-in default pneu-net")->check(CLI::ExistingFile);
  mesh->add_option("--out", mesh_out, "Output file: FILE.vtu or FILE.inp")->required();
  mesh->add_option("--set", sets, "Override a scene key (repeatable)");

  CLI::App* sc = app.add_subcommand("scene", "Print the built-in default scene (every key, with units and comments)");
  bool defaults = false;
  sc->add_flag("--defaults", defaults, "Print the default scene (the default action)");

  CLI::App* sw = app.add_subcommand(
      "sweep", "Run a scene over a grid or Latin hypercube of scene-key values, one worker process per point; "
               "tabulate the metrics (sweep.csv) and plot them (sweep_<key>.svg). Re-running continues a sweep");
  SweepOptions sweep;
  sw->add_option("scene", sweep.scene_path, "Scene file (TOML); omit for the built-in default pneu-net")
      ->check(CLI::ExistingFile);
  sw->add_option("--param", sweep.params,
                 "KEY=LO:HI:N[:log]: sweep a numeric scene key over N values from LO to HI, evenly or log spaced, "
                 "e.g. materials.silicone.fatigue.tau_s=100:1000:5:log (repeatable; the grid is their product)")
      ->required()
      ->check(CLI::Validator(
          [](std::string& spec) {
            try {
              parse_param_spec(spec);
              return std::string();
            } catch (const InputError& e) {
              return std::string(e.what()).substr(8);  // CLI11 adds the "--param: " itself
            }
          },
          "KEY=LO:HI:N[:log]"));
  sw->add_option("--lhs", sweep.lhs, "Latin-hypercube design of N samples over the --param ranges instead of the grid "
                                     "(each --param's N is then ignored and may be left out)")
      ->check(CLI::Range(1, 100000));
  sw->add_option("--seed", sweep.seed, "Random seed of --lhs (same seed, same samples)")->capture_default_str();
  sw->add_option("--out", sweep.out_dir, "Sweep directory: points/NNNN/, sweep.csv, sweep_<key>.svg, sweep.json")
      ->required();
  sw->add_option("--jobs", sweep.jobs, "Worker processes at a time (default: number of cores); results do not depend on it")
      ->check(CLI::Range(1, 1024));
  sw->add_option("--threads-per-job", sweep.threads_per_job, "Threads of each worker process")
      ->check(CLI::Range(1, 1024))
      ->capture_default_str();
  sw->add_option("--set", sweep.sets, "Override a scene key at every point, e.g. --set load.trials=10 (repeatable)");
  sw->add_flag("--dry-run", sweep.dry_run, "List the points and exit without running them");

  CLI::App* sy = app.add_subcommand(
      "synth", "Synthetic measurements from a scene with hidden effects, sampled like the rig (pressure 400 Hz, "
               "angle 30 fps, controller overshoot, noise, outlier frames): OUT.csv, OUT.truth.csv, OUT.truth.json");
  SynthOptions synth;
  std::string hidden_spec;
  sy->add_option("scene", synth.scene_path, "Scene file (TOML); omit for the built-in default pneu-net")
      ->check(CLI::ExistingFile);
  sy->add_option("--hidden", hidden_spec,
                 "EFFECT[,EFFECT...] hidden at their truth values (candidates: stiffness, viscoelastic, mullins, "
                 "fatigue, pressure_lag, gravity and registered material effects), or none (the control dataset)")
      ->required();
  sy->add_option("--out", synth.out_csv, "Measurement CSV to write (canonical format); truth files go beside it")
      ->required();
  sy->add_option("--set", synth.sets, "Override a scene key, also a hidden effect's value (repeatable)");
  sy->add_option("--seed", synth.seed, "Random seed of the noise (same seed, same file)")->capture_default_str();
  sy->add_option("--threads", synth.threads, "Worker threads (default: all cores); results do not depend on it")
      ->check(CLI::Range(1, 1024));
  sy->add_option("--pressure-rate", synth.pressure_rate_Hz, "Pressure sampling rate (Hz)")->capture_default_str();
  sy->add_option("--angle-rate", synth.angle_rate_Hz, "Angle (video) frame rate (Hz)")->capture_default_str();
  sy->add_option("--controller-hz", synth.controller_hz, "Natural frequency of the inlet controller (Hz)")
      ->capture_default_str();
  sy->add_option("--controller-damping", synth.controller_damping,
                 "Damping ratio of the inlet controller, in (0, 1) (0.65: ~7 % overshoot, 0.3 s rise at 1 Hz)")
      ->capture_default_str();
  sy->add_option("--pressure-noise", synth.pressure_noise_kPa, "Pressure sensor white noise, 1 sigma (kPa)")
      ->capture_default_str();
  sy->add_option("--angle-noise", synth.angle_noise_deg, "Angle tracking white noise, 1 sigma (deg)")
      ->capture_default_str();
  sy->add_option("--outliers", synth.outlier_fraction, "Fraction of frames with a tracking failure (0 = none)")
      ->capture_default_str();
  sy->add_option("--report-every", synth.report_every_s, "Densest spacing of solved model states in holds (s)")
      ->capture_default_str();
  sy->add_option("--inlet-tolerance", synth.inlet_tolerance_kPa,
                 "Piecewise-linear fit of the true inlet pressure that drives the model (kPa)")
      ->capture_default_str();

  std::unique_ptr<CompareCommand> cmp = add_compare_command(app);
  std::unique_ptr<DiagnoseCommand> dia = add_diagnose_command(app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help / --version print and exit 0; a malformed command line is bad input: exit 2 like every
    // other input error (README, exit codes), not CLI11's own codes (105, 106, ...).
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }
  try {
    if (sim->parsed()) {
      RunOptions opt;
      if (!resume_dir.empty()) {
        if (!scene_path.empty() || !sets.empty())
          throw InputError("--resume continues a run with its own scene.toml; do not give a scene or --set");
        if (!out_dir.empty() && out_dir != resume_dir)
          throw InputError("--resume DIR writes into DIR; omit --out or give the same directory");
        out_dir = resume_dir;
        opt.resume = true;
      }
      if (out_dir.empty()) throw InputError("--out DIR is required (or --resume DIR)");
      opt.out_dir = out_dir;
      opt.checkpoint_every_s = ckpt_every;
      opt.abort_after_checkpoints = abort_after;
      opt.threads = threads;
      opt.ideal_cache_dir = ideal_cache;
      opt.progress = isatty(fileno(stderr));
      opt.command_line = join_args(argc, argv);
      const Scene scene = opt.resume ? Scene::load("") : Scene::load(scene_path, sets);
      const RunResult r = run_simulation(scene, opt);
      std::printf("%zu states, %.1f s; results in %s (angles.csv, summary.json, results.pvd)\n", r.records.size(), r.wall_s,
                  out_dir.c_str());
      return 0;
    }
    if (cmp->cmd->parsed()) return run_compare_command(*cmp, join_args(argc, argv));
    if (dia->cmd->parsed()) return run_diagnose_command(*dia, join_args(argc, argv));
    if (sw->parsed()) {
      sweep.exe = fs::read_symlink("/proc/self/exe").string();
      sweep.command_line = join_args(argc, argv);
      const SweepResult r = run_sweep(sweep);
      if (sweep.dry_run) return 0;
      std::printf("sweep: %zu points, %d ok (%d skipped), %d failed, %.1f s; table %s\n", r.points.size(), r.ok, r.skipped,
                  r.failed, r.wall_s, (fs::path(sweep.out_dir) / "sweep.csv").c_str());
      if (r.failed > 0) std::fprintf(stderr, "error: %d of %zu points failed (their errors are in sweep.csv)\n", r.failed, r.points.size());
      return r.failed > 0 ? 1 : 0;
    }
    if (sy->parsed()) {
      synth.hidden = parse_hidden(hidden_spec);
      synth.command_line = join_args(argc, argv);
      const SynthResult r = run_synth(synth);
      std::printf("synth: %zu trial(s), %ld model states, %d outlier frames, %.1f s; wrote %s (+ .truth.csv, .truth.json)\n",
                  r.data.trials.size(), r.states, r.outliers, r.wall_s, synth.out_csv.c_str());
      return 0;
    }
    if (mesh->parsed()) return cmd_mesh(scene_path, sets, mesh_out);
    if (sc->parsed()) {
      std::cout << Scene::default_text();
      return 0;
    }
  } catch (const InputError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  } catch (const PhysicsError& e) {
    std::fprintf(stderr, "\nsimulation failed: %s\n", e.what());
    return 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
  return 0;
}
