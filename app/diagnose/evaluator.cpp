// PathModelEvaluator (app/diagnose/evaluator.h): the reduced-model replay of a recording, its calibration
// mesh's pressure map and its cache of elastic FEM curves. Kept apart from the calibration and
// the selection, which only see angles per frame: this is where diagnose drives the path model
// and the static FEM sweeps (the full-FEM runs of --refine and --verify are fem.cpp).
#include "app/diagnose/evaluator.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include <tbb/parallel_invoke.h>

#include "app/diagnose/detail.h"
#include "app/diagnose/elastic_curve.h"
#include "app/simulate/drive.h"
#include "app/simulate/result_cache.h"
#include "core/errors.h"
#include "scenes/pressure_lag.h"
#include "scenes/scene_settings.h"

namespace pneufem::diagnose_detail {

namespace {

/// The scene without its chamber-pressure lag (both orders): the lag acts on the load, not the curves.
Scene without_lag(const Scene& s) { return s.with({"load.pressure_lag_s=0.0", "load.pressure_lag2_s=0.0"}); }

/// Cache key of a scene's elastic FEM curve: its TOML without the lag (curves are lag-free) and
/// without the tables of disabled effects, whose constants do not change the model (otherwise
/// every calibration run of a history effect on top of gravity missed the cache of its elastic
/// gravity offset, one FEM sweep per run).
std::string curve_key(const Scene& s) { return without_lag(s).model_toml(); }

bool has_history(const Model& m) {
  for (const Part& p : m.parts)
    if (p.material->state_size() > 0) return true;
  return false;
}

}  // namespace


PathModelEvaluator::PathModelEvaluator(const Scene& base, const Recording& rec, const std::vector<ComparedFrame>& frames,
                           int rom_points, const Scene* mesh_scene, const std::string& cache_dir)
    : cache_dir_(cache_dir), rec_(rec), frames_(frames) {
  ref_ = build_model(elastic_reference_scene(base));
  double p_max = 0.0;
  for (const TrialRecording& t : rec.trials)
    for (double p : t.pressure_kPa.value) p_max = std::max(p_max, p);
  p_max_Pa_ = std::max(1e3, p_max * 1e3);
  DriveOptions d;
  d.max_report_gap_s = 0.5;  // creep and damage inside holds: 0.5 s states, linear in between
  rest_s_ = load_settings(base).rest_s;
  inlet_ = measured_load(rec, d, rest_s_, true, offset_);
  double inlet_max_Pa = 0.0, scene_peak_Pa = 0.0;
  for (const TrialLoad& tr : inlet_.trials)
    for (double p : tr.pressure_Pa) inlet_max_Pa = std::max(inlet_max_Pa, p);
  for (const TrialLoad& tr : ref_->load.trials)
    for (double p : tr.pressure_Pa) scene_peak_Pa = std::max(scene_peak_Pa, p);
  // Not the measured peak itself: the cache entries below are keyed by this pressure, and it must
  // be the same for every recording of one protocol (elastic_reference_peak_Pa).
  reference_peak_Pa_ = elastic_reference_peak_Pa(scene_peak_Pa, std::max(p_max_Pa_, inlet_max_Pa));
  PathModelOptions po;
  po.p_top_Pa = 1.8 * reference_peak_Pa_;  // softened models reach angles the elastic one reaches only above the peak
  po.dp_Pa = reference_peak_Pa_ / 40.0;
  po.max_points = rom_points;
  po.max_dt_s = 0.5;
  po.newton = ref_->solver.quasi_static.newton;
  auto make_path = [&] {
    if (cache_dir_.empty()) {
      path_ = std::make_unique<PathModel>(ref_->model, po);
      return;
    }
    // Stored flat: the sample count, the pressures, then each sample's displacement.
    Fnv1a h;
    h.str(executable_fingerprint());
    h.str("elastic path");
    hash_model(h, elastic_reference_scene(base), ref_->model);
    h.num(po.p_top_Pa);
    h.num(po.dp_Pa);
    const Eigen::Index nd = ref_->model.num_dofs();
    const std::vector<double> flat = cached_doubles(
        cache_dir_, "path", h.hex(),
        [&] {
          const ElasticPathTrace t = trace_elastic_path(ref_->model, po);
          std::vector<double> f = {static_cast<double>(t.p_Pa.size())};
          f.insert(f.end(), t.p_Pa.begin(), t.p_Pa.end());
          for (const Eigen::VectorXd& u : t.u) f.insert(f.end(), u.data(), u.data() + u.size());
          return f;
        },
        &path_source_);
    ElasticPathTrace t;
    const std::size_t ns = flat.empty() ? 0 : static_cast<std::size_t>(flat[0]);
    if (flat.size() != 1 + ns + ns * static_cast<std::size_t>(nd))
      throw InputError("diagnose: the cached elastic path (" + path_source_ + ") does not fit the model; delete it");
    t.p_Pa.assign(flat.begin() + 1, flat.begin() + 1 + static_cast<std::ptrdiff_t>(ns));
    for (std::size_t k = 0; k < ns; ++k)
      t.u.push_back(Eigen::Map<const Eigen::VectorXd>(flat.data() + 1 + ns + k * static_cast<std::size_t>(nd), nd));
    path_ = std::make_unique<PathModel>(ref_->model, po, t);
  };
  if (!mesh_scene) {
    make_path();
    return;
  }
  // The scene mesh's sweep (the expensive part) runs beside the coarse path trace.
  std::string fine_error;
  tbb::parallel_invoke(make_path,
                       [&] {
                         try {
                           const Scene fine_scene = elastic_reference_scene(*mesh_scene);
                           const std::unique_ptr<BuiltModel> fine = build_model(fine_scene);
                           fine_dofs_ = fine->model.num_dofs();
                           fine_curve_ = stored_curve(fine_scene, *fine, reference_peak_Pa_, kMeshCurvePoints, &fine_source_);
                         } catch (const PhysicsError& e) {
                           fine_error = e.what();
                         }
                       });
  if (!fine_error.empty())
    throw PhysicsError("diagnose: the static sweep of the scene's own mesh (for the calibration mesh's pressure map) to " +
                       fmt_kPa(reference_peak_Pa_) + " failed: " + fine_error);
  const std::vector<double>& th = path_->path_angle_deg();
  const std::vector<double>& pc = path_->path_pressure_Pa();
  for (std::size_t i = 0; i < fine_curve_.size(); ++i) {
    const double p = reference_peak_Pa_ * static_cast<double>(i) / kMeshCurvePoints;
    if (fine_curve_[i] > th.back() + 1e-9)
      throw PhysicsError("diagnose: the calibration mesh's elastic path ends at " + fmt_kPa(pc.back()) + " (" +
                         std::to_string(th.back()) + " deg, a limit point) before the angle the scene's mesh reaches at " +
                         fmt_kPa(p) + " (" + std::to_string(fine_curve_[i]) + " deg): use a finer --calibration-h");
    map_Pa_.push_back(interpolate_quadratic(th, pc, fine_curve_[i]));
    coarse_curve_.push_back(interpolate_quadratic(pc, th, p));
  }
}

std::vector<double> PathModelEvaluator::at_frames(const Scene& variant) const {
  const std::vector<std::vector<double>> per_trial = simulate(variant, true);
  std::vector<double> out(frames_.size());
  std::vector<std::size_t> next(rec_.trials.size(), 0);
  for (std::size_t i = 0; i < frames_.size(); ++i) out[i] = per_trial[frames_[i].trial_index][next[frames_[i].trial_index]++];
  return out;
}

std::vector<Series> PathModelEvaluator::series(const Scene& variant) const {
  const std::vector<std::vector<double>> a = simulate(variant, false);
  std::vector<Series> out(rec_.trials.size());
  for (std::size_t k = 0; k < rec_.trials.size(); ++k) {
    out[k].t_s = rec_.trials[k].angle_deg.t_s;
    out[k].value = a[k];
  }
  return out;
}

bool PathModelEvaluator::uses_fem_sweeps(const Scene& variant) const {
  const std::unique_ptr<BuiltModel> bm = build_model(variant);
  return !has_history(bm->model) && bm->model.gravity_m_s2.norm() > 0.0;
}

std::vector<std::vector<double>> PathModelEvaluator::sample_times(bool kept_only) const {
  const std::size_t nt = rec_.trials.size();
  std::vector<std::vector<double>> times(nt);
  if (kept_only) {
    for (const ComparedFrame& f : frames_) times[f.trial_index].push_back(f.t_s - offset_[f.trial_index]);
  } else {
    for (std::size_t k = 0; k < nt; ++k)
      for (double t : rec_.trials[k].angle_deg.t_s) times[k].push_back(t - offset_[k]);
  }
  return times;
}

std::vector<std::vector<double>> PathModelEvaluator::simulate_elastic(const Scene& variant, const BuiltModel& bm,
                                                                      const LoadHistory& load,
                                                                      const std::vector<std::vector<double>>& times) const {
  // Elastic (stiffness, gravity, lag): the angle is a function of the chamber pressure alone:
  // one sweep 0 -> max pressure, then a lookup per sample. Without gravity the reduced model
  // gives the sweep (exact for the reference, ~1 % for a uniform stiffness change: see
  // tests/engine/test_path_model.cpp); gravity loads a different deformation mode, which the
  // 1-dof reduced model cannot represent, so then the sweep is the full static FEM (fewer
  // points, quadratic interpolation; cached by scene without the lag).
  // Curves span the reference peak, above the inlet's peak pressure, which a lagged chamber
  // pressure never exceeds, so every lag shares one curve per scene (the cache key leaves the lag out).
  const std::size_t nt = rec_.trials.size();
  std::vector<std::vector<double>> out(nt);
  const double hi = chamber(reference_peak_Pa_);
  const bool fem = bm.model.gravity_m_s2.norm() > 0.0;
  const int n = fem ? kFemCurvePoints : 120;
  std::vector<double> th;
  if (fem) {
    th = elastic_curve(variant, &bm, hi, n);
  } else {
    PathLoad pl;
    for (int i = 0; i <= n; ++i) {
      pl.t_s.push_back(i * 0.1);
      pl.p_Pa.push_back(hi * i / n);
    }
    th = path_->run(bm.model, pl);
  }
  for (std::size_t k = 0; k < nt; ++k) {
    const TrialLoad& tr = load.trials[k];
    for (double t : times[k]) {
      out[k].push_back(curve_at(th, hi, chamber(tr.pressure(std::clamp(t, 0.0, tr.duration())))));
    }
  }
  return out;
}

PathLoad PathModelEvaluator::continuous_replay(const LoadHistory& load, std::vector<double>& start) const {
  const std::size_t nt = rec_.trials.size();
  PathLoad pl;
  start.assign(nt, 0.0);
  double g = 0.0;
  for (std::size_t k = 0; k < nt; ++k) {
    const TrialLoad& tr = load.trials[k];
    start[k] = g;
    for (std::size_t i = 0; i < tr.time_s.size(); ++i) {
      const double t = g + tr.time_s[i];
      if (!pl.t_s.empty() && t <= pl.t_s.back()) continue;
      pl.t_s.push_back(t);
      pl.p_Pa.push_back(chamber(tr.pressure_Pa[i]));
    }
    g += tr.duration();
    // Between trials the actuator is vented to 0 and rests for load.rest_s (as the FEM drive
    // does); with no rest, the vent takes 1 ms so the next trial starts from 0 kPa.
    const double rest = std::max(rest_s_, 1e-3);
    pl.t_s.push_back(g + std::min(1e-3, 0.5 * rest));
    pl.p_Pa.push_back(0.0);
    if (rest > 1e-3) {
      pl.t_s.push_back(g + rest);
      pl.p_Pa.push_back(0.0);
    }
    g += rest;
  }
  return pl;
}

std::vector<double> PathModelEvaluator::gravity_offset(const Scene& variant, const BuiltModel& bm, double hi) const {
  // Gravity loads a deformation mode the 1-dof reduced model cannot carry: add the elastic
  // FEM's gravity offset at the same pressure, theta_g(p) - theta_0(p) (exact for the elastic
  // model; for history effects it neglects how their softening changes the sag, a second-order
  // term). Static sweeps, cached: one per gravity vector, or, for a rig angle phi, one per node
  // of the rig-angle interpolation (app/diagnose/elastic_curve.h), the offset being sum_j w_j(phi)
  // offset(phi_j). Why interpolate: calibrating the rig angle on top of a history effect
  // otherwise costs a static FEM sweep per evaluation (measured: 24 runs, 56 s of a 84 s
  // diagnosis on the 5-chamber test actuator); five sweeps serve every angle, within ~1e-4 deg
  // of the direct sweep (RigAngleInterpolation.MatchesDirectFemSweepsBetweenNodes).
  const Scene el = elastic_reference_scene(variant);
  const std::vector<double> c0 = elastic_curve(el, nullptr, hi, kFemCurvePoints);
  std::vector<double> off(c0.size(), 0.0);
  const double rig_deg = variant.has("gravity.rig_angle_deg") ? variant.number("gravity.rig_angle_deg") : -1.0;
  if (rig_deg >= 0.0) {
    const auto w = rig_angle_weights(rig_deg * std::numbers::pi / 180.0);
    for (int j = 0; j < kRigAngleNodes; ++j) {
      const std::vector<double> cj =
          elastic_curve(el.with({"gravity.rig_angle_deg=" + fmt("%.17g", rig_angle_node_rad(j) * 180.0 / std::numbers::pi)}),
                        nullptr, hi, kFemCurvePoints);
      for (std::size_t i = 0; i < off.size(); ++i) off[i] += w[j] * (cj[i] - c0[i]);
    }
  } else {
    const Vec3 gv = bm.model.gravity_m_s2;
    char buf[160];
    std::snprintf(buf, sizeof buf, "gravity.g_m_s2=[%.17g, %.17g, %.17g]", gv.x(), gv.y(), gv.z());
    const std::vector<double> cg = elastic_curve(el.with({buf}), nullptr, hi, kFemCurvePoints);
    for (std::size_t i = 0; i < off.size(); ++i) off[i] = cg[i] - c0[i];
  }
  return off;
}

std::vector<std::vector<double>> PathModelEvaluator::simulate(const Scene& variant, bool kept_only) const {
  const std::unique_ptr<BuiltModel> bm = build_model(variant);
  const PressureLag lag = scene_pressure_lag(variant);  // first or second order (load.pressure_lag2_s)
  const LoadHistory load = lag.on() ? apply_pressure_lag(inlet_, lag, 1e-4 * p_max_Pa_) : inlet_;
  const std::vector<std::vector<double>> times = sample_times(kept_only);
  if (!has_history(bm->model)) return simulate_elastic(variant, *bm, load, times);
  // History: one continuous replay of all trials (internal variables carry over).
  std::vector<double> start;
  const PathLoad pl = continuous_replay(load, start);
  std::vector<double> th = path_->run(bm->model, pl);
  if (bm->model.gravity_m_s2.norm() > 0.0) {
    const double hi = chamber(reference_peak_Pa_);  // pl holds mapped pressures
    const std::vector<double> off = gravity_offset(variant, *bm, hi);
    for (std::size_t i = 0; i < th.size(); ++i) th[i] += curve_at(off, hi, pl.p_Pa[i]);
  }
  // Each sample by linear interpolation in the replay's time.
  const std::size_t nt = rec_.trials.size();
  std::vector<std::vector<double>> out(nt);
  for (std::size_t k = 0; k < nt; ++k) {
    const TrialLoad& tr = load.trials[k];
    for (double t : times[k]) {
      const double gt = start[k] + std::clamp(t, 0.0, tr.duration());
      const auto it = std::upper_bound(pl.t_s.begin(), pl.t_s.end(), gt);
      const std::size_t i = std::clamp<std::size_t>(static_cast<std::size_t>(it - pl.t_s.begin()), 1, pl.t_s.size() - 1);
      const double f = std::clamp((gt - pl.t_s[i - 1]) / (pl.t_s[i] - pl.t_s[i - 1]), 0.0, 1.0);
      out[k].push_back(th[i - 1] + f * (th[i] - th[i - 1]));
    }
  }
  return out;
}

std::string PathModelEvaluator::fmt_kPa(double p_Pa) {
  char b[32];
  std::snprintf(b, sizeof b, "%.2f kPa", p_Pa * 1e-3);
  return b;
}

double PathModelEvaluator::interpolate_quadratic(const std::vector<double>& xs, const std::vector<double>& ys, double x) {
  const std::size_t n = xs.size();
  if (n < 3) return n ? ys.front() : 0.0;
  const std::size_t k = static_cast<std::size_t>(std::upper_bound(xs.begin(), xs.end(), x) - xs.begin());
  const std::size_t c = std::clamp<std::size_t>(k, 1, n - 2);  // centre: samples c-1, c, c+1
  const double x0 = xs[c - 1], x1 = xs[c], x2 = xs[c + 1];
  return ys[c - 1] * (x - x1) * (x - x2) / ((x0 - x1) * (x0 - x2)) + ys[c] * (x - x0) * (x - x2) / ((x1 - x0) * (x1 - x2)) +
         ys[c + 1] * (x - x0) * (x - x1) / ((x2 - x0) * (x2 - x1));
}

double PathModelEvaluator::curve_at(const std::vector<double>& th, double hi, double p) {
  const int n = static_cast<int>(th.size()) - 1;
  const double x = hi > 0.0 ? std::clamp(p / hi, 0.0, 1.0) * n : 0.0;
  const int c = std::clamp(static_cast<int>(std::lround(x)), 1, n - 1);
  const double u = x - c;
  return th[c] + 0.5 * u * (th[c + 1] - th[c - 1]) + 0.5 * u * u * (th[c + 1] - 2 * th[c] + th[c - 1]);
}

std::vector<double> PathModelEvaluator::elastic_curve(const Scene& variant, const BuiltModel* bm_in, double hi, int n) const {
  const std::string key = curve_key(variant);
  {
    std::lock_guard<std::mutex> lock(cache_mu_);
    const auto it = curves_.find(key);
    if (it != curves_.end()) return it->second;
  }
  std::unique_ptr<BuiltModel> own;
  if (!bm_in) own = build_model(variant);
  const BuiltModel& bm = bm_in ? *bm_in : *own;
  std::string source;
  const std::vector<double> th = stored_curve(variant, bm, hi, n, &source);
  ++(source.starts_with("cache ") ? curves_from_cache_ : curves_computed_);
  std::lock_guard<std::mutex> lock(cache_mu_);
  curves_[key] = th;
  return th;
}

std::vector<double> PathModelEvaluator::stored_curve(const Scene& variant, const BuiltModel& bm, double hi, int n,
                                               std::string* source) const {
  if (source) *source = "computed";
  if (cache_dir_.empty()) return static_angle_curve(bm, hi, n);
  Fnv1a h;
  h.str(executable_fingerprint());
  h.str("static angle curve");
  hash_model(h, without_lag(variant), bm.model);  // curves are lag-free (curve_key)
  h.num(hi);
  h.num(n);
  return cached_doubles(cache_dir_, "curve", h.hex(), [&] { return static_angle_curve(bm, hi, n); }, source);
}

}  // namespace pneufem::diagnose_detail
