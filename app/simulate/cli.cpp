#include "app/simulate/cli.h"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "app/simulate/command.h"
#include "core/atomic_file.h"
#include "core/errors.h"
#include "engine/assembly.h"
#include "scenes/build_model.h"
#include "scenes/calculix_deck.h"
#include "scenes/scene.h"
#include "scenes/scene_reference.h"
#include "scenes/scene_settings.h"
#include "scenes/stl_scene.h"
#include "viz/vtk_output.h"

namespace pneufem {

namespace fs = std::filesystem;

std::unique_ptr<SimulateCommand> add_simulate_command(CLI::App& app) {
  auto c = std::make_unique<SimulateCommand>();
  CLI::App* sim = c->cmd =
      app.add_subcommand("simulate", "Run a scene (default: the built-in pneu-net) and write a run directory");
  sim->add_option("scene", c->scene_path, "Scene file (TOML); omit for the built-in default pneu-net")->check(CLI::ExistingFile);
  sim->add_option("--out", c->out_dir, "Output directory (created if needed)");
  sim->add_option("--set", c->sets, "Override a scene key, e.g. --set load.trials=10 (repeatable)");
  sim->add_option("--threads", c->threads, "Worker threads (default: all cores); results do not depend on it")
      ->check(CLI::Range(1, 1024));
  sim->add_option("--resume", c->resume_dir,
                  "Continue a killed run in this directory from its checkpoint (uses its scene.toml; the final "
                  "results equal an uninterrupted run). A checkpoint of another scene, mesh, protocol or build, "
                  "or a damaged one, is refused; a fresh simulate into the directory removes it");
  sim->add_option("--checkpoint-every", c->checkpoint_every_s, "Wall-clock seconds between checkpoints (0 = after every segment)")
      ->check(CLI::NonNegativeNumber);
  sim->add_option("--abort-after-checkpoints", c->abort_after_checkpoints, "Testing aid: exit abruptly after N checkpoints")
      ->group("");
  sim->add_option("--ideal-cache", c->ideal_cache_dir,
                  "Share the ideal elastic model of metrics.json between runs through this directory (keyed by "
                  "pneufem version, mesh and every scene key but the inelastic ones): the first run computes it, "
                  "later runs of the same actuator read it (pneufem sweep gives its points one)");
  sim->add_option("--cache", c->cache_dir,
                  "Store the reduced model's offline part (elastic path and basis; solver.model = \"reduced\") in this "
                  "directory and reuse it: the first run of an actuator builds it, later runs with any effect constants "
                  "read it");
  return c;
}

int run_simulate_command(SimulateCommand& c, const std::string& command_line) {
  RunOptions opt;
  std::string out_dir = c.out_dir;
  if (!c.resume_dir.empty()) {
    if (!c.scene_path.empty() || !c.sets.empty())
      throw InputError("--resume continues a run with its own scene.toml; do not give a scene or --set");
    if (!out_dir.empty() && out_dir != c.resume_dir)
      throw InputError("--resume DIR writes into DIR; omit --out or give the same directory");
    out_dir = c.resume_dir;
    opt.resume = true;
  }
  if (out_dir.empty()) throw InputError("--out DIR is required (or --resume DIR)");
  opt.out_dir = out_dir;
  opt.checkpoint_every_s = c.checkpoint_every_s;
  opt.abort_after_checkpoints = c.abort_after_checkpoints;
  opt.threads = c.threads;
  opt.ideal_cache_dir = c.ideal_cache_dir;
  opt.cache_dir = c.cache_dir;
  opt.progress = isatty(fileno(stderr));
  opt.progress_log_every_s = opt.progress ? 0.0 : 60.0;  // a log gets a line a minute
  opt.command_line = command_line;
  const Scene scene = opt.resume ? Scene::load("") : Scene::load(c.scene_path, c.sets);
  const RunResult r = run_simulation(scene, opt);
  std::printf("%s", top_angles_text(r.records).c_str());
  for (const std::string& w : r.warnings) std::printf("warning (also in summary.json): %s\n", w.c_str());
  std::printf("%zu states, %.1f s; results in %s (angles.csv, summary.json, results.pvd)\n", r.records.size(), r.wall_s,
              out_dir.c_str());
  return 0;
}

std::unique_ptr<MeshCommand> add_mesh_command(CLI::App& app) {
  auto c = std::make_unique<MeshCommand>();
  CLI::App* mesh = c->cmd = app.add_subcommand(
      "mesh", "Write the scene's mesh as .vtu (ParaView) or a runnable CalculiX deck .inp; or mesh your own actuator's "
              "closed surface: pneufem mesh model.stl --out mesh.vtu");
  mesh->add_option("scene", c->scene_path,
                   "Scene file (TOML), or an actuator's closed surface (.stl, .obj: the default scene with "
                   "mesh.source = \"stl\" and mesh.file = it); omit for the built-in default pneu-net")
      ->check(CLI::ExistingFile);
  mesh->add_option("--out", c->out, "Output file: FILE.vtu or FILE.inp")->required();
  mesh->add_option("--set", c->sets, "Override a scene key (repeatable)");
  return c;
}

namespace {

/// The mesh command's scene: a TOML file, or the default scene meshing a surface file.
Scene mesh_command_scene(const MeshCommand& c) {
  std::string ext = fs::path(c.scene_path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), ::tolower);
  if (ext != ".stl" && ext != ".obj") return Scene::load(c.scene_path, c.sets);
  std::vector<std::string> sets{"mesh.source=\"stl\"", "mesh.file=\"" + fs::absolute(c.scene_path).string() + "\""};
  sets.insert(sets.end(), c.sets.begin(), c.sets.end());
  return Scene::load("", sets);
}

}  // namespace

int run_mesh_command(const MeshCommand& c) {
  const std::string ext = fs::path(c.out).extension().string();
  if (ext != ".inp" && ext != ".vtu")
    throw InputError("--out " + c.out + ": the mesh file must end in .vtu (ParaView) or .inp (Abaqus/CalculiX)");
  const Scene scene = mesh_command_scene(c);
  std::unique_ptr<BuiltModel> bm = build_model(scene);
  if (ext == ".inp") {
    std::vector<std::string> notes;
    write_file_atomic(c.out, calculix_deck(scene, *bm, &notes));
    bm->warnings.insert(bm->warnings.end(), notes.begin(), notes.end());
  } else {
    const Assembler asmb(bm->model);
    const Eigen::VectorXd u = Eigen::VectorXd::Zero(bm->model.num_dofs());
    write_vtu(c.out, bm->model, compute_fields(asmb, u, asmb.initial_state()), 0.0, 0, 0.0, 0.0);
  }
  for (const std::string& w : bm->warnings) std::printf("note: %s\n", w.c_str());
  if (mesh_settings(scene).source == MeshSettings::Source::Stl) {
    StlMeshReport rep;
    (void)stl_scene_mesh(scene, nullptr, &rep);  // the report of the same (deterministic) mesh
    std::printf("%s", describe(rep).c_str());
  }
  const MeshStats& st = bm->stats;
  std::printf("wrote %s: %d nodes, %d %s elements\n", c.out.c_str(), st.nodes, st.elements, st.element_type.c_str());
  return 0;
}

std::unique_ptr<SceneCommand> add_scene_command(CLI::App& app) {
  auto c = std::make_unique<SceneCommand>();
  c->cmd = app.add_subcommand("scene", "Print the built-in default scene (every key, with units and comments)");
  CLI::Option* d = c->cmd->add_flag("--defaults", c->defaults, "Print the default scene (the default action)");
  c->cmd->add_flag("--reference", c->reference,
                   "Print the scene reference in Markdown: every key with its default, unit and meaning "
                   "(docs/scene_reference.md)")
      ->excludes(d);
  return c;
}

int run_scene_command(const SceneCommand& c) {
  std::cout << (c.reference ? scene_reference_markdown() : Scene::default_text());
  return 0;
}

}  // namespace pneufem
