// The full-FEM stages of diagnose (app/diagnose/detail.h): space-mapping refinement of the
// selected constants (--refine), their local calibration on the FEM itself (--fem-calibrate) and
// the FEM check of the baseline and fitted scenes (--verify). Apart from the selection because
// they run after it, on its result, and cost full FEM runs of the recording rather than reduced-
// model runs.
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

void refine_with_fem(const Scene& scene, const Scene& cal_scene, const Recording& rec,
                     const std::vector<ComparedFrame>& frames, const PathModelEvaluator& rom, const DiagnoseOptions& opt,
                     ChosenEffects& chosen, std::vector<std::string>& selected_sets, long& rom_runs,
                     DiagnosisResult& out, std::vector<Series>* fitted_fem) {
  // Space mapping (output correction): the reduced model is a 1-dof Ritz model and misjudges
  // strongly localised effects (damage concentrated in the walls) by up to a factor ~2 in angle
  // change (tests/app/test_path_model.cpp). Each refinement runs the full FEM once at the current
  // constants, adds its frame-by-frame difference from the reduced model as a fixed correction,
  // and re-calibrates each selected effect in turn from its current constants. At convergence the
  // corrected reduced model equals the FEM at the fitted constants, so the constants are the FEM's.
  //
  // When the FEM cannot follow the constants to the end (typically fatigue: the reduced model
  // misses the feedback "a damaged wall stretches more, so it damages faster", so its constants
  // are too aggressive and the FEM's walls fail or reach a limit point), the refinement uses the
  // frames the FEM did solve: the correction is applied there and the reduced model alone is used
  // after the failure. Re-calibrating against that moves the constants towards what the FEM can
  // follow, and the next refinement's FEM gets further (an FEM-verified continuation).
  auto fem_at_frames = [&](const Scene& s, std::string* failure, double* failure_time_s,
                           std::vector<Series>* traces = nullptr) {
    DriveOptions d;
    d.threads = opt.threads;
    d.partial_on_failure = true;
    const DriveResult dr = simulate_recording(s, rec, d);
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
  double best_fem_rss = std::numeric_limits<double>::infinity();  // complete FEM runs only
  if (fitted_fem) fitted_fem->clear();
  // Run 0 scores the reduced model's constants and gives the first correction; run k = 1..N scores
  // the k-th re-calibration (and corrects the next). So --refine N costs N + 1 FEM runs, and the
  // constants returned have always been run by the FEM (the last re-calibration too: before
  // 2026-11-26 it was never run, so --refine 1 returned the reduced model's constants unchanged).
  const int fem_runs = opt.refine > 0 ? opt.refine + 1 : 0;
  for (int it = 0; it < fem_runs && !chosen.empty(); ++it) {
    if (opt.progress)
      std::fprintf(stderr, it == 0 ? "diagnose: the reduced model's constants with the full FEM ...\n"
                                   : "diagnose: refinement %d with the full FEM ...\n", it);
    std::string failure;
    double failure_time_s = -1.0;
    std::vector<Series> traces;
    const std::vector<double> fem = fem_at_frames(scene.with(selected_sets), &failure, &failure_time_s, &traces);
    std::size_t solved = 0;
    for (double v : fem) solved += std::isfinite(v) ? 1 : 0;
    if (!failure.empty()) {
      std::ostringstream m;
      m << (it == 0 ? std::string("the reduced model's constants") : "refinement " + std::to_string(it))
        << ": the full FEM stopped at t = " << failure_time_s << " s of trial "
        << frames[std::min(solved, frames.size() - 1)].trial_index + 1 << " (" << solved << " of " << frames.size()
        << " frames solved; corrected there, reduced model alone after): " << failure;
      out.fem_error += (out.fem_error.empty() ? "" : "; ") + m.str();
      if (opt.progress) std::fprintf(stderr, "diagnose: %s\n", m.str().c_str());
      if (solved == 0 || it + 1 == fem_runs) break;
    } else {
      const double fem_rss = rss_of(fem, frames);
      if (opt.progress) std::fprintf(stderr, "diagnose: FEM rss %.4g deg^2 (best before %.4g)\n", fem_rss, best_fem_rss);
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
      if (fitted_fem) *fitted_fem = std::move(traces);
      if (it + 1 == fem_runs) break;  // the last run only scores
    }
    const std::vector<double> romv = rom.at_frames(cal_scene.with(selected_sets));
    std::vector<double> corr(fem.size());
    for (std::size_t i = 0; i < fem.size(); ++i) corr[i] = std::isfinite(fem[i]) ? fem[i] - romv[i] : 0.0;
    for (std::size_t j = 0; j < chosen.size(); ++j) {
      const Scene base_j = cal_scene.with(sets_except(j));
      const CandidateEffect& c = *chosen[j].first;
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
        const std::vector<double> fem = fem_at_frames(base_j.with(c.sets(base_j, v)), &failure, &t_fail);
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
  if ((opt.refine > 0 || opt.fem_calibration_runs > 0) && !chosen.empty()) {
    // The result: the constants of the best complete FEM run (the last re-calibration is untested
    // by the FEM unless it was the best), else the last ones (no FEM run completed).
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
