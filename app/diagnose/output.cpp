// The files a diagnosis writes (app/diagnose/detail.h; schema of diagnosis.json in the README):
// diagnosis.json, fitted.toml, diagnosis.csv (one row per candidate and round), calibration.csv
// (every evaluation of every calibration), report.md (its text is report.cpp's) and the history
// lines (the baseline and the model after each round, per trial). Apart from the diagnosis because
// it only formats a finished DiagnosisResult; nothing here changes a number.
#include <algorithm>
#include <cstdio>
#include <cmath>
#include <filesystem>

#include "app/compare/history.h"
#include "app/diagnose/command.h"
#include "app/diagnose/detail.h"
#include "app/diagnose/evaluator.h"
#include "core/atomic_file.h"
#include "core/json_writer.h"
#include "core/version.h"

namespace fs = std::filesystem;

namespace pneufem::diagnose_detail {

namespace {

/// A growth split (DiagnosisResult::baseline_growth, final_growth): the trials it is taken over and
/// the growth (deg) of measured - model at the top holds and at rest.
std::string growth_split_json(const GrowthSplit& g) {
  json::Object o;
  o.add("trials", g.trials).add("top_deg", g.top_deg).add("rest_deg", g.rest_deg);
  o.add("difference_deg", g.difference_deg).add("top_se_deg", g.top_se_deg).add("rest_se_deg", g.rest_se_deg);
  o.add("difference_se_deg", g.difference_se_deg).add("difference_significant", g.significant ? "true" : "false");
  return o.str(4);
}

/// diagnosis.json's "intervals": per round, each selected constant's value, interval and whether
/// the recording identifies it.
std::string intervals_json(const std::vector<RoundIntervals>& rounds) {
  std::string s = "[";
  for (std::size_t r = 0; r < rounds.size(); ++r) {
    const RoundIntervals& ri = rounds[r];
    std::string cs = "[";
    for (std::size_t j = 0; j < ri.constants.size(); ++j) {
      const ConstantInterval& c = ri.constants[j];
      json::Object o;
      o.add_str("effect", c.effect).add_str("name", c.name).add("value", c.value);
      if (ri.computed) o.add("lo", c.lo).add("hi", c.hi).add("identified", c.identified ? "true" : "false");
      cs += (j ? ",\n      " : "\n      ") + o.str(6);
    }
    json::Object o;
    o.add("round", ri.round).add("rss_within", ri.rss_tol).add("computed", ri.computed ? "true" : "false");
    o.add("evaluations", ri.evaluations).add("constants", cs + "\n    ]");
    s += (r ? ",\n    " : "\n    ") + o.str(4);
  }
  return s + (rounds.empty() ? "]" : "\n  ]");
}

/// diagnosis.json's model-equivalence report (equivalent_models, final_parameters) and the cost of
/// each round (round_costs).
void add_equivalence_and_costs(json::Object& root, const DiagnosisResult& out) {
  std::string em = "[";
  for (std::size_t j = 0; j < out.equivalent_models.size(); ++j) {
    const EquivalentModel& m = out.equivalent_models[j];
    std::string effects = "[", bound = "[";
    for (std::size_t i = 0; i < m.effects.size(); ++i) effects += (i ? ", " : "") + json::quote(m.effects[i]);
    for (std::size_t i = 0; i < m.at_bound.size(); ++i) bound += (i ? ", " : "") + json::quote(m.at_bound[i]);
    json::Object o;
    o.add("effects", effects + "]").add("round", m.round).add("parameters", m.parameters).add("nrmse", m.nrmse);
    o.add("at_bound", bound + "]").add_str("text", equivalent_model_text(m, out));
    em += (j ? ",\n    " : "\n    ") + o.str(4);
  }
  root.add("equivalent_models", em + (out.equivalent_models.empty() ? "]" : "\n  ]"));
  root.add("final_parameters", out.final_parameters);
  std::string rc = "[";
  for (std::size_t j = 0; j < out.round_costs.size(); ++j) {
    json::Object o;
    o.add("round", out.round_costs[j].round).add("candidates", out.round_costs[j].candidates);
    o.add("runs", static_cast<double>(out.round_costs[j].runs)).add("wall_s", out.round_costs[j].wall_s);
    rc += (j ? ", " : "") + o.str(4);
  }
  root.add("round_costs", rc + "]");
}

/// diagnosis.json's "candidates": one object per candidate and round.
std::string candidates_json(const std::vector<CandidateResult>& candidates) {
  std::string cs = "[";
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    const CandidateResult& c = candidates[i];
    json::Object p;
    for (std::size_t j = 0; j < c.params.size(); ++j) p.add(c.param_names[j], c.params[j]);
    json::Object o;
    o.add_str("effect", c.effect).add("round", c.round).add("nrmse", c.nrmse);
    o.add("nrmse_per_trial", json::array(c.nrmse_per_trial)).add("params", c.params.empty() ? "{}" : p.str(6));
    o.add("sets", json::strings(c.sets)).add("delta_aic", c.delta_aic).add("removed_fraction", c.removed);
    o.add("significant", c.significant ? "true" : "false").add("evaluations", c.evaluations).add("wall_s", c.wall_s);
    o.add_str("why", c.why);
    o.add("at_bound", json::strings(c.at_bound));
    o.add("nrmse_beyond_static", c.nrmse_beyond_static).add("delta_aic_beyond_static", c.delta_aic_beyond_static);
    o.add("removed_fraction_beyond_static", c.removed_beyond_static).add("beyond_static", c.beyond_static ? "true" : "false");
    if (c.static_change_nrmse >= 0.0) o.add("static_change_nrmse", c.static_change_nrmse);
    o.add("profiled", c.profiled ? "true" : "false");
    if (!c.refit_selected.empty()) o.add("refit_selected_params", json::array(c.refit_selected));
    if (!c.trade_lo.empty()) {
      json::Object ranges;
      for (std::size_t j = 0; j < c.trade_lo.size(); ++j) ranges.add(c.param_names[j], json::array({c.trade_lo[j], c.trade_hi[j]}));
      json::Object t;
      t.add("rss_within", c.trade_rss_tol).add("ranges", ranges.str(8));
      o.add("trade_off", t.str(6));
    }
    if (!c.error.empty()) o.add_str("error", c.error);
    cs += (i ? ",\n    " : "\n    ") + o.str(4);
  }
  return cs + "\n  ]";
}

/// diagnosis.json's method.calibration_mesh: the calibration mesh and its correction, so a reader
/// can judge its size against the effects'.
std::string calibration_mesh_json(const PathModelEvaluator& rom, const DiagnoseOptions& opt) {
  json::Object cm;
  const std::vector<double>& f = rom.fine_curve();
  const std::vector<double>& c = rom.coarse_curve();
  std::vector<double> p;
  for (std::size_t i = 0; i < f.size(); ++i)
    p.push_back(rom.reference_peak_Pa() * 1e-3 * static_cast<double>(i) / static_cast<double>(f.size() - 1));
  cm.add("h_mm", opt.calibration_h_mm).add("dofs", static_cast<double>(rom.dofs())).add("scene_dofs", static_cast<double>(rom.fine_dofs()));
  std::vector<double> m;
  for (double v : rom.pressure_map_Pa()) m.push_back(v * 1e-3);
  cm.add("pressure_kPa", json::array(p)).add("scene_mesh_angle_deg", json::array(f)).add("calibration_mesh_angle_deg", json::array(c));
  cm.add("mapped_pressure_kPa", json::array(m));
  cm.add_str("scene_mesh_sweep_source", rom.fine_source());
  return cm.str(4);
}

/// diagnosis.json's "method": the evaluator, its elastic path and cache, the calibration mesh and
/// the selection's settings and cost.
std::string method_json(const PathModelEvaluator& rom, const DiagnoseOptions& opt, const DiagnosisResult& out) {
  json::Object method;
  method.add_str("evaluator", "reduced path model (engine/path_model.h), " + std::to_string(rom.path().num_points()) +
                                  " material points, elastic path to " +
                                  fmt("%.1f", rom.path().path_pressure_Pa().back() * 1e-3) + " kPa");
  method.add("reference_peak_kPa", rom.reference_peak_Pa() * 1e-3);
  method.add_str("elastic_path_source", rom.path_source());
  method.add("static_curves_from_cache", rom.curves_from_cache()).add("static_curves_computed", rom.curves_computed());
  if (!opt.cache_dir.empty()) method.add_str("cache_dir", opt.cache_dir);
  if (opt.calibration_h_mm > 0.0) method.add("calibration_mesh", calibration_mesh_json(rom, opt));
  method.add("aic_threshold", opt.aic_threshold).add("min_removed", opt.min_removed).add("max_effects", opt.max_effects)
      .add("min_static_change", opt.min_static_change);
  method.add("trust_elastic_model", opt.trust_elastic_model ? "true" : "false");
  method.add("reduced_model_runs", static_cast<double>(out.rom_runs)).add("wall_s", out.wall_s);
  return method.str(2);
}

/// diagnosis.json's "refined_params": the constants the accurate model refined, per effect.
std::string refined_params_json(const ChosenEffects& chosen) {
  std::string rp = "{";
  for (std::size_t j = 0; j < chosen.size(); ++j) {
    json::Object p;
    for (std::size_t i = 0; i < chosen[j].first->params.size(); ++i) p.add(chosen[j].first->params[i].name, chosen[j].second[i]);
    rp += (j ? ", " : "") + json::quote(chosen[j].first->name) + ": " + p.str(4);
  }
  return rp + "}";
}

/// diagnosis.json, whole (schema in the README).
std::string diagnosis_json(const Scene& scene, const PathModelEvaluator& rom, const ChosenEffects& chosen,
                           const DiagnoseOptions& opt, const DiagnosisResult& out) {
  json::Object root;
  root.add_str("version", version_string());
  root.add_str("command", opt.command_line);
  root.add_str("data", opt.data_path);
  // A failed diagnosis (run_diagnosis's failure path) writes what it had done, saying so here.
  root.add_str("status", out.failure.empty() ? std::string("ok") : "failed: " + out.failure);
  json::Object b;
  b.add("nrmse", out.baseline_nrmse).add("nrmse_per_trial", json::array(out.baseline_nrmse_per_trial));
  b.add("rmse_deg_per_trial", json::array(out.baseline_rmse_deg_per_trial));
  if (out.verified_baseline_nrmse >= 0) b.add("nrmse_fem", out.verified_baseline_nrmse);
  if (out.baseline_growth.trials > 0) b.add("growth_split", growth_split_json(out.baseline_growth));
  root.add("baseline", b.str(2));
  root.add("candidates", candidates_json(out.candidates));
  root.add("missing_effect", out.missing_effect.empty() ? "null" : json::quote(out.missing_effect));
  root.add("missing_history_effect", out.missing_history_effect.empty() ? "null" : json::quote(out.missing_history_effect));
  if (!out.stopped.empty()) root.add("stopped", json::quote(out.stopped));
  root.add("equivalents", json::strings(out.equivalents));
  root.add("form_changes", json::strings(out.form_changes));
  add_equivalence_and_costs(root, out);
  root.add("selected", json::strings(out.selected));
  root.add("intervals", intervals_json(out.intervals));
  root.add("interval_notes", json::strings(out.interval_notes));
  if (!out.refined_params.empty()) root.add("refined_params", refined_params_json(chosen));
  if (!out.refined_model.empty()) {
    root.add_str("refined_model", out.refined_model);
    root.add("refined_nrmse", out.refined_nrmse);
    root.add("refined_nrmse_per_trial", json::array(out.refined_nrmse_per_trial));
  }
  root.add("noise_floor_nrmse", out.noise_floor_nrmse);
  root.add("final_nrmse", out.final_nrmse);
  root.add("final_nrmse_per_trial", json::array(out.final_nrmse_per_trial));
  root.add("final_rmse_deg_per_trial", json::array(out.final_rmse_deg_per_trial));
  if (out.verified_fitted_nrmse >= 0) root.add("final_nrmse_fem", out.verified_fitted_nrmse);
  if (out.final_growth.trials > 0) root.add("final_growth_split", growth_split_json(out.final_growth));
  if (!out.growth_note.empty()) root.add_str("growth_note", out.growth_note);
  json::Object sr;
  sr.add("nrmse", out.final_nrmse_beyond_static).add("share_of_excess", out.static_share).add_str("note", out.static_note);
  root.add("static_remainder", sr.str(2));
  if (!out.fem_error.empty()) root.add_str("fem_error", out.fem_error);
  root.add("method", method_json(rom, opt, out));
  root.add("scene", scene.to_json());
  return root.str() + "\n";
}

/// diagnosis.csv: one row per candidate and round.
std::string candidates_csv(const std::vector<CandidateResult>& candidates) {
  std::string csv = "round,effect,nrmse,delta_aic,removed_fraction,significant,evaluations,params,nrmse_beyond_static,beyond_static\n";
  for (const CandidateResult& c : candidates) {
    std::string p;
    for (std::size_t j = 0; j < c.params.size(); ++j) p += (j ? ";" : "") + c.param_names[j] + "=" + json::num(c.params[j]);
    csv += std::to_string(c.round) + "," + c.effect + "," + json::num(c.nrmse) + "," + json::num(c.delta_aic) + "," +
           json::num(c.removed) + "," + (c.significant ? "1" : "0") + "," + std::to_string(c.evaluations) + "," + p + "," +
           json::num(c.nrmse_beyond_static) + "," + (c.beyond_static ? "1" : "0") + "\n";
  }
  return csv;
}

/// calibration.csv: every evaluation of every calibration.
std::string calibration_csv(const std::vector<CandidateResult>& candidates) {
  std::string tr = "round,effect,evaluation,params,rss_deg2,error\n";
  for (const CandidateResult& c : candidates)
    for (std::size_t i = 0; i < c.trace.size(); ++i) {
      std::string p;
      for (std::size_t j = 0; j < c.trace[i].params.size(); ++j)
        p += (j ? ";" : "") + c.param_names[j] + "=" + json::num(c.trace[i].params[j]);
      std::string e = c.trace[i].error;
      std::replace(e.begin(), e.end(), '"', '\'');
      tr += std::to_string(c.round) + "," + c.effect + "," + std::to_string(i + 1) + "," + p + "," +
            (std::isfinite(c.trace[i].rss_deg2) ? json::num(c.trace[i].rss_deg2) : std::string("inf")) + ",\"" + e + "\"\n";
    }
  return tr;
}

/// The history lines: the baseline, then the model after each round (the path model's errors; the
/// last round carries fitted.toml's hash only without a refinement), then the refined model by the
/// model that refined it, each with the error per trial, so the fall shows trial by trial.
void append_diagnosis_history(const Scene& scene, const Scene& fitted, const DiagnoseOptions& opt, const DiagnosisResult& out) {
  HistoryEntry h;
  h.time_utc = utc_now();
  h.source = "diagnose";
  h.label = "diagnose baseline (path model)";
  h.scene_hash = scene_hash(scene);
  h.nrmse = out.baseline_nrmse;
  h.trial_nrmse = out.baseline_nrmse_per_trial;
  h.trial_rmse_deg = out.baseline_rmse_deg_per_trial;
  append_history(opt.out_dir, h);
  for (std::size_t i = 0; i < out.after_round.size(); ++i) {
    const ModelAfterRound& m = out.after_round[i];
    h.label = "diagnose";
    for (const std::string& e : m.effects) h.label += " + " + e;
    h.label += " (path model)";
    const bool last = i + 1 == out.after_round.size();
    h.scene_hash = last && out.refined_model.empty() ? scene_hash(fitted) : scene_hash(scene.with(m.sets));
    h.nrmse = m.nrmse;
    h.trial_nrmse = m.nrmse_per_trial;
    h.trial_rmse_deg = m.rmse_deg_per_trial;
    append_history(opt.out_dir, h);
  }
  if (!out.refined_model.empty()) {
    h.label = "diagnose, refined (" + std::string(out.refined_model == "full" ? "full FEM" : "reduced-order model") + ")";
    h.scene_hash = scene_hash(fitted);
    h.nrmse = out.refined_nrmse;
    h.trial_nrmse = out.refined_nrmse_per_trial;
    h.trial_rmse_deg.clear();
    append_history(opt.out_dir, h);
  }
}

}  // namespace

void write_diagnosis(const Scene& scene, const Scene& fitted, const Recording& rec, const PathModelEvaluator& rom,
                     const ChosenEffects& chosen, const DiagnoseOptions& opt, const DiagnosisResult& out) {
  fs::create_directories(opt.out_dir);
  const fs::path dir(opt.out_dir);
  write_file_atomic((dir / "diagnosis.json").string(), diagnosis_json(scene, rom, chosen, opt, out));
  write_file_atomic((dir / "fitted.toml").string(), out.fitted_toml);
  write_file_atomic((dir / "diagnosis.csv").string(), candidates_csv(out.candidates));
  write_file_atomic((dir / "calibration.csv").string(), calibration_csv(out.candidates));
  const std::string failed =
      out.failure.empty() ? std::string()
                          : "> **This diagnosis failed** after " + std::to_string(out.after_round.size()) +
                                " selected effect(s): " + out.failure +
                                ". What follows is what it had done before; the missing effect and fitted.toml are those "
                                "of the rounds that finished, not a result.\n\n";
  write_file_atomic((dir / "report.md").string(), failed + diagnosis_report(scene, rec, rom, opt, out));
  append_diagnosis_history(scene, fitted, opt, out);
}

}  // namespace pneufem::diagnose_detail

namespace pneufem {

bool constants_trade_off(const CandidateResult& c) {
  for (std::size_t j = 0; j < c.trade_lo.size() && j < c.trade_hi.size(); ++j)
    if (c.trade_hi[j] > 2.0 * c.trade_lo[j]) return true;
  return false;
}

std::string selected_constants_text(const DiagnosisResult& r) {
  struct Entry {
    const CandidateResult* c;
    std::vector<double> values;
    std::string how;  ///< "" = its own calibration (ranges apply)
  };
  std::vector<Entry> e;
  for (std::size_t i = 0; i < r.selected.size(); ++i) {
    const auto it = std::find_if(r.candidates.begin(), r.candidates.end(), [&](const CandidateResult& c) {
      return c.effect == r.selected[i] && c.round == static_cast<int>(i) + 1;
    });
    if (it == r.candidates.end()) continue;
    std::size_t o = 0;  // a joint re-fit replaces the constants of the effects selected before
    for (Entry& before : e)
      for (double& v : before.values)
        if (o < it->refit_selected.size()) v = it->refit_selected[o++], before.how = "re-fitted with " + it->effect;
    e.push_back({&*it, it->params, ""});
  }
  // The selection's own record of the final constants wins over the rounds' rows: after a swap of
  // forms (try_other_forms) the effect's row is its own round's calibration and the re-fits read
  // from later rows were those of the form it replaced (measured on creep_fatigue_lag: the broad
  // creep printed with the one-term creep's gamma 0.351, tau 10.6 s, the model's being 1.15, 30 s).
  if (r.final_constants.size() == e.size())
    for (std::size_t i = 0; i < e.size(); ++i)
      if (r.final_constants[i].size() == e[i].values.size() && r.final_constants[i] != e[i].values) {
        e[i].values = r.final_constants[i];
        if (e[i].how.empty() || !r.form_changes.empty()) e[i].how = "re-fitted jointly with the other selected effects";
      }
  if (r.refined_params.size() == e.size())
    for (std::size_t i = 0; i < e.size(); ++i) e[i].values = r.refined_params[i], e[i].how = r.refined_model == "reduced" ? "refined with the reduced-order model" : "refined with the FEM";
  std::string out;
  for (const Entry& x : e) {
    std::string line = "  " + x.c->effect + ":";
    const bool ranges = x.how.empty() && x.c->trade_lo.size() == x.values.size();
    for (std::size_t j = 0; j < x.values.size(); ++j) {
      char buf[160];
      std::snprintf(buf, sizeof buf, "%s %s %.4g", j ? "," : "", x.c->param_names[j].c_str(), x.values[j]);
      line += buf;
      if (ranges) {
        std::snprintf(buf, sizeof buf, " (%.4g to %.4g)", x.c->trade_lo[j], x.c->trade_hi[j]);
        line += buf;
      }
    }
    if (!x.how.empty()) line += " (" + x.how + ")";
    if (ranges) {
      char buf[120];
      std::snprintf(buf, sizeof buf, "; ranges: RSS within %.0f %% of the best%s", 100.0 * x.c->trade_rss_tol,
                    constants_trade_off(*x.c) ? ", the constants trade off" : "");
      line += buf;
    }
    out += line + "\n";
  }
  if (!r.intervals.empty() && r.intervals.back().computed) {
    const RoundIntervals& ri = r.intervals.back();
    char buf[200];
    std::snprintf(buf, sizeof buf,
                  "  joint intervals of the path model's constants after round %d (its fit within %.0f %% of its RSS, the "
                  "other constants re-adjusting):",
                  ri.round, 100.0 * ri.rss_tol);
    std::string line = buf;
    for (std::size_t j = 0; j < ri.constants.size(); ++j) {
      const ConstantInterval& c = ri.constants[j];
      std::snprintf(buf, sizeof buf, "%s %s.%s %.4g to %.4g%s", j ? ";" : "", c.effect.c_str(), c.name.c_str(), c.lo, c.hi,
                    c.identified ? "" : " (not identified: the recording does not fix it)");
      line += buf;
    }
    out += line + "\n";
  }
  for (const std::string& n : r.interval_notes) out += "  note: " + n + "\n";
  return out;
}

}  // namespace pneufem
