#include "app/compare/command.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <algorithm>

#include "app/compare/dlc_map.h"
#include "app/compare/report.h"
#include "core/atomic_file.h"
#include "core/errors.h"
#include "core/output_dir.h"
#include "core/json_writer.h"
#include "core/version.h"

namespace pneufem {

namespace fs = std::filesystem;

namespace {

std::string bools(const std::vector<StepComparison>& st, bool StepComparison::*f) {
  std::string s = "[";
  for (std::size_t i = 0; i < st.size(); ++i) s += (i ? ", " : "") + std::string(st[i].*f ? "true" : "false");
  return s + "]";
}

std::string numbers(const std::vector<StepComparison>& st, double StepComparison::*f) {
  std::vector<double> v;
  for (const StepComparison& s : st) v.push_back(s.*f);
  return json::array(v);
}

std::string strings(const std::vector<std::string>& v) {
  std::string s = "[";
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + json::quote(v[i]);
  return s + "]";
}

std::string profile_json(const Comparison& c, double bin_s) {
  json::Object o;
  o.add("bin_s", bin_s)
      .add("t_s", json::array(c.profile.t_s))
      .add("all_deg", json::array(c.profile.mean_deg))
      .add("early_trials_deg", json::array(c.profile_early_trials.mean_deg))
      .add("late_trials_deg", json::array(c.profile_late_trials.mean_deg))
      .add("before_mark_deg", c.residual_before_mark_deg)
      .add("after_mark_deg", c.residual_after_mark_deg);
  return o.str(2);
}

/// metrics.json "trials": one object per trial with its NRMSE, RMSE, range, noise and the
/// per-step arrays (levels, marks, spreads, slopes, steadiness, mean residual).
std::string trials_json(const Comparison& c) {
  std::string trials = "[";
  for (std::size_t k = 0; k < c.trials.size(); ++k) {
    const TrialComparison& t = c.trials[k];
    json::Object o;
    o.add("trial", t.trial)
        .add("nrmse_mark", t.nrmse_mark)
        .add("nrmse", t.nrmse)
        .add("rmse_deg", t.rmse_deg)
        .add("range_deg", t.range_deg)
        .add("frames", static_cast<double>(t.frames))
        .add("outliers", static_cast<double>(t.outliers))
        .add("noise_deg", t.noise_deg)
        .add("levels_kPa", numbers(t.steps, &StepComparison::level_kPa))
        .add("t_start_s", numbers(t.steps, &StepComparison::t_start_s))
        .add("abs_error_deg", numbers(t.steps, &StepComparison::abs_error_deg))
        .add("measured_mark_deg", numbers(t.steps, &StepComparison::measured_mark_deg))
        .add("model_mark_deg", numbers(t.steps, &StepComparison::model_mark_deg))
        .add("spread_measured_deg", numbers(t.steps, &StepComparison::spread_measured_deg))
        .add("spread_model_deg", numbers(t.steps, &StepComparison::spread_model_deg))
        .add("slope_measured_deg_s", numbers(t.steps, &StepComparison::slope_measured_deg_s))
        .add("slope_model_deg_s", numbers(t.steps, &StepComparison::slope_model_deg_s))
        .add("slope_residual_deg_s", numbers(t.steps, &StepComparison::slope_residual_deg_s))
        .add("steady", bools(t.steps, &StepComparison::steady))
        .add("steady_model", bools(t.steps, &StepComparison::steady_model))
        .add("mean_residual_deg", numbers(t.steps, &StepComparison::mean_residual_deg));
    trials += (k ? ", " : "") + o.str(4);
  }
  return trials + "]";
}

/// metrics.json "regions": each region's sensitivity (best stiffness scale, share of the residual
/// variance it explains, NRMSE), or null when --regions was not asked.
std::string regions_json(const CompareRunOptions& opt, const CompareRunResult& r) {
  if (!opt.regions) return "null";
  std::string regions = "[";
  for (std::size_t i = 0; i < r.regions.size(); ++i) {
    const RegionSensitivity& g = r.regions[i];
    json::Object o;
    o.add_str("region", g.region)
        .add("elements", static_cast<double>(g.elements))
        .add("best_scale", g.best_scale)
        .add("variance_fraction", g.variance_fraction)
        .add("nrmse", g.nrmse);
    regions += (i ? ", " : "") + o.str(4);
  }
  return regions + "]";
}

/// metrics.json "worst_states": the states written as VTU, their files relative to --out.
std::string worst_states_json(const CompareRunOptions& opt, const CompareRunResult& r) {
  std::string worst = "[";
  for (std::size_t i = 0; i < r.drive.worst.size(); ++i) {
    const WorstState& w = r.drive.worst[i];
    json::Object o;
    o.add("trial", w.trial)
        .add("time_s", w.time_s)
        .add("model_deg", w.model_deg)
        .add("measured_deg", w.measured_deg)
        .add_str("file", fs::path(w.file).lexically_relative(opt.out_dir).string());
    worst += (i ? ", " : "") + o.str(4);
  }
  return worst + "]";
}

/// metrics.json "mesh": node and element counts, element type, volume, elements per region.
std::string mesh_json(const CompareRunResult& r) {
  json::Object mesh_regions;
  for (const auto& [name, n] : r.drive.mesh.elements_per_region) mesh_regions.add(name, static_cast<double>(n));
  json::Object mesh;
  mesh.add("nodes", r.drive.mesh.nodes)
      .add("elements", r.drive.mesh.elements)
      .add_str("element_type", r.drive.mesh.element_type)
      .add("volume_m3", r.drive.mesh.volume_m3)
      .add("elements_per_region", mesh_regions.str(4));
  return mesh.str(2);
}

/// metrics.json "simulation": how the model ran (status, states, model and, when the reduced
/// model ran, its offline cost, basis source, worst check and enrichments).
std::string simulation_json(const CompareRunResult& r) {
  json::Object sim;
  sim.add_str("status", r.drive.failure.empty() ? "complete" : "incomplete")
      .add_str("failure", r.drive.failure)
      .add("states", static_cast<double>(r.drive.states))
      .add("pressure_tolerance_kPa", r.drive.tolerance_kPa)
      .add("wall_s", r.drive.wall_s)
      .add_str("model", r.drive.model);
  if (r.drive.model != "full") {  // the reduced model ran (and stood, or was replaced by the FEM: model says which)
    sim.add("reduced_offline_s", r.drive.reduced_offline_s)
        .add_str("reduced_basis", r.drive.reduced_basis_source)
        .add("reduced_worst_check_deg", r.drive.reduced_worst_check_deg)
        .add("reduced_enrichments", static_cast<double>(r.drive.reduced_enrichments));
  }
  return sim.str(2);
}

std::string metrics_json_text(const Scene& scene, const CompareRunOptions& opt, const CompareRunResult& r,
                              const std::string& label, const std::string& hash) {
  const Comparison& c = r.comparison;
  std::vector<double> trial_nrmse;
  for (const TrialComparison& t : c.trials) trial_nrmse.push_back(t.nrmse);
  std::string map = "[";
  for (std::size_t k = 0; k < c.residual_map_deg.size(); ++k) map += (k ? ", " : "") + json::array(c.residual_map_deg[k]);
  map += "]";
  json::Object o;
  o.add_str("pneufem_version", version_string())
      .add_str("command_line", opt.command_line)
      .add_str("label", label)
      .add_str("data_file", opt.data_path)
      .add_str("scene_hash", hash)
      .add("nrmse", c.nrmse)
      .add("rmse_deg", c.rmse_deg)
      .add("range_deg", c.range_deg)
      .add("rss_deg2", c.rss_deg2)
      .add("n", static_cast<double>(c.n))
      .add("noise_floor_nrmse", c.noise_floor_nrmse)
      .add("trial_nrmse", json::array(trial_nrmse))
      .add("trials", trials_json(c))
      .add("residual_map_deg", map)
      .add("residual_profile", profile_json(c, opt.compare.bin_s))
      .add("regions", regions_json(opt, r))
      .add("worst_states", worst_states_json(opt, r))
      .add("simulation", simulation_json(r))
      .add("wall_s", r.wall_s)
      .add("warnings", strings(r.warnings))
      .add("mesh", mesh_json(r))
      .add("scene", scene.to_json());
  return o.str() + "\n";
}

std::string csv_num(double v) {
  if (!std::isfinite(v)) return "";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.9g", v);
  return buf;
}

std::string metrics_csv_text(const Comparison& c) {
  std::string s =
      "trial,step,t_start_s,t_end_s,level_kPa,measured_mark_deg,model_mark_deg,abs_error_deg,spread_measured_deg,"
      "spread_model_deg,slope_measured_deg_s,slope_model_deg_s,slope_residual_deg_s,steady,steady_model,"
      "mean_residual_deg,frames\n";
  for (const TrialComparison& t : c.trials)
    for (std::size_t k = 0; k < t.steps.size(); ++k) {
      const StepComparison& st = t.steps[k];
      s += std::to_string(t.trial) + "," + std::to_string(k + 1);
      for (double v : {st.t_start_s, st.t_end_s, st.level_kPa, st.measured_mark_deg, st.model_mark_deg, st.abs_error_deg,
                       st.spread_measured_deg, st.spread_model_deg, st.slope_measured_deg_s, st.slope_model_deg_s,
                       st.slope_residual_deg_s})
        s.append(",").append(csv_num(v));
      s.append(st.steady ? ",1" : ",0").append(st.steady_model ? ",1," : ",0,");
      s.append(csv_num(st.mean_residual_deg)).append(",").append(std::to_string(st.frames)).append("\n");
    }
  return s;
}

/// Model angles of every trial (the drive's traces) in the recording's order.
std::vector<Series> model_series(const DriveResult& d) {
  std::vector<Series> out;
  for (const TrialTrace& t : d.trials) out.push_back(t.angle_deg);
  return out;
}

/// Region sensitivities (see command.h).
std::vector<RegionSensitivity> region_sensitivities(const Scene& scene, const Recording& rec,
                                                    const CompareRunResult& base, const CompareRunOptions& opt,
                                                    std::vector<std::string>& warnings) {
  const Comparison& c0 = base.comparison;
  std::vector<double> e;
  for (const ComparedFrame& f : c0.frames) e.push_back(f.model_deg - f.measured_deg);
  DriveOptions dopt;
  dopt.threads = opt.threads;
  dopt.progress = opt.progress;
  dopt.progress_log_every_s = opt.progress_log_every_s;
  dopt.cache_dir = opt.cache_dir;
  std::vector<RegionSensitivity> out;
  const double d_scale = opt.region_scale - 1.0;
  for (const auto& [region, elements] : base.drive.mesh.elements_per_region) {
    if (elements <= 0) continue;
    char set[200];
    std::snprintf(set, sizeof set, "regions.%s.stiffness_scale=%.17g", region.c_str(), opt.region_scale);
    Scene perturbed = scene;
    try {
      perturbed = scene.with({set});
    } catch (const InputError& err) {
      warnings.push_back("region sensitivity skipped for '" + region + "': " + err.what());
      continue;
    }
    if (opt.progress) std::fprintf(stderr, "  region %s: stiffness x %.2f\n", region.c_str(), opt.region_scale);
    const DriveResult d = simulate_recording(perturbed, rec, dopt);
    const Comparison c = compare_recording(rec, model_series(d), opt.compare);
    if (c.frames.size() != c0.frames.size())
      throw std::logic_error("region sensitivity: the compared frames changed with the model");
    std::vector<double> s(e.size());
    for (std::size_t i = 0; i < e.size(); ++i) s[i] = (c.frames[i].model_deg - c0.frames[i].model_deg) / d_scale;
    const Projection p = project_residual(e, s);
    out.push_back({region, elements, 1.0 + p.delta, p.fraction, c.nrmse});
  }
  std::stable_sort(out.begin(), out.end(), [](const RegionSensitivity& a, const RegionSensitivity& b) {
    return a.variance_fraction > b.variance_fraction;
  });
  return out;
}

}  // namespace

CompareRunResult run_compare(const Scene& scene, const CompareRunOptions& opt) {
  const auto wall0 = std::chrono::steady_clock::now();
  if (opt.out_dir.empty()) throw InputError("--out DIR is required");
  check_output_dir(opt.out_dir, "--out");  // before anything is read or run: a bad --out fails now
  if (opt.data_path.empty()) throw InputError("--data FILE is required (canonical CSV trial,time_s,pressure_kPa,angle_deg)");
  Recording rec = opt.dlc_map_path.empty() ? read_measurements_csv(opt.data_path)
                                           : merge_deeplabcut(read_measurements_csv(opt.data_path), opt.dlc_map_path);
  fill_commanded_pressure(rec, scene);  // angles alone: the scene's protocol drives the model
  CompareRunResult r;
  r.warnings = rec.warnings;

  // Worst-state VTUs go to a staging folder first: the directory only changes once everything
  // has been computed.
  fs::path dir = fs::path(opt.out_dir).lexically_normal();
  if (dir.filename().empty()) dir = dir.parent_path();  // "out/" -> "out": the staging folder is a sibling
  const fs::path staging = dir.string() + ".vtu.tmp";
  std::error_code ec;
  fs::remove_all(staging, ec);
  prepare_output_dir(opt.out_dir, "--out");  // the inputs are good: DIR exists before the model runs
  DriveOptions dopt;
  dopt.threads = opt.threads;
  dopt.progress = opt.progress;
  dopt.progress_log_every_s = opt.progress_log_every_s;
  dopt.vtu_dir = staging.string();
  dopt.cache_dir = opt.cache_dir;
  // A model the FEM cannot follow to the end (a limit point, failed walls) still gives the
  // comparison of the frames solved before: hours of computation are not thrown away, and where it
  // stopped is itself a finding. metrics.json says "incomplete" with the reason; the CLI exits 3.
  dopt.partial_on_failure = true;
  try {
    r.drive = simulate_recording(scene, rec, dopt);
    if (!r.drive.failure.empty()) {
      std::ostringstream w;
      w << "the model run stopped early (at t = " << r.drive.failure_time_s
        << " s of its last trial): the metrics cover only the frames solved before. " << r.drive.failure;
      r.warnings.push_back(w.str());
    }
    r.comparison = compare_recording(rec, model_series(r.drive), opt.compare);
    r.warnings.insert(r.warnings.end(), r.comparison.warnings.begin(), r.comparison.warnings.end());
    if (opt.regions && r.drive.failure.empty()) r.regions = region_sensitivities(scene, rec, r, opt, r.warnings);
  } catch (...) {
    fs::remove_all(staging, ec);
    throw;
  }

  prepare_output_dir(opt.out_dir, "--out");  // again: it may have gone while the model ran
  // Move the worst-state VTUs into DIR/vtu (replacing an older set).
  fs::remove_all(dir / "vtu", ec);
  if (!r.drive.worst.empty()) {
    fs::rename(staging, dir / "vtu");
    for (WorstState& w : r.drive.worst) w.file = (dir / "vtu" / fs::path(w.file).filename()).string();
  }
  fs::remove_all(staging, ec);

  const std::string label =
      !opt.label.empty() ? opt.label : (scene.path().empty() ? "default" : fs::path(scene.path()).filename().string());
  const std::string hash = scene_hash(scene);
  r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();

  HistoryEntry h;
  h.time_utc = utc_now();
  h.label = label;
  h.scene_hash = hash;
  h.nrmse = r.comparison.nrmse;
  for (const TrialComparison& t : r.comparison.trials) h.trial_nrmse.push_back(t.nrmse);
  std::vector<HistoryEntry> history = read_history(opt.out_dir);
  if (r.drive.failure.empty()) history.push_back(h);

  write_file_atomic((dir / "metrics.json").string(), metrics_json_text(scene, opt, r, label, hash));
  write_file_atomic((dir / "metrics.csv").string(), metrics_csv_text(r.comparison));
  write_file_atomic((dir / "scene.toml").string(), r.drive.scene_text);
  const std::vector<ReportFigure> figs = compare_figures(rec, r, history);
  write_report_figures(dir.string(), figs, r.comparison);  // fig_*.svg, their fig_*.csv, model_vs_measured.csv
  write_file_atomic((dir / "report.html").string(), compare_report_html(rec, r, figs, history, label, opt.data_path));
  // The study history plots the error of each model variant; an incomplete run's error covers
  // other frames than the others', so it is not added there.
  if (r.drive.failure.empty()) append_history(opt.out_dir, h);
  return r;
}

}  // namespace pneufem
