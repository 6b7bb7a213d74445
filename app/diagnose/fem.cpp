// The accurate-model stages of diagnose (app/diagnose/detail.h): space-mapping refinement of the
// selected constants (--refine, on the reduced-order model or the full FEM), their local
// calibration on the FEM itself (--fem-calibrate) and the FEM check of the baseline and fitted
// scenes (--verify). Apart from the selection because they run after it, on its result, and cost
// runs of a model far slower than the 1-dof path model the selection uses.
#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "analysis/steps.h"
#include "app/diagnose/detail.h"
#include "app/diagnose/evaluator.h"
#include "app/simulate/drive.h"
#include "core/errors.h"

namespace pneufem::diagnose_detail {

namespace {

/// How an accurate model runs a recording: the full FEM of the user's scene, or the reduced-order
/// model (engine/rom.h) of the calibration scene, driven by the path model's chamber pressure map
/// when that is a coarser mesh (PathModelEvaluator::chamber), so that both models of the space
/// mapping see the same mesh and pressure. Reduced runs are unchecked and never fall back to the
/// FEM (a diagnosis must not turn into hours of FEM unasked); a failure is that run's failure, as
/// the FEM's would be.
struct AccurateModel {
  bool reduced;
  const Scene& scene;      ///< the user's scene (full FEM)
  const Scene& cal_scene;  ///< the calibration scene (reduced model)
  const PathModelEvaluator& rom;
  const DiagnoseOptions& opt;

  const char* name() const { return reduced ? "the reduced-order model" : "the full FEM"; }

  DriveResult run(const Recording& rec, const std::vector<std::string>& sets) const {
    DriveOptions d;
    d.threads = opt.threads;
    d.partial_on_failure = true;
    if (!reduced) return simulate_recording(scene.with(sets), rec, d);
    std::vector<std::string> s = sets;
    s.push_back("solver.model=\"reduced\"");
    d.cache_dir = opt.cache_dir;
    d.reduced_check = false;
    d.reduced_fallback = false;
    if (!rom.pressure_map_Pa().empty()) d.chamber_pressure = [this](double p) { return rom.chamber(p); };
    // The offline part for the protocol's peak, not this recording's noisy one: a second recording
    // of the protocol reuses it from the cache (elastic_reference_peak_Pa, app/diagnose/evaluator.h).
    d.reduced_peak_Pa = rom.chamber(rom.reference_peak_Pa());
    return simulate_recording(cal_scene.with(s), rec, d);
  }
};

/// One refinement of the selected constants by an accurate model (refine_with_fem): the space
/// mapping (--refine), then the local calibration on the FEM (--fem-calibrate), then the result.
/// Holds what the stages share: the selected effects' constants (the caller's, updated in place)
/// and the best complete accurate run so far.
class Refinement {
 public:
  Refinement(const Scene& scene, const Scene& cal_scene, const Recording& rec, const std::vector<ComparedFrame>& frames,
             const PathModelEvaluator& rom, const DiagnoseOptions& opt, ChosenEffects& chosen,
             std::vector<std::string>& selected_sets, long& rom_runs, DiagnosisResult& out, std::vector<Series>* fitted_fem)
      : scene_(scene), cal_scene_(cal_scene), rec_(rec), frames_(frames), rom_(rom), opt_(opt), chosen_(chosen),
        selected_sets_(selected_sets), rom_runs_(rom_runs), out_(out), fitted_fem_(fitted_fem),
        accurate_{opt.refine_model == DiagnoseOptions::RefineModel::Reduced, scene, cal_scene, rom, opt},
        full_fem_{false, scene, cal_scene, rom, opt}, chosen_best_(chosen) {
    const bool any_refinable =
        std::any_of(chosen_.begin(), chosen_.end(), [&](const auto& ch) { return refinable(*ch.first); });
    fem_runs_ = opt_.refine > 0 && any_refinable ? opt_.refine + 1 : 0;
    if (fitted_fem_) fitted_fem_->clear();
  }

  void space_mapping();
  void calibrate_on_fem();
  void finish();

 private:
  std::vector<double> at_frames_of(const AccurateModel& model, const std::vector<std::string>& sets, std::string* failure,
                                   double* failure_time_s, std::vector<Series>* traces = nullptr) const;
  std::vector<std::string> sets_of(const ChosenEffects& ch) const;
  /// The selected effects other than the j-th, at their current constants (each effect is
  /// re-calibrated in turn with the others fixed).
  std::vector<std::string> sets_except(std::size_t j) const {
    ChosenEffects others = chosen_;
    others.erase(others.begin() + static_cast<std::ptrdiff_t>(j));
    return sets_of(others);
  }
  /// With the reduced model only effects with history are re-calibrated: a static effect's constants
  /// (stiffness) change the elastic reference the reduced basis is built for, so each new value would
  /// cost a new offline part, and the path model is exact for them up to the mesh map anyway.
  bool refinable(const CandidateEffect& c) const { return !accurate_.reduced || c.history; }
  std::size_t record_failure(int it, const std::vector<double>& fem, const std::string& failure, double failure_time_s);
  bool keep_if_best(const std::vector<double>& fem, std::vector<Series>& traces);
  void step_back_towards_best();
  void recalibrate_with_correction(const std::vector<double>& fem);

  const Scene& scene_;
  const Scene& cal_scene_;
  const Recording& rec_;
  const std::vector<ComparedFrame>& frames_;
  const PathModelEvaluator& rom_;
  const DiagnoseOptions& opt_;
  ChosenEffects& chosen_;
  std::vector<std::string>& selected_sets_;
  long& rom_runs_;
  DiagnosisResult& out_;
  std::vector<Series>* fitted_fem_;
  const AccurateModel accurate_;
  const AccurateModel full_fem_;
  ChosenEffects chosen_best_;
  double best_fem_rss_ = std::numeric_limits<double>::infinity();  ///< complete accurate-model runs only
  std::vector<Series> best_traces_;                                 ///< ... the angles of the best one
  int fem_runs_ = 0;
};

/// The accurate model's angle at every compared frame; NaN where it did not solve.
std::vector<double> Refinement::at_frames_of(const AccurateModel& model, const std::vector<std::string>& sets,
                                             std::string* failure, double* failure_time_s,
                                             std::vector<Series>* traces) const {
  const DriveResult dr = model.run(rec_, sets);
  *failure = dr.failure;
  *failure_time_s = dr.failure_time_s;
  if (traces) {
    traces->clear();
    for (const TrialTrace& t : dr.trials) traces->push_back(t.angle_deg);
  }
  std::vector<double> v(frames_.size());
  for (std::size_t i = 0; i < frames_.size(); ++i) {
    const Series& a = dr.trials[frames_[i].trial_index].angle_deg;
    v[i] = value_at(a, frames_[i].t_s);
    // value_at interpolates: a frame between the last solved one and the first unsolved one has
    // no FEM value either.
    if (!dr.failure.empty()) {
      const auto it = std::lower_bound(a.t_s.begin(), a.t_s.end(), frames_[i].t_s);
      const std::size_t j = static_cast<std::size_t>(it - a.t_s.begin());
      if (j >= a.t_s.size() || !std::isfinite(a.value[j]) || (j > 0 && !std::isfinite(a.value[j - 1]))) v[i] = NAN;
    }
  }
  return v;
}

std::vector<std::string> Refinement::sets_of(const ChosenEffects& ch) const {
  std::vector<std::string> v;
  for (const auto& [c, vals] : ch) {
    const std::vector<std::string> sc = c->sets(scene_, vals);
    v.insert(v.end(), sc.begin(), sc.end());
  }
  return v;
}

// Space mapping (output correction): the path model is a 1-dof Ritz model and misjudges strongly
// localised effects (damage concentrated in the walls) by up to a factor ~2 in angle change
// (tests/engine/test_path_model.cpp). Each refinement runs the accurate model (the reduced-order
// model, or the full FEM with --refine-model full) once at the current constants, adds its
// frame-by-frame difference from the path model as a fixed correction, and re-calibrates each
// selected effect in turn from its current constants. At convergence the corrected path model
// equals the accurate model at the fitted constants, so the constants are the accurate model's.
//
// When the accurate model cannot follow the constants to the end (typically fatigue: the path model
// misses the feedback "a damaged wall stretches more, so it damages faster", so its constants are
// too aggressive and the FEM's walls fail or reach a limit point), the refinement uses the frames it
// did solve: the correction is applied there and the path model alone is used after the failure.
// Re-calibrating against that moves the constants towards what the accurate model can follow, and
// its next run gets further (a verified continuation).
//
// Run 0 scores the path model's constants and gives the first correction; run k = 1..N scores the
// k-th re-calibration (and corrects the next). So --refine N costs N + 1 accurate runs, and the
// constants returned have always been run by the accurate model (the last re-calibration too:
// before 2026-11-26 it was never run, so --refine 1 returned the path model's constants unchanged).
void Refinement::space_mapping() {
  for (int it = 0; it < fem_runs_ && !chosen_.empty(); ++it) {
    if (opt_.progress) {
      if (it == 0) std::fprintf(stderr, "diagnose: the path model's constants with %s ...\n", accurate_.name());
      else std::fprintf(stderr, "diagnose: refinement %d with %s ...\n", it, accurate_.name());
    }
    std::string failure;
    double failure_time_s = -1.0;
    std::vector<Series> traces;
    const std::vector<double> fem = at_frames_of(accurate_, selected_sets_, &failure, &failure_time_s, &traces);
    const bool last = it + 1 == fem_runs_;
    if (!failure.empty()) {
      const std::size_t solved = record_failure(it, fem, failure, failure_time_s);
      if (solved == 0 || last) break;
    } else {
      if (!keep_if_best(fem, traces)) {
        step_back_towards_best();
        continue;
      }
      if (last) break;  // the last run only scores
    }
    recalibrate_with_correction(fem);
  }
  if (!best_traces_.empty()) {  // the error of the refined constants, per trial, by the model that refined them
    const Comparison c = compare_recording(rec_, best_traces_);
    out_.refined_model = accurate_.reduced ? "reduced" : "full";
    out_.refined_nrmse = c.nrmse;
    out_.refined_nrmse_per_trial.clear();
    for (const TrialComparison& t : c.trials) out_.refined_nrmse_per_trial.push_back(t.nrmse);
  }
}

/// An accurate run that stopped early: said in the result and on the console; returns the number of
/// frames it solved.
std::size_t Refinement::record_failure(int it, const std::vector<double>& fem, const std::string& failure,
                                       double failure_time_s) {
  std::size_t solved = 0;
  for (double v : fem) solved += std::isfinite(v) ? 1 : 0;
  std::ostringstream m;
  m << (it == 0 ? std::string("the path model's constants") : "refinement " + std::to_string(it)) << ": "
    << accurate_.name() << " stopped at t = " << failure_time_s << " s of trial "
    << frames_[std::min(solved, frames_.size() - 1)].trial_index + 1 << " (" << solved << " of " << frames_.size()
    << " frames solved; corrected there, path model alone after): " << failure;
  out_.fem_error += (out_.fem_error.empty() ? "" : "; ") + m.str();
  if (opt_.progress) std::fprintf(stderr, "diagnose: %s\n", m.str().c_str());
  return solved;
}

// Safeguard: the correction is frozen at the last accurate run, so when the accurate-vs-path
// difference changes quickly with the constants (damage that fails wall points) a re-calibration can
// jump too far (measured: fatigue W_th 4.8 -> 29 kPa, FEM error back to the baseline's). Every
// accurate run therefore also scores its constants; constants whose complete run fits worse than the
// best so far are not used to build a correction (false is returned) — the next trial point is
// halfway back towards the best (step_back_towards_best), and the best constants are the result.
bool Refinement::keep_if_best(const std::vector<double>& fem, std::vector<Series>& traces) {
  const double fem_rss = rss_of(fem, frames_);
  if (opt_.progress)
    std::fprintf(stderr, "diagnose: rss of %s %.4g deg^2 (best before %.4g)\n", accurate_.name(), fem_rss, best_fem_rss_);
  if (!(fem_rss < best_fem_rss_) && std::isfinite(best_fem_rss_)) return false;
  best_fem_rss_ = fem_rss;
  chosen_best_ = chosen_;
  best_traces_ = traces;
  if (fitted_fem_ && !accurate_.reduced) *fitted_fem_ = std::move(traces);  // --verify need not run them again
  return true;
}

/// Halfway from the current constants back to the best, in each parameter's calibration scale.
void Refinement::step_back_towards_best() {
  for (std::size_t j = 0; j < chosen_.size(); ++j) {
    const std::vector<CandidateParameter>& ps = chosen_[j].first->params;
    for (std::size_t k = 0; k < ps.size(); ++k) {
      double& v = chosen_[j].second[k];
      const double b = chosen_best_[j].second[k];
      v = ps[k].log ? std::sqrt(v * b) : 0.5 * (v + b);
    }
  }
  selected_sets_ = sets_of(chosen_);
}

/// The correction (accurate minus path model at the current constants, zero where the accurate run
/// did not solve) added to the path model, and each refinable effect re-calibrated in turn.
void Refinement::recalibrate_with_correction(const std::vector<double>& fem) {
  const std::vector<double> romv = rom_.at_frames(cal_scene_.with(selected_sets_));
  std::vector<double> corr(fem.size());
  for (std::size_t i = 0; i < fem.size(); ++i) corr[i] = std::isfinite(fem[i]) ? fem[i] - romv[i] : 0.0;
  for (std::size_t j = 0; j < chosen_.size(); ++j) {
    const Scene base_j = cal_scene_.with(sets_except(j));
    const CandidateEffect& c = *chosen_[j].first;
    if (!refinable(c)) continue;
    auto rss = [&](const std::vector<double>& v) {
      std::vector<double> m = rom_.at_frames(base_j.with(c.sets(base_j, v)));
      for (std::size_t i = 0; i < m.size(); ++i) m[i] += corr[i];
      return rss_of(m, frames_);
    };
    const Calibration cal = calibrate(c, rss, std::max(8, opt_.max_evaluations / 2), &chosen_[j].second);
    rom_runs_ += cal.evaluations;
    if (std::isfinite(cal.rss)) chosen_[j].second = cal.values;
  }
  selected_sets_ = sets_of(chosen_);
}

/// Local calibration on the FEM itself (--fem-calibrate; each effect in turn, the others at their
/// constants). A run that does not complete scores as failed (the calibrator then avoids the region).
void Refinement::calibrate_on_fem() {
  if (opt_.fem_calibration_runs <= 0 || chosen_.empty()) return;
  if (std::isfinite(best_fem_rss_)) chosen_ = chosen_best_;
  for (std::size_t j = 0; j < chosen_.size(); ++j) {
    const Scene base_j = scene_.with(sets_except(j));
    const CandidateEffect& c = *chosen_[j].first;
    int run = 0;
    auto rss = [&](const std::vector<double>& v) {
      std::string failure;
      double t_fail = -1.0;
      std::vector<std::string> sets = sets_except(j);
      const std::vector<std::string> own = c.sets(base_j, v);
      sets.insert(sets.end(), own.begin(), own.end());
      const std::vector<double> fem = at_frames_of(full_fem_, sets, &failure, &t_fail);
      if (!failure.empty()) throw PhysicsError("the FEM stopped early: " + failure);
      const double r = rss_of(fem, frames_);
      if (opt_.progress) {
        std::fprintf(stderr, "diagnose: FEM calibration of %s, run %d:", c.name.c_str(), ++run);
        for (double x : v) std::fprintf(stderr, " %.4g", x);
        std::fprintf(stderr, " -> rss %.4g deg^2\n", r);
      }
      return r;
    };
    const Calibration cal = calibrate(c, rss, opt_.fem_calibration_runs, &chosen_[j].second);
    if (std::isfinite(cal.rss)) {
      chosen_[j].second = cal.values;
      best_fem_rss_ = cal.rss;
      chosen_best_ = chosen_;
      if (fitted_fem_) fitted_fem_->clear();  // not the traces of these constants any more
    }
  }
  selected_sets_ = sets_of(chosen_);
}

/// The result: the constants of the best complete accurate run (the last re-calibration is untested
/// unless it was the best), else the last ones (no run completed).
void Refinement::finish() {
  if ((fem_runs_ == 0 && opt_.fem_calibration_runs <= 0) || chosen_.empty()) return;
  if (std::isfinite(best_fem_rss_)) {
    chosen_ = chosen_best_;
    selected_sets_ = sets_of(chosen_);
  }
  out_.refined_params.clear();
  for (const auto& [c, v] : chosen_) out_.refined_params.push_back(v);
}

}  // namespace

void refine_with_fem(const Scene& scene, const Scene& cal_scene, const Recording& rec,
                     const std::vector<ComparedFrame>& frames, const PathModelEvaluator& rom, const DiagnoseOptions& opt,
                     ChosenEffects& chosen, std::vector<std::string>& selected_sets, long& rom_runs,
                     DiagnosisResult& out, std::vector<Series>* fitted_fem) {
  Refinement r(scene, cal_scene, rec, frames, rom, opt, chosen, selected_sets, rom_runs, out, fitted_fem);
  r.space_mapping();
  r.calibrate_on_fem();
  r.finish();
}

void verify_with_fem(const Scene& scene, const Scene& fitted, const Recording& rec, const DiagnoseOptions& opt,
                     DiagnosisResult& out, const std::vector<Series>* fitted_fem) {
  DriveOptions d;
  d.threads = opt.threads;
  auto fem_nrmse = [&](const Scene& s, const char* which) {
    if (opt.progress) std::fprintf(stderr, "diagnose: verifying the %s scene with the full FEM ...\n", which);
    try {
      std::vector<Series> v;
      for (TrialTrace& t : simulate_recording(s, rec, d).trials) v.push_back(std::move(t.angle_deg));
      return compare_recording(rec, v).nrmse;
    } catch (const PhysicsError& e) {
      const std::string msg = std::string("the full FEM of the ") + which + " scene failed: " + e.what();
      out.fem_error += (out.fem_error.empty() ? "" : "; ") + msg;
      if (opt.progress) std::fprintf(stderr, "diagnose: %s\n", msg.c_str());
      return -1.0;
    }
  };
  out.verified_baseline_nrmse = fem_nrmse(scene, "baseline");
  out.verified_fitted_nrmse = fitted_fem && !fitted_fem->empty() ? compare_recording(rec, *fitted_fem).nrmse
                                                                  : fem_nrmse(fitted, "fitted");
}

}  // namespace pneufem::diagnose_detail
