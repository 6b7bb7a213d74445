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

}  // namespace

void refine_with_fem(const Scene& scene, const Scene& cal_scene, const Recording& rec,
                     const std::vector<ComparedFrame>& frames, const PathModelEvaluator& rom, const DiagnoseOptions& opt,
                     ChosenEffects& chosen, std::vector<std::string>& selected_sets, long& rom_runs,
                     DiagnosisResult& out, std::vector<Series>* fitted_fem) {
  // Space mapping (output correction): the path model is a 1-dof Ritz model and misjudges
  // strongly localised effects (damage concentrated in the walls) by up to a factor ~2 in angle
  // change (tests/engine/test_path_model.cpp). Each refinement runs the accurate model (the
  // reduced-order model, or the full FEM with --refine-model full) once at the current constants,
  // adds its frame-by-frame difference from the path model as a fixed correction, and
  // re-calibrates each selected effect in turn from its current constants. At convergence the
  // corrected path model equals the accurate model at the fitted constants, so the constants are
  // the accurate model's.
  //
  // When the accurate model cannot follow the constants to the end (typically fatigue: the path
  // model misses the feedback "a damaged wall stretches more, so it damages faster", so its
  // constants are too aggressive and the FEM's walls fail or reach a limit point), the refinement
  // uses the frames it did solve: the correction is applied there and the path model alone is used
  // after the failure. Re-calibrating against that moves the constants towards what the accurate
  // model can follow, and its next run gets further (a verified continuation).
  const AccurateModel accurate{opt.refine_model == DiagnoseOptions::RefineModel::Reduced, scene, cal_scene, rom, opt};
  const AccurateModel full_fem{false, scene, cal_scene, rom, opt};
  auto at_frames_of = [&](const AccurateModel& model, const std::vector<std::string>& sets, std::string* failure,
                          double* failure_time_s, std::vector<Series>* traces = nullptr) {
    const DriveResult dr = model.run(rec, sets);
    *failure = dr.failure;
    *failure_time_s = dr.failure_time_s;
    if (traces) {
      traces->clear();
      for (const TrialTrace& t : dr.trials) traces->push_back(t.angle_deg);
    }
    std::vector<double> v(frames.size());
    for (std::size_t i = 0; i < frames.size(); ++i) {
      const Series& a = dr.trials[frames[i].trial_index].angle_deg;
      v[i] = value_at(a, frames[i].t_s);
      // value_at interpolates: a frame between the last solved one and the first unsolved one has
      // no FEM value either.
      if (!dr.failure.empty()) {
        const auto it = std::lower_bound(a.t_s.begin(), a.t_s.end(), frames[i].t_s);
        const std::size_t j = static_cast<std::size_t>(it - a.t_s.begin());
        if (j >= a.t_s.size() || !std::isfinite(a.value[j]) || (j > 0 && !std::isfinite(a.value[j - 1])))
          v[i] = NAN;
      }
    }
    return v;
  };
  //
  // Safeguard: the correction is frozen at the last FEM run, so when the FEM-vs-reduced difference
  // changes quickly with the constants (damage that fails wall points) a re-calibration can jump
  // too far (measured: fatigue W_th 4.8 -> 29 kPa, FEM error back to the baseline's). Every FEM run
  // therefore also scores its constants; constants whose complete FEM run fits worse than the best
  // so far are not used to build a correction — the next trial point is halfway (in each
  // parameter's calibration scale) back towards the best, and the best constants are the result.
  auto sets_of = [&](const std::vector<std::pair<const CandidateEffect*, std::vector<double>>>& ch) {
    std::vector<std::string> v;
    for (const auto& [c, vals] : ch) {
      const std::vector<std::string> sc = c->sets(scene, vals);
      v.insert(v.end(), sc.begin(), sc.end());
    }
    return v;
  };
  // The selected effects other than the j-th, at their current constants (each effect is
  // re-calibrated in turn with the others fixed).
  auto sets_except = [&](std::size_t j) {
    auto others = chosen;
    others.erase(others.begin() + static_cast<std::ptrdiff_t>(j));
    return sets_of(others);
  };
  auto chosen_best = chosen;
  double best_fem_rss = std::numeric_limits<double>::infinity();  // complete accurate-model runs only
  std::vector<Series> best_traces;                                // ... the angles of the best one
  if (fitted_fem) fitted_fem->clear();
  // Run 0 scores the reduced model's constants and gives the first correction; run k = 1..N scores
  // the k-th re-calibration (and corrects the next). So --refine N costs N + 1 FEM runs, and the
  // constants returned have always been run by the FEM (the last re-calibration too: before
  // 2026-11-26 it was never run, so --refine 1 returned the reduced model's constants unchanged).
  //
  // With the reduced model only effects with history are re-calibrated: a static effect's constants
  // (stiffness) change the elastic reference the reduced basis is built for, so each new value would
  // cost a new offline part, and the path model is exact for them up to the mesh map anyway.
  auto refinable = [&](const CandidateEffect& c) { return !accurate.reduced || c.history; };
  const bool any_refinable =
      std::any_of(chosen.begin(), chosen.end(), [&](const auto& ch) { return refinable(*ch.first); });
  const int fem_runs = opt.refine > 0 && any_refinable ? opt.refine + 1 : 0;
  for (int it = 0; it < fem_runs && !chosen.empty(); ++it) {
    if (opt.progress) {
      if (it == 0) std::fprintf(stderr, "diagnose: the path model's constants with %s ...\n", accurate.name());
      else std::fprintf(stderr, "diagnose: refinement %d with %s ...\n", it, accurate.name());
    }
    std::string failure;
    double failure_time_s = -1.0;
    std::vector<Series> traces;
    const std::vector<double> fem = at_frames_of(accurate, selected_sets, &failure, &failure_time_s, &traces);
    std::size_t solved = 0;
    for (double v : fem) solved += std::isfinite(v) ? 1 : 0;
    if (!failure.empty()) {
      std::ostringstream m;
      m << (it == 0 ? std::string("the path model's constants") : "refinement " + std::to_string(it)) << ": "
        << accurate.name() << " stopped at t = " << failure_time_s << " s of trial "
        << frames[std::min(solved, frames.size() - 1)].trial_index + 1 << " (" << solved << " of " << frames.size()
        << " frames solved; corrected there, path model alone after): " << failure;
      out.fem_error += (out.fem_error.empty() ? "" : "; ") + m.str();
      if (opt.progress) std::fprintf(stderr, "diagnose: %s\n", m.str().c_str());
      if (solved == 0 || it + 1 == fem_runs) break;
    } else {
      const double fem_rss = rss_of(fem, frames);
      if (opt.progress)
        std::fprintf(stderr, "diagnose: rss of %s %.4g deg^2 (best before %.4g)\n", accurate.name(), fem_rss, best_fem_rss);
      if (!(fem_rss < best_fem_rss) && std::isfinite(best_fem_rss)) {
        // Worse than the best complete run: step halfway back, no new correction.
        for (std::size_t j = 0; j < chosen.size(); ++j) {
          const std::vector<CandidateParameter>& ps = chosen[j].first->params;
          for (std::size_t k = 0; k < ps.size(); ++k) {
            double& v = chosen[j].second[k];
            const double b = chosen_best[j].second[k];
            v = ps[k].log ? std::sqrt(v * b) : 0.5 * (v + b);
          }
        }
        selected_sets = sets_of(chosen);
        continue;
      }
      best_fem_rss = fem_rss;
      chosen_best = chosen;
      best_traces = traces;
      if (fitted_fem && !accurate.reduced) *fitted_fem = std::move(traces);  // --verify need not run them again
      if (it + 1 == fem_runs) break;  // the last run only scores
    }
    const std::vector<double> romv = rom.at_frames(cal_scene.with(selected_sets));
    std::vector<double> corr(fem.size());
    for (std::size_t i = 0; i < fem.size(); ++i) corr[i] = std::isfinite(fem[i]) ? fem[i] - romv[i] : 0.0;
    for (std::size_t j = 0; j < chosen.size(); ++j) {
      const Scene base_j = cal_scene.with(sets_except(j));
      const CandidateEffect& c = *chosen[j].first;
      if (!refinable(c)) continue;
      auto rss = [&](const std::vector<double>& v) {
        std::vector<double> m = rom.at_frames(base_j.with(c.sets(base_j, v)));
        for (std::size_t i = 0; i < m.size(); ++i) m[i] += corr[i];
        return rss_of(m, frames);
      };
      const Calibration cal = calibrate(c, rss, std::max(8, opt.max_evaluations / 2), &chosen[j].second);
      rom_runs += cal.evaluations;
      if (std::isfinite(cal.rss)) chosen[j].second = cal.values;
    }
    selected_sets = sets_of(chosen);
  }
  if (!best_traces.empty()) {  // the error of the refined constants, per trial, by the model that refined them
    const Comparison c = compare_recording(rec, best_traces);
    out.refined_model = accurate.reduced ? "reduced" : "full";
    out.refined_nrmse = c.nrmse;
    out.refined_nrmse_per_trial.clear();
    for (const TrialComparison& t : c.trials) out.refined_nrmse_per_trial.push_back(t.nrmse);
  }
  if (opt.fem_calibration_runs > 0 && !chosen.empty()) {
    // Local calibration on the FEM itself (each effect in turn, the others at their constants). A
    // run that does not complete scores as failed (the calibrator then avoids the region).
    if (std::isfinite(best_fem_rss)) chosen = chosen_best;
    for (std::size_t j = 0; j < chosen.size(); ++j) {
      const Scene base_j = scene.with(sets_except(j));
      const CandidateEffect& c = *chosen[j].first;
      int run = 0;
      auto rss = [&](const std::vector<double>& v) {
        std::string failure;
        double t_fail = -1.0;
        std::vector<std::string> sets = sets_except(j);
        const std::vector<std::string> own = c.sets(base_j, v);
        sets.insert(sets.end(), own.begin(), own.end());
        const std::vector<double> fem = at_frames_of(full_fem, sets, &failure, &t_fail);
        if (!failure.empty()) throw PhysicsError("the FEM stopped early: " + failure);
        const double r = rss_of(fem, frames);
        if (opt.progress) {
          std::fprintf(stderr, "diagnose: FEM calibration of %s, run %d:", c.name.c_str(), ++run);
          for (double x : v) std::fprintf(stderr, " %.4g", x);
          std::fprintf(stderr, " -> rss %.4g deg^2\n", r);
        }
        return r;
      };
      const Calibration cal = calibrate(c, rss, opt.fem_calibration_runs, &chosen[j].second);
      if (std::isfinite(cal.rss)) {
        chosen[j].second = cal.values;
        best_fem_rss = cal.rss;
        chosen_best = chosen;
        if (fitted_fem) fitted_fem->clear();  // not the traces of these constants any more
      }
    }
    selected_sets = sets_of(chosen);
  }
  if ((fem_runs > 0 || opt.fem_calibration_runs > 0) && !chosen.empty()) {
    // The result: the constants of the best complete accurate run (the last re-calibration is
    // untested unless it was the best), else the last ones (no run completed).
    if (std::isfinite(best_fem_rss)) {
      chosen = chosen_best;
      selected_sets = sets_of(chosen);
    }
    out.refined_params.clear();
    for (const auto& [c, v] : chosen) out.refined_params.push_back(v);
  }
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
