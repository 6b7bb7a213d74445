// report.md of `pneufem diagnose` (app/diagnose/detail.h): the diagnosis for a person, in the order
// it was made — what was compared, the error per trial before and after, each round's candidates
// with their tests and the one chosen, and the reasons in words. Apart from output.cpp because it
// is prose and tables, not a schema; like it, it only formats a finished DiagnosisResult (the
// numbers are diagnosis.json's, printed to 4 decimals for NRMSEs and 3 for degrees).
#include <algorithm>
#include <cmath>
#include <string>

#include "app/compare/history.h"
#include "app/diagnose/command.h"
#include "app/diagnose/detail.h"
#include "app/diagnose/evaluator.h"
#include "core/version.h"
#include "scenes/scene_settings.h"

namespace pneufem::diagnose_detail {

namespace {

/// A table cell: Markdown would read a '|' inside it as a column break.
std::string cell(std::string text) {
  for (std::size_t i = text.find('|'); i != std::string::npos; i = text.find('|', i + 2)) text.replace(i, 1, "\\|");
  return text;
}

/// The i-th value of a per-trial array, or "–" where it has none.
std::string at(const std::vector<double>& v, std::size_t i, const char* f) { return i < v.size() ? fmt(f, v[i]) : "–"; }

/// A fraction in whole percent ("-1 %", "30 %"; never "-0 %").
std::string percent(double fraction) {
  const double v = std::round(100.0 * fraction);
  return fmt("%.0f %%", v == 0.0 ? 0.0 : v);
}

/// "name = value, ..." of a candidate's calibrated constants.
std::string constants(const CandidateResult& c) {
  std::string out;
  for (std::size_t j = 0; j < c.params.size() && j < c.param_names.size(); ++j)
    out += (j ? ", " : "") + c.param_names[j] + " = " + fmt("%.4g", c.params[j]);
  return out.empty() ? "–" : out;
}

/// "a + b + c".
std::string joined(const std::vector<std::string>& effects) {
  std::string e;
  for (const std::string& n : effects) e += (e.empty() ? "" : " + ") + n;
  return e;
}

std::string recording_section(const Recording& rec, const DiagnoseOptions& opt) {
  double peak_kPa = 0.0, longest_s = 0.0;
  std::size_t frames = 0;
  for (const TrialRecording& t : rec.trials) {
    for (double p : t.pressure_kPa.value) peak_kPa = std::max(peak_kPa, p);
    frames += t.angle_deg.t_s.size();
    if (!t.angle_deg.t_s.empty()) longest_s = std::max(longest_s, t.angle_deg.t_s.back() - t.angle_deg.t_s.front());
  }
  return "- Recording: `" + opt.data_path + "`: " + std::to_string(rec.trials.size()) + " trial(s), " + std::to_string(frames) +
         " angle frames, the longest trial " + fmt("%.1f", longest_s) + " s, peak pressure " + fmt("%.2f", peak_kPa) + " kPa.\n";
}

std::string scene_section(const Scene& scene, const PathModelEvaluator& rom, const DiagnoseOptions& opt) {
  const MeshSettings ms = mesh_settings(scene);
  std::string mesh = ms.source == MeshSettings::Source::PneuNet ? "built-in pneu-net, h = " + fmt("%g", ms.h_mm) + " mm"
                                                                : "deck `" + ms.file + "`";
  std::string out = "- Scene: hash `" + scene_hash(scene) + "` (its full text is in diagnosis.json), mesh " + mesh + ".\n";
  out += "- Calibrated with the reduced path model: " + std::to_string(rom.path().num_points()) + " material points, " +
         (opt.calibration_h_mm > 0.0 ? "on the built-in mesher at h = " + fmt("%g", opt.calibration_h_mm) +
                                           " mm through the scene mesh's elastic curve (scene mesh sweep: " + rom.fine_source() + "), "
                                     : std::string()) +
         "elastic path traced to " + fmt("%.1f", rom.path().path_pressure_Pa().back() * 1e-3) + " kPa for a peak of " +
         fmt("%.1f", rom.reference_peak_Pa() * 1e-3) + " kPa (path: " + rom.path_source() + ").\n";
  if (!opt.cache_dir.empty())
    out += "- Cache `" + opt.cache_dir + "`: elastic path " + rom.path_source() + "; static FEM curves " +
           std::to_string(rom.curves_from_cache()) + " from the cache, " + std::to_string(rom.curves_computed()) + " computed.\n";
  return out;
}

/// Baseline beside the final model, per trial, then the pooled values.
std::string per_trial_section(const DiagnosisResult& out) {
  std::string s = "## Error per trial\n\n";
  s += out.selected.empty() ? "Nothing was selected: the final model is the baseline.\n\n"
                            : "The final model is the scene plus " + joined(out.selected) + " (reduced model, the constants below).\n\n";
  s += "| trial | baseline NRMSE | final NRMSE | baseline RMSE (deg) | final RMSE (deg) |\n";
  s += "|---|---|---|---|---|\n";
  const std::size_t n = std::max(out.baseline_nrmse_per_trial.size(), out.final_nrmse_per_trial.size());
  for (std::size_t k = 0; k < n; ++k)
    s += "| " + std::to_string(k + 1) + " | " + at(out.baseline_nrmse_per_trial, k, "%.4f") + " | " +
         at(out.final_nrmse_per_trial, k, "%.4f") + " | " + at(out.baseline_rmse_deg_per_trial, k, "%.3f") + " | " +
         at(out.final_rmse_deg_per_trial, k, "%.3f") + " |\n";
  s += "| all | " + fmt("%.4f", out.baseline_nrmse) + " | " + fmt("%.4f", out.final_nrmse) + " | | |\n\n";
  s += "Noise floor (NRMSE the angle tracking noise alone leaves): " + fmt("%.4f", out.noise_floor_nrmse) + ".";
  if (!out.refined_model.empty()) {
    s += std::string("\n\nThe constants were refined with the ") +
         (out.refined_model == "full" ? "full FEM" : "reduced-order model") +
         " (space mapping, --refine); its error at the refined constants, per trial:";
    for (std::size_t k = 0; k < out.refined_nrmse_per_trial.size(); ++k)
      s += (k ? ", " : " ") + fmt("%.4f", out.refined_nrmse_per_trial[k]);
    s += " (all " + fmt("%.4f", out.refined_nrmse) + ").";
  }
  if (out.verified_fitted_nrmse >= 0.0)
    s += " Full FEM (--verify): baseline " + fmt("%.4f", out.verified_baseline_nrmse) + ", fitted " +
         fmt("%.4f", out.verified_fitted_nrmse) + ".";
  return s + "\n";
}

/// One round: the model it started from, the candidates with their tests, the choice, the reasons.
std::string round_section(const DiagnosisResult& out, int round) {
  std::string s = "## Round " + std::to_string(round) + "\n\n";
  const std::size_t before = static_cast<std::size_t>(round - 1);
  if (before == 0) {
    s += "Each candidate added to the baseline (NRMSE " + fmt("%.4f", out.baseline_nrmse) + ").\n\n";
  } else if (before <= out.after_round.size()) {
    s += "Each remaining candidate added to the baseline + " + joined(out.after_round[before - 1].effects) + " (NRMSE " + fmt("%.4f", out.after_round[before - 1].nrmse) +
         "); from this round on a candidate must also explain error beyond a static misfit of the angle curve.\n\n";
  }
  for (const RoundCost& c : out.round_costs)
    if (c.round == round)
      s += "Cost: " + std::to_string(c.candidates) + " candidates, " + std::to_string(c.runs) + " runs of the path model, " +
           fmt("%.1f", c.wall_s) + " s.\n\n";
  s += "| effect | constants | NRMSE | delta AIC | error removed | NRMSE beyond static | removed beyond static | significant |\n";
  s += "|---|---|---|---|---|---|---|---|\n";
  for (const CandidateResult& c : out.candidates) {
    if (c.round != round) continue;
    if (!c.error.empty()) {
      s += "| " + c.effect + " | " + cell(c.error) + " | – | – | – | – | – | no |\n";
      continue;
    }
    s += "| " + c.effect + " | " + cell(constants(c)) + " | " + fmt("%.4f", c.nrmse) + " | " + fmt("%.1f", c.delta_aic) + " | " +
         percent(c.removed) + " | " + fmt("%.4f", c.nrmse_beyond_static) + " | " +
         percent(c.removed_beyond_static) + " | " + (c.significant ? "yes" : "no") + " |\n";
  }
  if (before < out.selected.size()) {
    const auto chosen = std::find_if(out.candidates.begin(), out.candidates.end(),
                                     [&](const CandidateResult& c) { return c.round == round && c.effect == out.selected[before]; });
    s += "\nChosen: **" + out.selected[before] + "**" +
         (chosen != out.candidates.end() ? " with " + constants(*chosen) : std::string()) + ".";
    if (before < out.after_round.size()) {
      s += " NRMSE per trial with it:";
      for (std::size_t k = 0; k < out.after_round[before].nrmse_per_trial.size(); ++k)
        s += (k ? ", " : " ") + fmt("%.4f", out.after_round[before].nrmse_per_trial[k]);
      s += ".";
    }
    s += "\n";
    for (const RoundIntervals& ri : out.intervals) {
      if (ri.round != round || !ri.computed) continue;
      s += "\nJoint intervals of the constants selected so far (the fit within " + fmt("%.0f", 100.0 * ri.rss_tol) +
           " % of its RSS, the other constants re-adjusting; " + std::to_string(ri.evaluations) + " runs):";
      for (std::size_t j = 0; j < ri.constants.size(); ++j) {
        const ConstantInterval& c = ri.constants[j];
        s += (j ? "; " : " ") + c.effect + "." + c.name + " " + fmt("%.4g", c.value) + " (" + fmt("%.4g", c.lo) + " to " +
             fmt("%.4g", c.hi) + (c.identified ? ")" : ", not identified)");
      }
      s += ".\n";
    }
    for (const std::string& n : out.interval_notes)
      if (n.rfind("round " + std::to_string(round) + " ", 0) == 0) s += "\n**Moved:** " + n + ".\n";
  } else {
    s += "\nNo candidate is significant: the selection stops here.\n";
  }
  s += "\nWhy, per candidate:\n\n";
  for (const CandidateResult& c : out.candidates)
    if (c.round == round) s += "- **" + c.effect + "**: " + (c.error.empty() ? c.why : "calibration failed: " + c.error) + "\n";
  return s;
}

}  // namespace

std::string diagnosis_report(const Scene& scene, const Recording& rec, const PathModelEvaluator& rom,
                             const DiagnoseOptions& opt, const DiagnosisResult& out) {
  std::string s = "# pneufem diagnose: which effect is the model missing?\n\n";
  s += "pneufem " + version_string() + (opt.command_line.empty() ? std::string() : ", `" + opt.command_line + "`") + ", " +
       fmt("%.1f", out.wall_s) + " s.\n\n";
  s += "**Missing effect: " + (out.missing_effect.empty() ? std::string("none") : out.missing_effect) + "**";
  if (!out.missing_history_effect.empty() && out.missing_history_effect != out.missing_effect)
    s += "; missing history effect: **" + out.missing_history_effect + "** (after " + out.missing_effect +
         ", which takes the larger, static part of the misfit)";
  s += ". NRMSE " + fmt("%.4f", out.baseline_nrmse) + " -> " + fmt("%.4f", out.final_nrmse) + " (noise floor " +
       fmt("%.4f", out.noise_floor_nrmse) + ").\n\n";
  s += "## Recording and scene\n\n" + recording_section(rec, opt) + scene_section(scene, rom, opt) + "\n";
  s += per_trial_section(out) + "\n";
  int rounds = 0;
  for (const CandidateResult& c : out.candidates) rounds = std::max(rounds, c.round);
  for (int r = 1; r <= rounds; ++r) s += round_section(out, r) + "\n";
  s += "## Result\n\n";
  if (const std::string k = selected_constants_text(out); !k.empty()) {
    // Its lines are indented by two spaces for the console: list items here.
    s += "Constants of the selected effects (fitted.toml):\n\n";
    for (std::size_t b = 0, e; b < k.size(); b = e + 1) {
      e = k.find('\n', b);
      if (e == std::string::npos) e = k.size();
      const std::size_t first = k.find_first_not_of(' ', b);
      if (first < e) s += "- " + k.substr(first, e - first) + "\n";
    }
    s += "\n";
  }
  if (!out.stopped.empty()) s += "Stopped " + out.stopped + ".\n\n";
  for (const std::string& e : out.form_changes) s += "Form changed: " + e + ".\n\n";
  for (const std::string& e : out.equivalents) s += "Equally good: " + e + ".\n\n";
  for (const EquivalentModel& m : out.equivalent_models) s += "Equivalent model: " + equivalent_model_text(m, out) + ".\n\n";
  if (!out.static_note.empty()) s += "What is left: " + out.static_note + ".\n\n";
  if (out.baseline_growth.trials > 0) {
    // Where the angle grows over the trials: a creep grows the top holds and the rests alike, a
    // permanent softening (fatigue) the top holds only.
    const auto split = [](const GrowthSplit& g) {
      return fmt("%+.2f", g.top_deg) + " deg at the top holds, " + fmt("%+.2f", g.rest_deg) + " deg at rest (top minus rest " +
             fmt("%+.2f", g.difference_deg) + " +- " + fmt("%.2f", g.difference_se_deg) + " deg, " +
             (g.significant ? "significant" : "not significant") + ")";
    };
    s += "Growth over the " + std::to_string(out.baseline_growth.trials) +
         " trials after the first (measured - model): baseline " + split(out.baseline_growth) +
         (out.final_growth.trials > 0 && !out.selected.empty() ? "; final model " + split(out.final_growth) : std::string()) +
         ". A creep that recovers slower than the rests grows both, a permanent softening (fatigue) the top holds; a "
         "difference is significant at 3 standard errors (per trial, the angle noise's error of the means or their "
         "scatter about the line, whichever is larger).\n\n";
  }
  if (!out.growth_note.empty()) s += "What the growth left says: " + out.growth_note + ".\n\n";
  if (!out.fem_error.empty()) s += "Refinement / full FEM: " + out.fem_error + "\n\n";
  s += "## Files\n\n"
       "- `diagnosis.json`: every number of this report (schema in the README).\n"
       "- `fitted.toml`: the scene plus the selected effects; `pneufem compare fitted.toml --data " + opt.data_path +
       " --out DIR` draws the figures (diagnose draws none).\n"
       "- `diagnosis.csv`: one row per candidate and round; `calibration.csv`: every reduced-model evaluation.\n"
       "- `history.jsonl`: the baseline and the model after each round, with the NRMSE and RMSE per trial.\n";
  return s;
}

}  // namespace pneufem::diagnose_detail
