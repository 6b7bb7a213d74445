// `pneufem diagnose` (app/diagnose.h): run_diagnosis, the rounds of greedy forward selection with
// their significance tests (effective_sample_size, params_at_bounds), and the order of the stages.
// What a stage does lives in its own file (app/diagnose_detail.h lists them); this one decides
// which candidates are tried, which are selected and when to stop.
#include "app/diagnose.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include <tbb/global_control.h>
#include <tbb/parallel_for.h>

#include "analysis/compare.h"
#include "analysis/measurements.h"
#include "app/diagnose_detail.h"
#include "app/diagnose_model.h"
#include "app/effect_catalog.h"
#include "app/elastic_curve.h"
#include "materials/errors.h"

namespace pneufem {

using namespace diagnose_detail;  // the internals of diagnose (app/diagnose_detail.h)

std::vector<std::string> params_at_bounds(const CandidateEffect& c, const std::vector<double>& values) {
  std::vector<std::string> out;
  if (c.interpolation == ParameterInterpolation::rig_angle) return out;
  for (std::size_t i = 0; i < c.params.size() && i < values.size(); ++i) {
    const CandidateParameter& p = c.params[i];
    const double v = std::clamp(values[i], p.lo, p.hi);
    const double x = p.log ? std::log(v / p.lo) / std::log(p.hi / p.lo) : (v - p.lo) / (p.hi - p.lo);
    if (x <= 0.01 || x >= 0.99) out.push_back(p.name);
  }
  return out;
}

double effective_sample_size(const std::vector<double>& r, const std::vector<int>& segment) {
  const double n = static_cast<double>(r.size());
  if (r.size() < 3) return n;
  double mean = 0.0;
  for (double v : r) mean += v;
  mean /= n;
  double c0 = 0.0, c1 = 0.0;
  for (std::size_t i = 0; i < r.size(); ++i) {
    c0 += sq(r[i] - mean);
    if (i > 0 && segment[i] == segment[i - 1]) c1 += (r[i] - mean) * (r[i - 1] - mean);
  }
  const double rho = c0 > 0.0 ? std::clamp(c1 / c0, 0.0, 0.999) : 0.0;
  return std::clamp(n * (1.0 - rho) / (1.0 + rho), std::min(n, 10.0), n);
}

DiagnosisResult run_diagnosis(const Scene& scene, const DiagnoseOptions& opt) {
  const auto t0 = std::chrono::steady_clock::now();
  if (opt.out_dir.empty()) throw InputError("diagnose: --out DIR is required");
  if (opt.max_effects < 1) throw InputError("diagnose: --max-effects must be >= 1");
  std::vector<const CandidateEffect*> cands;
  if (opt.candidates.empty())
    for (const CandidateEffect& c : candidate_effects()) cands.push_back(&c);
  else
    for (const std::string& n : opt.candidates) cands.push_back(&candidate_effect(n));
  std::unique_ptr<tbb::global_control> gc;
  if (opt.threads > 0) gc = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, opt.threads);

  const Recording rec = read_measurements_csv(opt.data_path);
  for (const std::string& w : rec.warnings) std::fprintf(stderr, "warning: %s\n", w.c_str());
  // Kept frames and metrics come from compare_recording; any model series gives the frames.
  std::vector<Series> zero(rec.trials.size());
  for (std::size_t k = 0; k < rec.trials.size(); ++k) {
    zero[k].t_s = rec.trials[k].angle_deg.t_s;
    zero[k].value.assign(zero[k].t_s.size(), 0.0);
  }
  const std::vector<ComparedFrame> frames = compare_recording(rec, zero).frames;
  std::vector<int> segment;
  for (const ComparedFrame& f : frames) segment.push_back(f.trial_index);

  // Calibration scene: the user's scene, or the same scene on a coarser built-in mesh (the reduced
  // model then carries the mesh correction; FEM runs of --verify/--refine/--fem-calibrate and
  // fitted.toml keep the user's mesh).
  Scene cal_scene = scene;
  if (opt.calibration_h_mm > 0.0) {
    if (scene.string("mesh.source") != "pneunet")
      throw InputError("diagnose: --calibration-h needs the built-in mesher (mesh.source = \"pneunet\"); this scene's mesh "
                       "comes from a deck (" + scene.string("mesh.file") + "): coarsen the deck itself, or omit --calibration-h");
    cal_scene = scene.with({"mesh.h_mm=" + fmt("%.17g", opt.calibration_h_mm)});
  }
  if (opt.progress)
    std::fprintf(stderr, "diagnose: tracing the elastic path%s ...\n",
                 opt.calibration_h_mm > 0.0 ? " (calibration mesh) and sweeping the scene's mesh" : "");
  const RomEvaluator rom(cal_scene, rec, frames, opt.rom_points, opt.calibration_h_mm > 0.0 ? &scene : nullptr);
  if (opt.progress) {
    std::fprintf(stderr, "diagnose: elastic path traced to %.1f kPa, %d material points (%.1f s)\n",
                 rom.path().path_pressure_Pa().back() * 1e-3, rom.path().num_points(),
                 std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    if (!rom.fine_curve().empty())
      std::fprintf(stderr,
                   "diagnose: calibration mesh %ld dof, scene mesh %ld dof: angle at %.1f kPa %.3f vs %.3f deg "
                   "(the calibration mesh is driven at %.2f kPa there)\n",
                   rom.dofs(), rom.fine_dofs(), rom.inlet_max_Pa() * 1e-3, rom.coarse_curve().back(), rom.fine_curve().back(),
                   rom.pressure_map_Pa().back() * 1e-3);
  }
  long rom_runs = 0;
  std::mutex mu;

  DiagnosisResult out;
  auto metrics = [&](const Scene& s) { return compare_recording(rec, rom.series(s)); };
  const Comparison base = metrics(cal_scene);
  ++rom_runs;
  // A recording in another convention (the bend counted the other way, radians under angle_deg:
  // analysis/compare.cpp) is not a missing physical effect: every candidate would be fitted to it.
  for (const std::string& w : base.warnings)
    if (w.find("runs opposite to the model's") != std::string::npos || w.find("probably in radians") != std::string::npos)
      throw InputError(opt.data_path + ": " + w + ". diagnose stops here: no physical effect explains that");
  out.baseline_nrmse = base.nrmse;
  for (const TrialComparison& t : base.trials) out.baseline_nrmse_per_trial.push_back(t.nrmse);
  out.noise_floor_nrmse = base.noise_floor_nrmse;
  const Signature sig = signature_of(base);

  std::vector<std::string> selected_sets;
  std::vector<std::pair<const CandidateEffect*, std::vector<double>>> chosen;  // selected, with constants
  Comparison current = base;
  double current_rss = base.rss_deg2;
  std::vector<bool> used(cands.size(), false);
  for (int round = 1; round <= opt.max_effects; ++round) {
    std::vector<CandidateResult> results(cands.size());
    std::vector<std::size_t> todo;
    for (std::size_t i = 0; i < cands.size(); ++i)
      if (!used[i]) todo.push_back(i);
    if (todo.empty()) break;
    // Discrepancy principle (Morozov): once the residual is at the noise floor, no further effect
    // can pass the third significance test (an NRMSE gain >= min_gain_of_floor x floor) without
    // fitting below the noise floor, so the next round cannot select anything: stop.
    if (round > 1 && opt.stop_at_noise_floor && current.nrmse < (1.0 + opt.min_gain_of_floor) * out.noise_floor_nrmse) {
      out.stopped = "after round " + std::to_string(round - 1) + ": the residual (NRMSE " + fmt("%.4f", current.nrmse) +
                    ") is within " + fmt("%.0f", 100.0 * opt.min_gain_of_floor) + " % of the noise floor (" +
                    fmt("%.4f", out.noise_floor_nrmse) +
                    "), so no further effect could be significant without fitting the noise (--all-rounds tries them anyway)";
      if (opt.progress) std::fprintf(stderr, "diagnose: stopped %s\n", out.stopped.c_str());
      break;
    }
    const Scene cur_scene = cal_scene.with(selected_sets);
    // Longest first: a candidate whose runs are static FEM sweeps (gravity) costs ~10x the others,
    // so it starts at once and the cheap ones fill the other cores (the order changes no result).
    // The same flag picks the candidates calibrated on interpolated node runs below.
    std::vector<char> costly(cands.size(), 0);
    for (std::size_t i : todo) {
      try {
        costly[i] = rom.uses_fem_sweeps(cur_scene.with(cands[i]->sets(cur_scene, initial_values(*cands[i]))));
      } catch (const std::exception&) {
        // only an ordering hint: a candidate whose scene does not build fails in its calibration below
      }
    }
    std::stable_sort(todo.begin(), todo.end(), [&](std::size_t a, std::size_t b) { return costly[a] > costly[b]; });
    const auto t_round = std::chrono::steady_clock::now();
    tbb::parallel_for(std::size_t{0}, todo.size(), [&](std::size_t j) {
      const CandidateEffect& c = *cands[todo[j]];
      CandidateResult& r = results[todo[j]];
      r.effect = c.name;
      r.round = round;
      for (const CandidateParameter& p : c.params) r.param_names.push_back(p.name);
      // Where every run costs a static FEM sweep (elastic with gravity), a one-parameter candidate
      // with a declared interpolation is calibrated on the model interpolated between a few node
      // runs (app/elastic_curve.h): 5-7 sweeps instead of one per evaluation. The calibrated value
      // is then evaluated exactly (metrics() below), so the reported error is the FEM's.
      const auto tc = std::chrono::steady_clock::now();  // calibration wall time, node sweeps included
      std::vector<std::vector<double>> node_frames;
      std::vector<double> node_x;  // calibration coordinate of each usable node (smooth)
      if (c.interpolation != ParameterInterpolation::none && c.params.size() == 1 && costly[todo[j]]) {
        const std::vector<double> at = interpolation_nodes(c.interpolation, c.params[0]);
        std::vector<std::vector<double>> nf(at.size());
        tbb::parallel_for(std::size_t{0}, at.size(), [&](std::size_t node) {
          try {
            nf[node] = rom.at_frames(cur_scene.with(c.sets(cur_scene, {at[node]})));
          } catch (const PhysicsError&) {
            // A node the FEM cannot reach (e.g. a softened actuator past its limit point).
          }
        });
        if (c.interpolation == ParameterInterpolation::rig_angle) {
          bool all = true;  // the trigonometric basis needs every node
          for (const auto& f : nf) all = all && !f.empty();
          if (all) node_frames = std::move(nf);
        } else {
          // Keep the longest run of consecutive reachable nodes (>= 4: a cubic at least); values
          // outside it are run one by one (and fail there like the nodes did).
          std::vector<bool> reachable;
          for (const auto& f : nf) reachable.push_back(!f.empty());
          const NodeRun run = longest_reachable_run(reachable, 4);
          for (std::size_t node = run.first; node < run.first + run.count; ++node) {
            node_frames.push_back(std::move(nf[node]));
            node_x.push_back(scale(c.params[0], at[node]));
          }
        }
      }
      auto rss = [&](const std::vector<double>& v) {
        std::vector<double> w;
        if (!node_frames.empty() && c.interpolation == ParameterInterpolation::rig_angle) {
          const auto rw = rig_angle_weights(v[0] * 3.14159265358979323846 / 180.0);
          w.assign(rw.begin(), rw.end());
        } else if (!node_frames.empty()) {
          const double x = scale(c.params[0], v[0]);
          if (x >= node_x.front() - 1e-12 && x <= node_x.back() + 1e-12) w = lagrange_weights(node_x, x);
        }
        if (!w.empty()) {
          std::vector<double> m(frames.size(), 0.0);
          for (std::size_t node = 0; node < w.size(); ++node)
            for (std::size_t i = 0; i < m.size(); ++i) m[i] += w[node] * node_frames[node][i];
          return rss_of(m, frames);
        }
        const Scene s = cur_scene.with(c.sets(cur_scene, v));
        return rss_of(rom.at_frames(s), frames);
      };
      const Calibration cal = calibrate(c, rss, opt.max_evaluations);
      r.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - tc).count();
      r.evaluations = cal.evaluations;
      r.trace = cal.trace;
      {
        std::lock_guard<std::mutex> lock(mu);
        rom_runs += cal.evaluations;
        if (opt.progress)
          std::fprintf(stderr, "  round %d %-14s rss %.4g deg^2 (%d runs, %.1f s)\n", round, c.name.c_str(), cal.rss,
                       cal.evaluations, r.wall_s);
      }
      if (!std::isfinite(cal.rss)) {
        r.error = cal.error.empty() ? "calibration failed" : cal.error;
        r.nrmse = std::numeric_limits<double>::infinity();
        return;
      }
      r.params = cal.values;
      r.sets = c.sets(cur_scene, cal.values);
      const Comparison cmp = metrics(cur_scene.with(r.sets));
      r.nrmse = cmp.nrmse;
      r.rss_deg2 = cmp.rss_deg2;
      for (const TrialComparison& t : cmp.trials) r.nrmse_per_trial.push_back(t.nrmse);
      std::vector<double> res;
      for (const ComparedFrame& f : cmp.frames) res.push_back(f.model_deg - f.measured_deg);
      const double n_eff = effective_sample_size(res, segment);
      r.delta_aic = n_eff * std::log(std::max(cmp.rss_deg2, 1e-300) / std::max(current_rss, 1e-300)) +
                    2.0 * static_cast<double>(c.params.size());
      const double excess = sq(current.nrmse) - sq(out.noise_floor_nrmse);
      r.removed = excess > 0.0 ? (sq(current.nrmse) - sq(cmp.nrmse)) / excess : 0.0;
      // Third condition: an absolute gain of at least a tenth of the noise floor. Near the floor
      // the "excess" is tiny and noise-fitting can remove a large fraction of it (measured on the
      // control dataset: 0.0098 -> 0.0097 with a floor of 0.0096 passed the first two tests).
      r.significant = r.delta_aic <= opt.aic_threshold && r.removed >= opt.min_removed &&
                      current.nrmse - cmp.nrmse >= opt.min_gain_of_floor * out.noise_floor_nrmse;
      r.why = c.name + (r.significant ? " is likely missing: " : " does not explain the error: ") + "it removes " +
              fmt("%.0f", 100.0 * std::max(0.0, r.removed)) + " % of the error above the noise floor (NRMSE " +
              fmt("%.4f", current.nrmse) + " -> " + fmt("%.4f", cmp.nrmse) + ", delta AIC " + fmt("%.1f", r.delta_aic) +
              " with " + std::to_string(c.params.size()) + " parameter(s)). Residual signature: " + evidence(c.name, sig) +
              ". " + c.signature;
      r.at_bound = params_at_bounds(c, r.params);
      for (const std::string& name : r.at_bound) {
        const auto p = std::find_if(c.params.begin(), c.params.end(), [&](const CandidateParameter& q) { return q.name == name; });
        const double v = r.params[static_cast<std::size_t>(p - c.params.begin())];
        r.why += " Caution: " + name + " = " + fmt("%.4g", v) + " sits at the edge of its calibrated range [" + fmt("%g", p->lo) +
                 ", " + fmt("%g", p->hi) + "]: the effect is pushed to an extreme, as when it stands in for a misfit of "
                 "another kind (the elastic response, the mesh, an effect not in the catalog); weigh it less.";
      }
    });
    if (opt.progress)
      std::fprintf(stderr, "diagnose: round %d done (%.1f s; %.1f s since the start)\n", round,
                   std::chrono::duration<double>(std::chrono::steady_clock::now() - t_round).count(),
                   std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    std::vector<std::size_t> order = todo;
    std::sort(order.begin(), order.end());  // catalog order among equals, whatever the run order was
    std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return results[a].nrmse < results[b].nrmse; });
    for (std::size_t i : order) out.candidates.push_back(results[i]);
    const CandidateResult& best = results[order.front()];
    if (!best.significant) break;
    used[order.front()] = true;
    chosen.emplace_back(cands[order.front()], best.params);
    out.selected.push_back(best.effect);
    if (round == 1) out.missing_effect = best.effect;
    selected_sets.insert(selected_sets.end(), best.sets.begin(), best.sets.end());
    current = metrics(cal_scene.with(selected_sets));
    current_rss = current.rss_deg2;
  }
  out.final_nrmse = current.nrmse;

  refine_with_fem(scene, cal_scene, rec, frames, rom, opt, chosen, selected_sets, rom_runs, out);
  out.rom_runs = rom_runs;

  const Scene fitted = scene.with(selected_sets);
  out.fitted_toml = "# pneufem diagnose: the input scene plus the selected effects (" +
                    (out.selected.empty() ? std::string("none") : out.selected.front()) +
                    (out.selected.size() > 1 ? " + " + out.selected[1] : std::string()) + ") with calibrated constants.\n" +
                    "# Data: " + opt.data_path + "\n" + fitted.to_toml();

  if (opt.verify || opt.refine > 0 || opt.fem_calibration_runs > 0) verify_with_fem(scene, fitted, rec, opt, out);
  out.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  write_diagnosis(scene, fitted, rom, chosen, opt, out);
  return out;
}

}  // namespace pneufem
