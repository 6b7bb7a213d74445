#include "app/compare/cli.h"

#include <unistd.h>

#include <cstdio>
#include <filesystem>

#include "scenes/scene_settings.h"

namespace pneufem {

std::unique_ptr<CompareCommand> add_compare_command(CLI::App& app) {
  auto c = std::make_unique<CompareCommand>();
  c->cmd = app.add_subcommand(
      "compare",
      "Simulate a recording (every trial driven by its measured pressure) and compare the model's bending angle "
      "with the measured one: metrics.json/csv, figures, report.html; appends to DIR/history.jsonl");
  CLI::App* s = c->cmd;
  s->add_option("scene", c->scene_path, "Scene file (TOML); omit for the built-in default pneu-net; its [load] is "
                                        "replaced by the measured pressure")
      ->check(CLI::ExistingFile);
  s->add_option("--data", c->options.data_path,
                "Recording, canonical CSV with columns trial,time_s,pressure_kPa,angle_deg (see analysis/measurements.h; without pressure_kPa the scene's [load] drives the model)")
      ->required()
      ->check(CLI::ExistingFile);
  s->add_option("--dlc-map", c->options.dlc_map_path,
                "Angles from DeepLabCut tracks: a TOML map of body parts and one DeepLabCut CSV per trial (see "
                "app/compare/dlc_map.h); --data then needs only the pressure of the mapped trials: its header still names "
                "angle_deg, whose cells may be empty (a trial of --data without a map entry keeps its CSV angles)")
      ->check(CLI::ExistingFile);
  s->add_option("--out", c->options.out_dir, "Output directory (created if needed; history.jsonl there grows by one line)")
      ->required();
  s->add_option("--set", c->sets, "Override a scene key, e.g. --set mesh.h_mm=4 (repeatable)");
  s->add_option("--threads", c->options.threads, "Worker threads (default: all cores); results do not depend on it")
      ->check(CLI::Range(1, 1024));
  s->add_flag("--regions", c->options.regions,
              "Region sensitivity: re-simulate with each mesh region's stiffness x 0.9 and project the residual on it "
              "(one extra simulation per region)");
  s->add_option("--label", c->options.label, "Name of this model variant in the history (default: the scene file name)");
  s->add_option("--model", c->model,
                "full: the full FEM (on the default mesh ~1 h per trial of the paper's staircase with all effects on, "
                "~5 h for ten). reduced: the reduced-order model (docs/theory.md): its offline part (elastic path and "
                "basis: ~30-60 min on the default mesh, ~3 min at mesh.h_mm = 6) is cached in --cache and reused for "
                "any effect constants and protocol, then minutes for ten trials; every report is checked against the "
                "full residual and a run whose estimated error exceeds solver.reduced_check_deg is redone with the full "
                "FEM (metrics.json \"simulation\".\"model\" says which ran). Default: the scene's solver.model")
      ->check(CLI::IsMember({"full", "reduced"}));
  s->add_option("--cache", c->options.cache_dir,
                "Directory of the reduced model's offline part (default with the reduced model: DIR/cache, so every "
                "compare into one study directory reuses it)");
  return c;
}

int run_compare_command(CompareCommand& c, const std::string& command_line) {
  c.options.command_line = command_line;
  c.options.progress = isatty(fileno(stderr));
  c.options.progress_log_every_s = c.options.progress ? 0.0 : 60.0;  // a log gets a line a minute
  std::vector<std::string> sets = c.sets;
  if (!c.model.empty()) sets.push_back("solver.model=\"" + c.model + "\"");  // after --set: the option decides
  const Scene scene = Scene::load(c.scene_path, sets);
  if (solver_settings(scene).model == SolverSettings::Model::Reduced && c.options.cache_dir.empty())
    c.options.cache_dir = (std::filesystem::path(c.options.out_dir) / "cache").string();
  const CompareRunResult r = run_compare(scene, c.options);
  std::printf("compare: NRMSE %.4f (noise floor %.4f) over %zu trials, %ld states, model %s, %.1f s; report "
              "%s/report.html\n",
              r.comparison.nrmse, r.comparison.noise_floor_nrmse, r.comparison.trials.size(), r.drive.states,
              r.drive.model.c_str(), r.wall_s, c.options.out_dir.c_str());
  // Everything the run noted (converted columns, dropped outlier frames, a recording in another
  // convention) is in metrics.json and the report; on the terminal too, so nobody misses it.
  for (const std::string& w : r.warnings)
    if (w.rfind("the model run stopped early", 0) != 0) std::fprintf(stderr, "warning: %s\n", w.c_str());
  if (!r.drive.failure.empty()) {
    std::fprintf(stderr,
                 "\nsimulation failed: %s\n(the frames solved before are compared and written to %s, with "
                 "\"status\": \"incomplete\" in metrics.json)\n",
                 r.drive.failure.c_str(), c.options.out_dir.c_str());
    return 3;  // as every physical failure (README, exit codes)
  }
  return 0;
}

}  // namespace pneufem
