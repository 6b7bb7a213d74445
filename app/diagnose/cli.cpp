#include "app/diagnose/cli.h"

#include <unistd.h>

#include <cstdio>

#include "core/errors.h"

namespace pneufem {

std::unique_ptr<DiagnoseCommand> add_diagnose_command(CLI::App& app) {
  auto c = std::make_unique<DiagnoseCommand>();
  c->cmd = app.add_subcommand(
      "diagnose",
      "Which physical effect is the model missing? Adds each candidate effect (stiffness, viscoelastic, viscoelastic_instantaneous, viscoelastic_broad, mullins, "
      "fatigue, fatigue_saturating, pressure_lag, gravity, registered effects) to the scene, calibrates it against the measurements, ranks "
      "them by the error they remove with an information criterion, and writes diagnosis.json, fitted.toml and report.md");
  c->cmd->add_option("scene", c->scene_path, "Scene file (TOML); omit for the built-in default pneu-net")
      ->check(CLI::ExistingFile);
  c->cmd->add_option("--data", c->options.data_path, "Measurements: canonical CSV trial,time_s,pressure_kPa,angle_deg (without pressure_kPa the scene's [load] drives the model)")
      ->required()
      ->check(CLI::ExistingFile);
  c->cmd->add_option("--out", c->options.out_dir, "Output directory (diagnosis.json, fitted.toml, report.md, diagnosis.csv, calibration.csv, history.jsonl)")
      ->required();
  c->cmd->add_option("--set", c->sets, "Override a scene key, e.g. --set mesh.h_mm=4 (repeatable)");
  c->cmd->add_option("--candidates", c->candidates, "Comma-separated candidate effects to try (default: all)");
  c->cmd->add_option("--max-effects", c->options.max_effects,
                     "Greedy forward selection: the rounds go on while an effect passes the tests, at most this many "
                     "(each round costs about what round 1 did)")
      ->check(CLI::Range(1, 6))
      ->capture_default_str();
  c->cmd->add_option("--evaluations", c->options.max_evaluations, "Reduced-model runs per candidate calibration")
      ->check(CLI::Range(5, 1000))
      ->capture_default_str();
  c->cmd->add_option("--aic-threshold", c->options.aic_threshold, "A candidate must lower the AIC by at least this")
      ->capture_default_str();
  c->cmd->add_option("--min-removed", c->options.min_removed,
                     "... and remove at least this fraction of the squared error above the noise floor")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  c->cmd->add_option("--min-static-change", c->options.min_static_change,
                     "An effect without history (stiffness, gravity) is named only when it moves the model's angle by at "
                     "least this fraction of the angle range (RMS): a smaller static misfit is the elastic model's accuracy, "
                     "to calibrate, not a missing effect (ignored with --trust-elastic-model)")
      ->check(CLI::Range(0.0, 1.0))
      ->capture_default_str();
  c->cmd->add_flag_callback(
      "--no-intervals", [o = &c->options] { o->intervals = false; },
      "Skip the joint intervals of the selected constants after each round (by default: the range of each constant, "
      "the others re-adjusting, within 25 % of the fit's RSS, and whether the recording identifies it; about 11 path-model "
      "runs for one effect's two constants, 30 for two effects' four)");
  c->cmd->add_flag_callback(
      "--all-rounds", [o = &c->options] { o->stop_at_noise_floor = false; },
      "Run every forward-selection round, even when the residual is already at the noise floor");
  c->cmd->add_flag_callback(
      "--no-growth-round", [o = &c->options] { o->growth_round = false; },
      "Skip the growth round: by default, when the final residual's top holds grow over the trials significantly "
      "beyond its rests (3 standard errors) and no fatigue is selected, the fatigue forms are tried once more on the "
      "RSS weighed with that growth's evidence (up to 2 calibrations per form)");
  c->cmd->add_flag("--trust-elastic-model", c->options.trust_elastic_model,
                   "The elastic response is known to be right (converged mesh of the measured geometry, calibrated "
                   "material): an effect after the first may then be one that only corrects the static angle curve "
                   "(stiffness, gravity). Default: it must explain error beyond a static misfit, which a coarse mesh "
                   "or an approximate geometry leaves too");
  c->cmd->add_option("--rom-points", c->options.rom_points, "Material points of the reduced model")
      ->check(CLI::Range(100, 10000000))
      ->capture_default_str();
  c->cmd->add_flag("--verify", c->options.verify, "Also run the baseline and the fitted scene with the full FEM");
  c->cmd->add_option("--refine", c->options.refine,
                     "Corrections of the selected effects' constants by the accurate model (--refine-model; space "
                     "mapping: N corrections cost N + 1 runs of the recording). The path model that selects the effects "
                     "biases damage constants (mullins, fatigue) up to ~2x; 0 = the path model's constants")
      ->check(CLI::Range(0, 5))
      ->capture_default_str();
  c->cmd->add_option_function<std::string>(
         "--refine-model",
         [o = &c->options](const std::string& m) {
           o->refine_model = m == "full" ? DiagnoseOptions::RefineModel::Full : DiagnoseOptions::RefineModel::Reduced;
         },
         "reduced (default): the reduced-order model of the calibration mesh (one offline part per actuator, "
         "~2-5 min at h = 6 and kept in --cache, then ~1 min per run of a ten-trial recording); full: the full FEM of "
         "the scene's mesh (~1 h per trial with damage on the default mesh), followed by a full-FEM check of the "
         "baseline as --verify")
      ->check(CLI::IsMember({"reduced", "full"}));
  c->cmd->add_option("--fem-calibrate", c->options.fem_calibration_runs,
                     "Then calibrate the selected effects' constants directly on the full FEM, locally from the "
                     "reduced-model (or refined) ones, with at most this many FEM runs per effect (~20 for two "
                     "constants); for effects the reduced model misjudges (fatigue)")
      ->check(CLI::Range(0, 200))
      ->capture_default_str();
  c->cmd->add_option("--calibration-h", c->options.calibration_h_mm,
                     "Calibrate on the built-in mesher at this element size (mm, e.g. 6) instead of the scene's mesh, "
                     "with an elastic correction from one static sweep of the scene's mesh: for large meshes "
                     "(BENCHMARKS.md: same ranking as the default mesh); --verify/--refine/--fem-calibrate and "
                     "fitted.toml keep the scene's mesh. Default: 3x the scene's element size when its built-in mesh "
                     "has more than 50k dof (the default actuator: 6), else the scene's mesh; 0 = the scene's mesh")
      ->check(CLI::Range(0.0, 1000.0));
  c->cmd->add_option("--cache", c->options.cache_dir,
                     "Keep the elastic FEM work that depends only on the actuator (the reduced model's elastic path, "
                     "the scene mesh's sweep, static curves with gravity) in this directory and reuse it in later runs "
                     "on the same actuator and protocol (keyed by the protocol's peak pressure, not a recording's noisy "
                     "one): identical results (the default scene: 527 s, re-run 50 s)");
  c->cmd->add_flag("--progress", c->progress, "Report each calibration on stderr (default: only when stderr is a terminal)");
  c->cmd->add_option("--threads", c->options.threads, "Worker threads (default: all cores); results do not depend on it")
      ->check(CLI::Range(1, 1024));
  return c;
}

int run_diagnose_command(DiagnoseCommand& c, const std::string& command_line) {
  c.options.command_line = command_line;
  c.options.progress = c.progress || isatty(2);
  c.options.candidates.clear();
  std::string cur;
  for (char ch : c.candidates + ",") {
    if (ch == ',') {
      if (!cur.empty()) c.options.candidates.push_back(cur);
      cur.clear();
    } else if (ch != ' ') {
      cur += ch;
    }
  }
  const Scene scene = Scene::load(c.scene_path, c.sets);
  const DiagnosisResult r = run_diagnosis(scene, c.options);
  std::printf("diagnose: baseline NRMSE %.4f (noise floor %.4f)\n", r.baseline_nrmse, r.noise_floor_nrmse);
  for (const CandidateResult& k : r.candidates) {
    std::string bound;
    for (const std::string& n : k.at_bound) bound += (bound.empty() ? "  (at the edge of its range: " : ", ") + n;
    if (!bound.empty()) bound += ")";
    if (!k.error.empty()) {  // a candidate that could not be calibrated has no numbers to show
      std::printf("  round %d %-14s not calibrated: %s\n", k.round, k.effect.c_str(), k.error.c_str());
      continue;
    }
    std::printf("  round %d %-14s NRMSE %.4f  dAIC %10.1f  beyond static %.4f  %s%s\n", k.round, k.effect.c_str(), k.nrmse,
                k.delta_aic, k.nrmse_beyond_static, k.significant ? "significant" : "", bound.c_str());
  }
  if (const std::string k = selected_constants_text(r); !k.empty()) std::printf("constants of the selected effects:\n%s", k.c_str());
  for (const std::string& e : r.form_changes) std::printf("form changed: %s\n", e.c_str());
  for (const std::string& e : r.equivalents) std::printf("equally good: %s\n", e.c_str());
  for (const EquivalentModel& m : r.equivalent_models) std::printf("equivalent model: %s\n", equivalent_model_text(m, r).c_str());
  if (!r.static_note.empty()) std::printf("what is left: %s\n", r.static_note.c_str());
  if (r.verified_fitted_nrmse >= 0)
    std::printf("full FEM: baseline NRMSE %.4f, fitted NRMSE %.4f\n", r.verified_baseline_nrmse, r.verified_fitted_nrmse);
  if (!r.refined_model.empty()) {
    std::printf("refined with the %s model: NRMSE %.4f; per trial", r.refined_model == "full" ? "full FEM" : "reduced-order",
                r.refined_nrmse);
    for (double e : r.refined_nrmse_per_trial) std::printf(" %.4f", e);
    std::printf("\n");
  }
  if (!r.fem_error.empty()) std::printf("refinement/FEM: %s\n", r.fem_error.c_str());
  if (!r.missing_history_effect.empty() && r.missing_history_effect != r.missing_effect)
    std::printf("missing history effect: %s (after %s, which takes the larger, static part of the misfit)\n",
                r.missing_history_effect.c_str(), r.missing_effect.c_str());
  std::printf("missing effect: %s; selected: %zu; final NRMSE %.4f; %.1f s. Wrote %s/diagnosis.json, fitted.toml and report.md\n",
              r.missing_effect.empty() ? "none" : r.missing_effect.c_str(), r.selected.size(), r.final_nrmse, r.wall_s,
              c.options.out_dir.c_str());
  if (c.options.cache_dir.empty() && r.elastic_wall_s > 20.0)
    std::printf("note: %.0f s of this run was elastic FEM work that depends only on the actuator and the peak pressure; "
                "--cache DIR keeps it for re-runs (docs/commands.md, \"Re-runs\")\n",
                r.elastic_wall_s);
  return 0;
}

}  // namespace pneufem
