#include "app/diagnose.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <sstream>

#include <nlopt.hpp>
#include <tbb/global_control.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_invoke.h>

#include "analysis/compare.h"
#include "analysis/steps.h"
#include "app/compare.h"
#include "app/drive.h"
#include "app/effect_catalog.h"
#include "app/elastic_curve.h"
#include "app/json.h"
#include "app/run.h"
#include "engine/angle.h"
#include "engine/assembly.h"
#include "engine/path_model.h"
#include "engine/static_solver.h"
#include "materials/errors.h"
#include "scenes/build_model.h"
#include "scenes/pressure_lag.h"

namespace fs = std::filesystem;

namespace pneufem {

namespace {

/// The elastic reference of a scene: every inelastic effect table switched off, no gravity, no
/// pressure lag (the path model adds gravity and lag itself; stiffness scales are elastic and stay).
Scene elastic_reference(const Scene& scene) {
  std::vector<std::string> sets;
  for (const std::string& m : scene.table_keys("materials"))
    for (const std::string& sub : scene.table_keys("materials." + m))
      if (scene.has("materials." + m + "." + sub + ".enabled")) sets.push_back("materials." + m + "." + sub + ".enabled=false");
  sets.push_back("gravity.g_m_s2=[0.0, 0.0, 0.0]");
  sets.push_back("gravity.rig_angle_deg=-1.0");
  if (scene.has("load.pressure_lag_s")) sets.push_back("load.pressure_lag_s=0.0");
  return scene.with(sets);
}

/// Cache key of a scene's elastic FEM curve: its TOML without the lag (curves are lag-free) and
/// without the tables of disabled effects, whose constants do not change the model (otherwise
/// every calibration run of a history effect on top of gravity missed the cache of its elastic
/// gravity offset, one FEM sweep per run).
std::string curve_key(const Scene& s) { return s.with({"load.pressure_lag_s=0.0"}).model_toml(); }

bool has_history(const Model& m) {
  for (const Part& p : m.parts)
    if (p.material->state_size() > 0) return true;
  return false;
}

/// Reduced-model replay of a recording for any variant of the base scene (same mesh).
///
/// Calibration mesh. With `mesh_scene` (the user's scene: the same model on a finer mesh) the
/// reduced model runs on `base` (a coarser mesh of the same geometry) driven by a mapped chamber
/// pressure phi(p) = p_c(theta_f(p)): the pressure at which the calibration mesh's elastic path
/// reaches the angle the scene's mesh reaches at p (theta_f from one static sweep of the scene's
/// mesh, p_c from the traced path). Why map the pressure and not add an angle offset: a coarse
/// mesh is too stiff (~7-10 % in angle from h = 2 to 4 mm on the default actuator, ~19 % from 2 to
/// 8 mm on a 3-chamber one), i.e. its error acts like a stiffness error, and a pressure map makes
/// the elastic baseline exact (up to interpolation) AND keeps a stiffness scale s exact when
/// p_c(theta) / p_f(theta) is constant: s p_c(theta) = p_c(theta_f(p)) gives p_f(theta) = p / s. An
/// additive angle offset theta_f(p) - theta_c(p) would not: on the 3-chamber case of
/// tests/app/test_diagnose.cpp (CalibrationMesh; theta ~ p^1.4, coarse 19 % stiffer) it biases a
/// calibrated scale by ~4 % (power-law estimate), the map by 1.9 % (measured). History effects
/// see the deformation the scene's mesh would have (same angle), so their strain-driven evolution
/// is alike. Without any correction the coarse mesh's stiffness is itself "a missing stiffness
/// effect". On the default actuator at 45 kPa the h = 6 mesh bends 55 deg, the h = 2 mesh 77 deg.
class RomEvaluator {
 public:
  RomEvaluator(const Scene& base, const Recording& rec, const std::vector<ComparedFrame>& frames, int rom_points,
               const Scene* mesh_scene = nullptr)
      : rec_(rec), frames_(frames) {
    ref_ = build_model(elastic_reference(base));
    double p_max = 0.0;
    for (const TrialRecording& t : rec.trials)
      for (double p : t.pressure_kPa.value) p_max = std::max(p_max, p);
    p_max_Pa_ = std::max(1e3, p_max * 1e3);
    DriveOptions d;
    d.max_report_gap_s = 0.5;  // creep and damage inside holds: 0.5 s states, linear in between
    inlet_ = measured_load(rec, d, base.number("load.rest_s"), true, offset_);
    rest_s_ = base.number("load.rest_s");
    for (const TrialLoad& tr : inlet_.trials)
      for (double p : tr.pressure_Pa) inlet_max_Pa_ = std::max(inlet_max_Pa_, p);
    PathModelOptions po;
    po.p_top_Pa = 1.8 * p_max_Pa_;  // softened models reach angles the elastic one reaches only above p_max
    po.dp_Pa = p_max_Pa_ / 40.0;
    po.max_points = rom_points;
    po.max_dt_s = 0.5;
    po.newton = ref_->solver.quasi_static.newton;
    if (!mesh_scene) {
      path_ = std::make_unique<PathModel>(ref_->model, po);
      return;
    }
    // The scene mesh's sweep (the expensive part) runs beside the coarse path trace.
    std::string fine_error;
    tbb::parallel_invoke([&] { path_ = std::make_unique<PathModel>(ref_->model, po); },
                         [&] {
                           try {
                             const std::unique_ptr<BuiltModel> fine = build_model(elastic_reference(*mesh_scene));
                             fine_dofs_ = fine->model.num_dofs();
                             fine_curve_ = static_angle_curve(*fine, inlet_max_Pa_, kMeshCurvePoints);
                           } catch (const PhysicsError& e) {
                             fine_error = e.what();
                           }
                         });
    if (!fine_error.empty())
      throw PhysicsError("diagnose: the static sweep of the scene's own mesh (for the calibration mesh's pressure map) to " +
                         fmt_kPa(inlet_max_Pa_) + " failed: " + fine_error);
    const std::vector<double>& th = path_->path_angle_deg();
    const std::vector<double>& pc = path_->path_pressure_Pa();
    for (std::size_t i = 0; i < fine_curve_.size(); ++i) {
      const double p = inlet_max_Pa_ * static_cast<double>(i) / kMeshCurvePoints;
      if (fine_curve_[i] > th.back() + 1e-9)
        throw PhysicsError("diagnose: the calibration mesh's elastic path ends at " + fmt_kPa(pc.back()) + " (" +
                           std::to_string(th.back()) + " deg, a limit point) before the angle the scene's mesh reaches at " +
                           fmt_kPa(p) + " (" + std::to_string(fine_curve_[i]) + " deg): use a finer --calibration-h");
      map_Pa_.push_back(interpolate_quadratic(th, pc, fine_curve_[i]));
      coarse_curve_.push_back(interpolate_quadratic(pc, th, p));
    }
  }

  /// The calibration mesh's pressure map (empty without one): static angles (deg) of the scene's
  /// mesh and of the calibration mesh at p = inlet_max_Pa() i / n, and phi(p) there (Pa).
  const std::vector<double>& fine_curve() const { return fine_curve_; }
  const std::vector<double>& coarse_curve() const { return coarse_curve_; }
  const std::vector<double>& pressure_map_Pa() const { return map_Pa_; }
  long fine_dofs() const { return fine_dofs_; }
  long dofs() const { return ref_->model.num_dofs(); }
  double inlet_max_Pa() const { return inlet_max_Pa_; }

  const PathModel& path() const { return *path_; }

  /// Model angle (deg) at every frame of `frames_` for the variant scene.
  std::vector<double> at_frames(const Scene& variant) const {
    const std::vector<std::vector<double>> per_trial = simulate(variant, true);
    std::vector<double> out(frames_.size());
    std::vector<std::size_t> next(rec_.trials.size(), 0);
    for (std::size_t i = 0; i < frames_.size(); ++i) out[i] = per_trial[frames_[i].trial_index][next[frames_[i].trial_index]++];
    return out;
  }

  /// Model angle series at every measured angle time of every trial.
  std::vector<Series> series(const Scene& variant) const {
    const std::vector<std::vector<double>> a = simulate(variant, false);
    std::vector<Series> out(rec_.trials.size());
    for (std::size_t k = 0; k < rec_.trials.size(); ++k) {
      out[k].t_s = rec_.trials[k].angle_deg.t_s;
      out[k].value = a[k];
    }
    return out;
  }

  /// Per trial, the model angle at the kept frames (kept_only) or at every angle sample.
  /// True when a run of `variant` costs a static FEM sweep (elastic with gravity), not the reduced model.
  bool uses_fem_sweeps(const Scene& variant) const {
    const std::unique_ptr<BuiltModel> bm = build_model(variant);
    return !has_history(bm->model) && bm->model.gravity_m_s2.norm() > 0.0;
  }

 private:
  std::vector<std::vector<double>> simulate(const Scene& variant, bool kept_only) const {
    const std::unique_ptr<BuiltModel> bm = build_model(variant);
    const double lag = variant.has("load.pressure_lag_s") ? variant.number("load.pressure_lag_s") : 0.0;
    const LoadHistory load = lag > 0.0 ? apply_pressure_lag(inlet_, lag, 1e-4 * p_max_Pa_) : inlet_;
    const std::size_t nt = rec_.trials.size();
    // Engine times of the requested samples, per trial.
    std::vector<std::vector<double>> times(nt);
    if (kept_only) {
      for (const ComparedFrame& f : frames_) times[f.trial_index].push_back(f.t_s - offset_[f.trial_index]);
    } else {
      for (std::size_t k = 0; k < nt; ++k)
        for (double t : rec_.trials[k].angle_deg.t_s) times[k].push_back(t - offset_[k]);
    }
    std::vector<std::vector<double>> out(nt);
    if (!has_history(bm->model)) {
      // Elastic (stiffness, gravity, lag): the angle is a function of the chamber pressure alone:
      // one sweep 0 -> max pressure, then a lookup per sample. Without gravity the reduced model
      // gives the sweep (exact for the reference, ~1 % for a uniform stiffness change: see
      // tests/app/test_path_model.cpp); gravity loads a different deformation mode, which the
      // 1-dof reduced model cannot represent, so then the sweep is the full static FEM (fewer
      // points, quadratic interpolation; cached by scene without the lag).
      // Curves span the inlet's peak pressure, which a lagged chamber pressure never exceeds, so
      // every lag shares one curve per scene (the cache key leaves the lag out).
      const double hi = chamber(inlet_max_Pa_);
      const bool fem = bm->model.gravity_m_s2.norm() > 0.0;
      const int n = fem ? kFemCurvePoints : 120;
      std::vector<double> th;
      if (fem) {
        th = elastic_curve(variant, bm.get(), hi, n);
      } else {
        PathLoad pl;
        for (int i = 0; i <= n; ++i) {
          pl.t_s.push_back(i * 0.1);
          pl.p_Pa.push_back(hi * i / n);
        }
        th = path_->run(bm->model, pl);
      }
      for (std::size_t k = 0; k < nt; ++k) {
        const TrialLoad& tr = load.trials[k];
        for (double t : times[k]) {
          out[k].push_back(curve_at(th, hi, chamber(tr.pressure(std::clamp(t, 0.0, tr.duration())))));
        }
      }
      return out;
    }
    // History: one continuous replay of all trials (internal variables carry over).
    PathLoad pl;
    std::vector<double> start(nt);
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
    std::vector<double> th = path_->run(bm->model, pl);
    if (bm->model.gravity_m_s2.norm() > 0.0) {
      // Gravity loads a deformation mode the 1-dof reduced model cannot carry: add the elastic
      // FEM's gravity offset at the same pressure, theta_g(p) - theta_0(p) (exact for the elastic
      // model; for history effects it neglects how their softening changes the sag, a second-order
      // term). Two static sweeps per gravity vector (cached).
      const Scene el = elastic_reference(variant);
      const Vec3 gv = bm->model.gravity_m_s2;
      char buf[160];
      std::snprintf(buf, sizeof buf, "gravity.g_m_s2=[%.17g, %.17g, %.17g]", gv.x(), gv.y(), gv.z());
      const double hi = chamber(inlet_max_Pa_);  // pl holds mapped pressures
      const std::vector<double> cg = elastic_curve(el.with({buf}), nullptr, hi, kFemCurvePoints);
      const std::vector<double> c0 = elastic_curve(el, nullptr, hi, kFemCurvePoints);
      std::vector<double> off(cg.size());
      for (std::size_t i = 0; i < cg.size(); ++i) off[i] = cg[i] - c0[i];
      for (std::size_t i = 0; i < th.size(); ++i) th[i] += curve_at(off, hi, pl.p_Pa[i]);
    }
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

  static constexpr int kFemCurvePoints = 16;
  /// Sweep points of the scene mesh for the pressure map (one static continuation of that mesh;
  /// its cost dominates diagnose with --calibration-h). The map phi(p) is close to linear (a
  /// stiffness-like mesh error: phi(p)/p falls from 1.13 to 1.10 over 0-20 kPa on the 3-chamber
  /// case of tests/app/test_diagnose.cpp), so 12 points suffice: dropping every other point of a
  /// 24-point map moved it by 1e-4 kPa there, far below the reduced model's own error.
  static constexpr int kMeshCurvePoints = 12;

  /// The pressure that drives the reduced model: p itself, or phi(p) with a calibration mesh
  /// (interpolated between the sweep's points; identity above the sweep's top is never needed:
  /// the sweep spans the inlet's peak).
  double chamber(double p) const { return map_Pa_.empty() ? p : curve_at(map_Pa_, inlet_max_Pa_, p); }

  static std::string fmt_kPa(double p_Pa) {
    char b[32];
    std::snprintf(b, sizeof b, "%.2f kPa", p_Pa * 1e-3);
    return b;
  }

  /// y(x) on samples (xs, ys) with xs increasing (not uniform): quadratic Lagrange interpolation on
  /// the three samples nearest x (linear extrapolation is not needed: callers stay inside).
  static double interpolate_quadratic(const std::vector<double>& xs, const std::vector<double>& ys, double x) {
    const std::size_t n = xs.size();
    if (n < 3) return n ? ys.front() : 0.0;
    const std::size_t k = static_cast<std::size_t>(std::upper_bound(xs.begin(), xs.end(), x) - xs.begin());
    const std::size_t c = std::clamp<std::size_t>(k, 1, n - 2);  // centre: samples c-1, c, c+1
    const double x0 = xs[c - 1], x1 = xs[c], x2 = xs[c + 1];
    return ys[c - 1] * (x - x1) * (x - x2) / ((x0 - x1) * (x0 - x2)) + ys[c] * (x - x0) * (x - x2) / ((x1 - x0) * (x1 - x2)) +
           ys[c + 1] * (x - x0) * (x - x1) / ((x2 - x0) * (x2 - x1));
  }

  /// A curve sampled at p = hi i / n (n = th.size() - 1) at pressure p (quadratic 3-point Lagrange
  /// interpolation on the nearest samples; p clamped to [0, hi]).
  static double curve_at(const std::vector<double>& th, double hi, double p) {
    const int n = static_cast<int>(th.size()) - 1;
    const double x = hi > 0.0 ? std::clamp(p / hi, 0.0, 1.0) * n : 0.0;
    const int c = std::clamp(static_cast<int>(std::lround(x)), 1, n - 1);
    const double u = x - c;
    return th[c] + 0.5 * u * (th[c + 1] - th[c - 1]) + 0.5 * u * u * (th[c + 1] - 2 * th[c] + th[c - 1]);
  }

  /// Angles (deg) of the static FEM equilibria at p = hi i / n, i = 0..n (cached by scene; `bm`
  /// is the variant's built model, or null to build it on a cache miss).
  std::vector<double> elastic_curve(const Scene& variant, const BuiltModel* bm_in, double hi, int n) const {
    const std::string key = curve_key(variant);
    {
      std::lock_guard<std::mutex> lock(cache_mu_);
      const auto it = curves_.find(key);
      if (it != curves_.end()) return it->second;
    }
    std::unique_ptr<BuiltModel> own;
    if (!bm_in) own = build_model(variant);
    const BuiltModel& bm = bm_in ? *bm_in : *own;
    const std::vector<double> th = static_angle_curve(bm, hi, n);
    std::lock_guard<std::mutex> lock(cache_mu_);
    curves_[key] = th;
    return th;
  }

  mutable std::mutex cache_mu_;
  mutable std::map<std::string, std::vector<double>> curves_;
  const Recording& rec_;
  const std::vector<ComparedFrame>& frames_;
  std::unique_ptr<BuiltModel> ref_;
  std::unique_ptr<PathModel> path_;
  std::vector<double> fine_curve_, coarse_curve_, map_Pa_;
  long fine_dofs_ = 0;
  LoadHistory inlet_;
  std::vector<double> offset_;
  double rest_s_ = 0.0, p_max_Pa_ = 0.0, inlet_max_Pa_ = 0.0;
};

double rss_of(const std::vector<double>& model, const std::vector<ComparedFrame>& frames) {
  double s = 0.0;
  for (std::size_t i = 0; i < frames.size(); ++i) s += (model[i] - frames[i].measured_deg) * (model[i] - frames[i].measured_deg);
  return s;
}

/// Value of a catalog parameter at the scaled coordinate x in [0, 1].
std::vector<double> initial_values(const CandidateEffect& c) {
  std::vector<double> v;
  for (const CandidateParameter& p : c.params) v.push_back(p.initial);
  return v;
}

double unscale(const CandidateParameter& p, double x) {
  x = std::clamp(x, 0.0, 1.0);
  return p.log ? p.lo * std::pow(p.hi / p.lo, x) : p.lo + x * (p.hi - p.lo);
}
double scale(const CandidateParameter& p, double v) {
  v = std::clamp(v, p.lo, p.hi);
  return p.log ? std::log(v / p.lo) / std::log(p.hi / p.lo) : (v - p.lo) / (p.hi - p.lo);
}

/// Parameter values of the interpolation nodes (app/elastic_curve.h): the rig angle's five angles
/// (deg), or Chebyshev-Lobatto nodes of the calibration coordinate (log or linear over the bounds).
std::vector<double> interpolation_nodes(ParameterInterpolation how, const CandidateParameter& p) {
  std::vector<double> v;
  if (how == ParameterInterpolation::rig_angle) {
    for (int j = 0; j < kRigAngleNodes; ++j) v.push_back(rig_angle_node_rad(j) * 180.0 / 3.14159265358979323846);
  } else {
    for (int j = 0; j < kSmoothNodes; ++j) v.push_back(unscale(p, smooth_node(j)));
  }
  return v;
}
struct Calibration {
  std::vector<double> values;
  double rss = std::numeric_limits<double>::infinity();
  int evaluations = 0;
  std::string error;
  std::vector<CalibrationPoint> trace;
};

/// Minimises rss(values) over the candidate's box: a coarse grid (5 points per parameter for
/// one parameter, 3 per parameter above), then golden-section search (one parameter) or BOBYQA
/// (several) from the best grid point.
/// The optimiser sees log(rss), which has the same minimiser: near a limit point the RSS of
/// neighbouring constants spans six decades (a softened model that snaps through is off by tens
/// of degrees), and BOBYQA's quadratic models of the raw RSS are then dominated by those points.
/// A failed evaluation (no equilibrium) is recorded as +infinity but scores as one decade worse
/// than the worst finite RSS seen, so it repels the search without breaking the model.
Calibration calibrate(const CandidateEffect& c, const std::function<double(const std::vector<double>&)>& rss,
                      int budget, const std::vector<double>* start = nullptr) {
  const std::size_t k = c.params.size();
  Calibration best;
  // Largest finite RSS seen (deg^2), for the failure score; starts at 1e6 deg^2 (tens of degrees
  // RMS over a recording) so that a failure before any large RSS never scores like a good fit.
  double worst = 1e6;
  // Optimisers re-evaluate points (BOBYQA starts at the point the grid already scored): each costs a
  // model run (a full FEM run for --fem-calibrate), so repeats are answered from memory.
  std::map<std::vector<double>, double> seen;
  std::function<double(const std::vector<double>&)> eval_new;
  auto eval = [&](const std::vector<double>& x) {
    const auto hit = seen.find(x);
    if (hit != seen.end()) return hit->second;
    const double f = eval_new(x);
    seen.emplace(x, f);
    return f;
  };
  eval_new = [&](const std::vector<double>& x) {
    std::vector<double> v(k);
    for (std::size_t i = 0; i < k; ++i) v[i] = unscale(c.params[i], x[i]);
    double r = std::numeric_limits<double>::infinity();
    ++best.evaluations;
    std::string err;
    try {
      r = rss(v);
    } catch (const std::exception& e) {
      err = e.what();
      if (best.error.empty()) best.error = err;
    }
    best.trace.push_back({v, r, err});
    if (r < best.rss) {
      best.rss = r;
      best.values = v;
    }
    if (std::isfinite(r)) {
      worst = std::max(worst, r);
      return std::log(std::max(r, 1e-300));
    }
    return std::log(std::max(worst, 1e-300)) + std::log(10.0);
  };
  if (k == 0) {
    eval({});
    return best;
  }
  // Coarse grid (and the catalog's initial point).
  std::vector<double> x0(k);
  for (std::size_t i = 0; i < k; ++i) x0[i] = scale(c.params[i], start ? (*start)[i] : c.params[i].initial);
  double fbest = eval(x0);
  // From a given start (refinement): a local search only, in a cell of +-1/per around it.
  const int per = start ? 6 : (k == 1 ? 5 : 3);
  std::vector<int> idx(k, 0);
  std::vector<double> xbest = x0;
  while (!start) {
    std::vector<double> x(k);
    for (std::size_t i = 0; i < k; ++i) x[i] = (idx[i] + 0.5) / per;
    const double f = eval(x);
    if (f < fbest) fbest = f, xbest = x;
    std::size_t i = 0;
    while (i < k && ++idx[i] == per) idx[i++] = 0;
    if (i == k) break;
  }
  const int left = std::max(4, budget - best.evaluations);
  if (k == 1) {
    // Golden section on the grid cell around the best point (+- one cell).
    double a = std::max(0.0, xbest[0] - 1.0 / per), b = std::min(1.0, xbest[0] + 1.0 / per);
    const double r = 0.5 * (std::sqrt(5.0) - 1.0);
    double c1 = b - r * (b - a), c2 = a + r * (b - a);
    double f1 = eval({c1}), f2 = eval({c2});
    for (int it = 2; it < left && b - a > 1e-4; ++it) {
      if (f1 < f2) {
        b = c2, c2 = c1, f2 = f1;
        c1 = b - r * (b - a);
        f1 = eval({c1});
      } else {
        a = c1, c1 = c2, f1 = f2;
        c2 = a + r * (b - a);
        f2 = eval({c2});
      }
    }
    return best;
  }
  nlopt::opt opt(nlopt::LN_BOBYQA, static_cast<unsigned>(k));
  opt.set_lower_bounds(std::vector<double>(k, 0.0));
  opt.set_upper_bounds(std::vector<double>(k, 1.0));
  opt.set_maxeval(left);
  opt.set_xtol_abs(1e-4);
  opt.set_initial_step(std::vector<double>(k, 0.5 / per));
  auto fn = [](const std::vector<double>& x, std::vector<double>&, void* data) {
    return (*static_cast<std::function<double(const std::vector<double>&)>*>(data))(x);
  };
  std::function<double(const std::vector<double>&)> f = eval;
  opt.set_min_objective(fn, &f);
  std::vector<double> x = xbest;
  double fx = 0.0;
  try {
    opt.optimize(x, fx);
  } catch (const std::exception&) {
    // roundoff / forced stop: the best point seen is kept by eval()
  }
  return best;
}

double sq(double v) { return v * v; }

/// Residual signature of a comparison: numbers the reasons are made of.
struct Signature {
  std::vector<double> trial_rmse;     ///< per trial
  double growth = 1.0;                ///< rmse of the last trial / first
  double creep_top_deg = 0.0;         ///< mean (measured - model) spread at the top third of the levels
  double creep_low_deg = 0.0;         ///< ... at the other levels
  double creep_first_deg = 0.0, creep_last_deg = 0.0;  ///< mean spread difference, first / last trial
  double first_vs_rest = 0.0;         ///< mean residual of trial 1 minus that of the others
  double early_deg = 0.0, late_deg = 0.0;  ///< mean residual in the first 0.5 s of steps / after the mark
  double rest_deg = 0.0;              ///< mean residual on steps at (near) zero pressure
  double proportional = 0.0;          ///< correlation of mark residual with the measured mark angle
};

Signature signature_of(const Comparison& c) {
  Signature s;
  double top = 0.0, low = 0.0;
  int ntop = 0, nlow = 0;
  std::vector<double> mean_res;
  double lvl_max = 0.0;
  for (const TrialComparison& t : c.trials)
    for (const StepComparison& st : t.steps) lvl_max = std::max(lvl_max, st.level_kPa);
  std::vector<double> xs, ys;
  double rest = 0.0;
  int nrest = 0;
  for (std::size_t k = 0; k < c.trials.size(); ++k) {
    const TrialComparison& t = c.trials[k];
    s.trial_rmse.push_back(t.rmse_deg);
    double cr = 0.0, mr = 0.0;
    int ncr = 0, nmr = 0;
    for (const StepComparison& st : t.steps) {
      const double d = st.spread_measured_deg - st.spread_model_deg;
      if (std::isfinite(d)) {
        (st.level_kPa >= 2.0 / 3.0 * lvl_max ? top : low) += d;
        ++(st.level_kPa >= 2.0 / 3.0 * lvl_max ? ntop : nlow);
        cr += d, ++ncr;
      }
      if (std::isfinite(st.mean_residual_deg)) mr += st.mean_residual_deg * st.frames, nmr += static_cast<int>(st.frames);
      if (std::isfinite(st.measured_mark_deg) && std::isfinite(st.model_mark_deg)) {
        xs.push_back(st.measured_mark_deg);
        ys.push_back(st.model_mark_deg - st.measured_mark_deg);
      }
      if (std::abs(st.level_kPa) < 0.05 * lvl_max && std::isfinite(st.mean_residual_deg)) rest += st.mean_residual_deg, ++nrest;
    }
    if (k == 0) s.creep_first_deg = ncr ? cr / ncr : 0.0;
    if (k + 1 == c.trials.size()) s.creep_last_deg = ncr ? cr / ncr : 0.0;
    mean_res.push_back(nmr ? mr / nmr : 0.0);
  }
  s.creep_top_deg = ntop ? top / ntop : 0.0;
  s.creep_low_deg = nlow ? low / nlow : 0.0;
  if (!s.trial_rmse.empty() && s.trial_rmse.front() > 0) s.growth = s.trial_rmse.back() / s.trial_rmse.front();
  if (mean_res.size() > 1) {
    double others = 0.0;
    for (std::size_t k = 1; k < mean_res.size(); ++k) others += mean_res[k];
    s.first_vs_rest = mean_res[0] - others / static_cast<double>(mean_res.size() - 1);
  }
  double e = 0.0, l = 0.0;
  long ne = 0, nl = 0;
  for (std::size_t i = 0; i < c.profile.t_s.size(); ++i) {
    if (!std::isfinite(c.profile.mean_deg[i])) continue;
    if (c.profile.t_s[i] < 0.5) e += c.profile.mean_deg[i] * c.profile.count[i], ne += c.profile.count[i];
    if (c.profile.t_s[i] > 2.5) l += c.profile.mean_deg[i] * c.profile.count[i], nl += c.profile.count[i];
  }
  s.early_deg = ne ? e / ne : 0.0;
  s.late_deg = nl ? l / nl : 0.0;
  s.rest_deg = nrest ? rest / nrest : 0.0;
  if (xs.size() > 2) {
    double mx = 0, my = 0;
    for (std::size_t i = 0; i < xs.size(); ++i) mx += xs[i], my += ys[i];
    mx /= xs.size(), my /= ys.size();
    double sxy = 0, sxx = 0, syy = 0;
    for (std::size_t i = 0; i < xs.size(); ++i)
      sxy += (xs[i] - mx) * (ys[i] - my), sxx += sq(xs[i] - mx), syy += sq(ys[i] - my);
    s.proportional = sxx > 0 && syy > 0 ? sxy / std::sqrt(sxx * syy) : 0.0;
  }
  return s;
}

std::string fmt(const char* f, double a) {
  char b[96];
  std::snprintf(b, sizeof b, f, a);
  return b;
}

/// The sentence about the residual feature that `effect` explains.
std::string evidence(const std::string& effect, const Signature& s) {
  const std::string growth = "the error grows from trial 1 to the last trial (rms " + fmt("%.2f", s.trial_rmse.front()) +
                             " -> " + fmt("%.2f", s.trial_rmse.back()) + " deg)";
  const std::string creep = "the measured angle keeps rising during the top holds (" + fmt("%+.2f", s.creep_top_deg) +
                            " deg more than modelled over a hold, vs " + fmt("%+.2f", s.creep_low_deg) + " at the lower steps)";
  if (effect == "fatigue") return growth + ", and " + creep;
  if (effect == "viscoelastic")
    return "inside the holds the measured angle creeps more than the model (" + fmt("%+.2f", s.creep_first_deg) +
           " deg in trial 1, " + fmt("%+.2f", s.creep_last_deg) + " deg in the last trial)";
  if (effect == "mullins")
    return "trial 1 differs from the later trials (mean residual " + fmt("%+.2f", s.first_vs_rest) +
           " deg relative to them), the signature of softening set by the first peak load";
  if (effect == "stiffness")
    return "the error scales with the angle (correlation of the step error with the angle " + fmt("%+.2f", s.proportional) +
           ") with little time structure";
  if (effect == "pressure_lag")
    return "the error concentrates right after each pressure step (mean residual " + fmt("%+.2f", s.early_deg) +
           " deg in the first 0.5 s vs " + fmt("%+.2f", s.late_deg) + " deg after the mark)";
  if (effect == "gravity")
    return "the model misses an angle at rest and low pressure (mean residual " + fmt("%+.2f", s.rest_deg) +
           " deg at 0 kPa)";
  return "its calibrated constants reshape the residual";
}

}  // namespace

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
  auto fem_at_frames = [&](const Scene& s, std::string* failure, double* failure_time_s) {
    DriveOptions d;
    d.threads = opt.threads;
    d.partial_on_failure = true;
    const DriveResult dr = simulate_recording(s, rec, d);
    *failure = dr.failure;
    *failure_time_s = dr.failure_time_s;
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
  for (int it = 0; it < opt.refine && !chosen.empty(); ++it) {
    if (opt.progress) std::fprintf(stderr, "diagnose: refinement %d with the full FEM ...\n", it + 1);
    std::string failure;
    double failure_time_s = -1.0;
    const std::vector<double> fem = fem_at_frames(scene.with(selected_sets), &failure, &failure_time_s);
    std::size_t solved = 0;
    for (double v : fem) solved += std::isfinite(v) ? 1 : 0;
    if (!failure.empty()) {
      std::ostringstream m;
      m << "refinement " << it + 1 << ": the full FEM stopped at t = " << failure_time_s << " s of trial "
        << frames[std::min(solved, frames.size() - 1)].trial_index + 1 << " (" << solved << " of " << frames.size()
        << " frames solved; corrected there, reduced model alone after): " << failure;
      out.fem_error += (out.fem_error.empty() ? "" : "; ") + m.str();
      if (opt.progress) std::fprintf(stderr, "diagnose: %s\n", m.str().c_str());
      if (solved == 0) break;
    } else {
      const double fem_rss = rss_of(fem, frames);
      if (opt.progress) std::fprintf(stderr, "diagnose: refinement %d: FEM rss %.4g deg^2 (best %.4g)\n", it + 1, fem_rss, best_fem_rss);
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
  out.rom_runs = rom_runs;

  const Scene fitted = scene.with(selected_sets);
  out.fitted_toml = "# pneufem diagnose: the input scene plus the selected effects (" +
                    (out.selected.empty() ? std::string("none") : out.selected.front()) +
                    (out.selected.size() > 1 ? " + " + out.selected[1] : std::string()) + ") with calibrated constants.\n" +
                    "# Data: " + opt.data_path + "\n" + fitted.to_toml();

  if (opt.verify || opt.refine > 0 || opt.fem_calibration_runs > 0) {
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
    out.verified_fitted_nrmse = fem_nrmse(fitted, "fitted");
  }
  out.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();

  // ---- outputs
  fs::create_directories(opt.out_dir);
  json::Object root;
  root.add_str("version", version_string());
  root.add_str("command", opt.command_line);
  root.add_str("data", opt.data_path);
  json::Object b;
  b.add("nrmse", out.baseline_nrmse).add("nrmse_per_trial", json::array(out.baseline_nrmse_per_trial));
  if (out.verified_baseline_nrmse >= 0) b.add("nrmse_fem", out.verified_baseline_nrmse);
  root.add("baseline", b.str(2));
  std::string cs = "[";
  for (std::size_t i = 0; i < out.candidates.size(); ++i) {
    const CandidateResult& c = out.candidates[i];
    json::Object p;
    for (std::size_t j = 0; j < c.params.size(); ++j) p.add(c.param_names[j], c.params[j]);
    json::Object o;
    o.add_str("effect", c.effect).add("round", c.round).add("nrmse", c.nrmse);
    o.add("nrmse_per_trial", json::array(c.nrmse_per_trial)).add("params", c.params.empty() ? "{}" : p.str(6));
    std::string sets = "[";
    for (std::size_t j = 0; j < c.sets.size(); ++j) sets += (j ? ", " : "") + json::quote(c.sets[j]);
    o.add("sets", sets + "]").add("delta_aic", c.delta_aic).add("removed_fraction", c.removed);
    o.add("significant", c.significant ? "true" : "false").add("evaluations", c.evaluations).add("wall_s", c.wall_s);
    o.add_str("why", c.why);
    std::string ab = "[";
    for (std::size_t j = 0; j < c.at_bound.size(); ++j) ab += (j ? ", " : "") + json::quote(c.at_bound[j]);
    o.add("at_bound", ab + "]");
    if (!c.error.empty()) o.add_str("error", c.error);
    cs += (i ? ",\n    " : "\n    ") + o.str(4);
  }
  root.add("candidates", cs + "\n  ]");
  root.add("missing_effect", out.missing_effect.empty() ? "null" : json::quote(out.missing_effect));
  if (!out.stopped.empty()) root.add("stopped", json::quote(out.stopped));
  std::string sel = "[";
  for (std::size_t j = 0; j < out.selected.size(); ++j) sel += (j ? ", " : "") + json::quote(out.selected[j]);
  root.add("selected", sel + "]");
  if (!out.refined_params.empty()) {
    std::string rp = "{";
    for (std::size_t j = 0; j < chosen.size(); ++j) {
      json::Object p;
      for (std::size_t i = 0; i < chosen[j].first->params.size(); ++i) p.add(chosen[j].first->params[i].name, chosen[j].second[i]);
      rp += (j ? ", " : "") + json::quote(chosen[j].first->name) + ": " + p.str(4);
    }
    root.add("refined_params", rp + "}");
  }
  root.add("noise_floor_nrmse", out.noise_floor_nrmse);
  root.add("final_nrmse", out.final_nrmse);
  if (out.verified_fitted_nrmse >= 0) root.add("final_nrmse_fem", out.verified_fitted_nrmse);
  if (!out.fem_error.empty()) root.add_str("fem_error", out.fem_error);
  json::Object method;
  method.add_str("evaluator", "reduced path model (engine/path_model.h), " + std::to_string(rom.path().num_points()) +
                                  " material points, elastic path to " +
                                  fmt("%.1f", rom.path().path_pressure_Pa().back() * 1e-3) + " kPa");
  if (opt.calibration_h_mm > 0.0) {
    // The calibration mesh and its correction, so a reader can judge its size against the effects'.
    json::Object cm;
    const std::vector<double>& f = rom.fine_curve();
    const std::vector<double>& c = rom.coarse_curve();
    std::vector<double> p;
    for (std::size_t i = 0; i < f.size(); ++i) p.push_back(rom.inlet_max_Pa() * 1e-3 * static_cast<double>(i) / static_cast<double>(f.size() - 1));
    cm.add("h_mm", opt.calibration_h_mm).add("dofs", static_cast<double>(rom.dofs())).add("scene_dofs", static_cast<double>(rom.fine_dofs()));
    std::vector<double> m;
    for (double v : rom.pressure_map_Pa()) m.push_back(v * 1e-3);
    cm.add("pressure_kPa", json::array(p)).add("scene_mesh_angle_deg", json::array(f)).add("calibration_mesh_angle_deg", json::array(c));
    cm.add("mapped_pressure_kPa", json::array(m));
    method.add("calibration_mesh", cm.str(4));
  }
  method.add("aic_threshold", opt.aic_threshold).add("min_removed", opt.min_removed).add("max_effects", opt.max_effects);
  method.add("reduced_model_runs", static_cast<double>(out.rom_runs)).add("wall_s", out.wall_s);
  root.add("method", method.str(2));
  root.add("scene", scene.to_json());
  write_file_atomic((fs::path(opt.out_dir) / "diagnosis.json").string(), root.str() + "\n");
  write_file_atomic((fs::path(opt.out_dir) / "fitted.toml").string(), out.fitted_toml);
  std::string csv = "round,effect,nrmse,delta_aic,removed_fraction,significant,evaluations,params\n";
  for (const CandidateResult& c : out.candidates) {
    std::string p;
    for (std::size_t j = 0; j < c.params.size(); ++j) p += (j ? ";" : "") + c.param_names[j] + "=" + json::num(c.params[j]);
    csv += std::to_string(c.round) + "," + c.effect + "," + json::num(c.nrmse) + "," + json::num(c.delta_aic) + "," +
           json::num(c.removed) + "," + (c.significant ? "1" : "0") + "," + std::to_string(c.evaluations) + "," + p + "\n";
  }
  write_file_atomic((fs::path(opt.out_dir) / "diagnosis.csv").string(), csv);
  std::string tr = "round,effect,evaluation,params,rss_deg2,error\n";
  for (const CandidateResult& c : out.candidates)
    for (std::size_t i = 0; i < c.trace.size(); ++i) {
      std::string p;
      for (std::size_t j = 0; j < c.trace[i].params.size(); ++j)
        p += (j ? ";" : "") + c.param_names[j] + "=" + json::num(c.trace[i].params[j]);
      std::string e = c.trace[i].error;
      std::replace(e.begin(), e.end(), '"', '\'');
      tr += std::to_string(c.round) + "," + c.effect + "," + std::to_string(i + 1) + "," + p + "," +
            (std::isfinite(c.trace[i].rss_deg2) ? json::num(c.trace[i].rss_deg2) : std::string("inf")) + ",\"" + e + "\"\n";
    }
  write_file_atomic((fs::path(opt.out_dir) / "calibration.csv").string(), tr);
  HistoryEntry h;
  h.time_utc = utc_now();
  h.source = "diagnose";
  h.label = "diagnose baseline (reduced model)";
  h.scene_hash = scene_hash(scene);
  h.nrmse = out.baseline_nrmse;
  h.trial_nrmse = out.baseline_nrmse_per_trial;
  append_history(opt.out_dir, h);
  if (!out.selected.empty()) {
    h.label = "diagnose + " + out.selected.front() + (out.selected.size() > 1 ? " + " + out.selected[1] : "") +
              " (reduced model)";
    h.scene_hash = scene_hash(fitted);
    h.nrmse = out.final_nrmse;
    h.trial_nrmse.clear();
    append_history(opt.out_dir, h);
  }
  return out;
}

}  // namespace pneufem
