#include "app/sweep/cli.h"

#include <cstdio>
#include <filesystem>

#include "core/errors.h"

namespace pneufem {

namespace fs = std::filesystem;

std::unique_ptr<SweepCommand> add_sweep_command(CLI::App& app) {
  auto c = std::make_unique<SweepCommand>();
  SweepOptions& sweep = c->options;
  CLI::App* sw = c->cmd = app.add_subcommand(
      "sweep", "Run a scene over a grid or Latin hypercube of scene-key values, one worker process per point; "
               "tabulate the metrics (sweep.csv) and plot them (sweep_<key>.svg). Re-running continues a sweep");
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
  sw->add_option("--model", sweep.model,
                 "The model of every point: reduced (the reduced-order model: one offline part per actuator, ~25 min on the "
                 "default mesh, shared by the points through DIR/rom_cache; then seconds to minutes per point, checked at "
                 "every report, falling back to the full FEM above solver.reduced_check_deg), full (the full FEM: ~30 min "
                 "per trial on the default mesh with effects on), or auto: reduced when every point has the same elastic "
                 "reference (the swept keys are effect constants, gravity or protocol), else full. Overrides the scene's "
                 "solver.model")
      ->check(CLI::IsMember({"auto", "full", "reduced"}))
      ->capture_default_str();
  sw->add_option("--fem-points", sweep.fem_points,
                 "Comma-separated points (the point column of sweep.csv) to run again with the full FEM after a reduced "
                 "sweep, into DIR/points/NNNN/fem/; sweep.csv gets their FEM NRMSE and largest |reduced - FEM| angle")
      ->delimiter(',');
  sw->add_option("--set", sweep.sets, "Override a scene key at every point, e.g. --set load.trials=10 (repeatable)");
  sw->add_flag("--dry-run", sweep.dry_run,
               "List the points and exit without running them (with --scheduler slurm: print the sbatch script, submit nothing)");
  sw->add_option("--scheduler", sweep.scheduler,
                 "local: worker processes on this machine (--jobs); slurm: submit the points as one SLURM job array "
                 "(one task per point) and return; the same command again collects the finished points, resubmits "
                 "failed or missing ones and writes the table and plots. DIR must be on the cluster's shared file system")
      ->check(CLI::IsMember({"local", "slurm"}))
      ->capture_default_str();
  sw->add_option("--partition", sweep.slurm.partition, "SLURM partition of the job array (sbatch --partition)");
  sw->add_option("--time", sweep.slurm.time, "Time limit of each point's task, e.g. 2:00:00 (sbatch --time)");
  sw->add_option("--mem", sweep.slurm.mem, "Memory of each point's task, e.g. 4G (sbatch --mem)");
  sw->add_option("--account", sweep.slurm.account, "SLURM account charged (sbatch --account)");
  sw->add_option("--max-parallel", sweep.slurm.max_parallel, "Points running at once on the cluster (the array's %N)")
      ->check(CLI::Range(1, 100000));
  return c;
}

int run_sweep_command(SweepCommand& c, const std::string& command_line, const std::string& exe) {
  SweepOptions& sweep = c.options;
  sweep.exe = exe.empty() ? fs::read_symlink("/proc/self/exe").string() : exe;
  if (!fs::exists(sweep.exe))
    throw InputError("sweep: the pneufem binary that runs the points, " + sweep.exe + ", does not exist");
  sweep.command_line = command_line;
  const SweepResult r = run_sweep(sweep);
  if (sweep.dry_run) return 0;
  if (sweep.scheduler == "slurm") {
    std::printf("sweep: %zu points, %d ok, %d failed, %d queued or running; table %s\n", r.points.size(), r.ok, r.failed,
                r.pending, (fs::path(sweep.out_dir) / "sweep.csv").c_str());
    if (!r.submitted_jobs.empty()) {
      std::string jobs;
      for (const std::string& j : r.submitted_jobs) jobs += (jobs.empty() ? "" : ",") + j;
      std::printf("sweep: submitted %zu point(s) as SLURM job %s; run this command again when it has finished "
                  "(squeue -j %s) to collect them\n", r.submitted_points.size(), jobs.c_str(), jobs.c_str());
    } else if (r.pending > 0) {
      std::printf("sweep: nothing submitted; run this command again when the queued points have finished\n");
    }
    if (r.failed > 0)
      std::fprintf(stderr, "error: %d of %zu points failed (their errors are in sweep.csv; they were submitted again)\n",
                   r.failed, r.points.size());
    return r.failed > 0 ? 1 : 0;
  }
  std::printf("sweep: %zu points, %d ok (%d skipped), %d failed, %.1f s; table %s\n", r.points.size(), r.ok, r.skipped,
              r.failed, r.wall_s, (fs::path(sweep.out_dir) / "sweep.csv").c_str());
  if (r.failed > 0) std::fprintf(stderr, "error: %d of %zu points failed (their errors are in sweep.csv)\n", r.failed, r.points.size());
  if (r.fem_failed > 0)
    std::fprintf(stderr, "error: %d FEM re-run(s) of --fem-points failed (their errors are in sweep.csv)\n", r.fem_failed);
  return r.failed > 0 || r.fem_failed > 0 ? 1 : 0;
}

}  // namespace pneufem
