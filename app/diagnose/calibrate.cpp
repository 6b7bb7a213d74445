// The calibration of a candidate's constants (app/diagnose/detail.h): the [0, 1] scaling of its
// parameters (log where the catalog says so), the nodes of interpolated calibrations, and the
// bounded search itself (grid, then golden section or NLopt BOBYQA). Apart from the selection
// because it knows nothing of recordings or models: it minimises a function of a candidate's few
// bounded constants, which the selection (reduced model) and the FEM stages (full FEM) hand it.
#include <algorithm>
#include <cmath>
#include <exception>
#include <map>

#include <Eigen/Eigenvalues>
#include <nlopt.hpp>

#include "app/diagnose/detail.h"
#include "app/diagnose/elastic_curve.h"

namespace pneufem::diagnose_detail {

double rss_of(const std::vector<double>& model, const std::vector<ComparedFrame>& frames) {
  double s = 0.0;
  for (std::size_t i = 0; i < frames.size(); ++i) s += (model[i] - frames[i].measured_deg) * (model[i] - frames[i].measured_deg);
  return s;
}

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

std::vector<double> interpolation_nodes(ParameterInterpolation how, const CandidateParameter& p) {
  std::vector<double> v;
  if (how == ParameterInterpolation::rig_angle) {
    for (int j = 0; j < kRigAngleNodes; ++j) v.push_back(rig_angle_node_rad(j) * 180.0 / 3.14159265358979323846);
  } else {
    for (int j = 0; j < kSmoothNodes; ++j) v.push_back(unscale(p, smooth_node(j)));
  }
  return v;
}

namespace {

/// The objective calibrate() minimises, on the [0, 1] calibration coordinates of a candidate's
/// constants: log(RSS), a failed run (an exception, or a non-finite RSS) scored one decade above the
/// largest finite RSS seen; each point is run once (optimisers re-evaluate points: BOBYQA starts at
/// the point the grid already scored, and each run costs a model run, a full FEM run for
/// --fem-calibrate), and every run is traced into `best`, which keeps the best point.
class CalibrationObjective {
 public:
  CalibrationObjective(const CandidateEffect& c, const std::function<double(const std::vector<double>&)>& rss, Calibration& best)
      : c_(c), rss_(rss), best_(best) {}

  double operator()(const std::vector<double>& x) {
    const auto hit = seen_.find(x);
    if (hit != seen_.end()) return hit->second;
    const double f = run(x);
    seen_.emplace(x, f);
    return f;
  }

  /// Calibration coordinates of best.values.
  const std::vector<double>& best_x() const { return best_x_; }

 private:
  double run(const std::vector<double>& x) {
    const std::size_t k = c_.params.size();
    std::vector<double> v(k);
    for (std::size_t i = 0; i < k; ++i) v[i] = unscale(c_.params[i], x[i]);
    double r = std::numeric_limits<double>::infinity();
    ++best_.evaluations;
    std::string err;
    try {
      r = rss_(v);
    } catch (const std::exception& e) {
      err = e.what();
      if (best_.error.empty()) best_.error = err;
    }
    best_.trace.push_back({v, r, err});
    if (r < best_.rss) {
      best_.rss = r;
      best_.values = v;
      best_x_ = x;
    }
    if (std::isfinite(r)) {
      worst_ = std::max(worst_, r);
      return std::log(std::max(r, 1e-300));
    }
    return std::log(std::max(worst_, 1e-300)) + std::log(10.0);
  }

  const CandidateEffect& c_;
  const std::function<double(const std::vector<double>&)>& rss_;
  Calibration& best_;
  // Largest finite RSS seen (deg^2), for the failure score; starts at 1e6 deg^2 (tens of degrees
  // RMS over a recording) so that a failure before any large RSS never scores like a good fit.
  double worst_ = 1e6;
  std::map<std::vector<double>, double> seen_;
  std::vector<double> best_x_;
};

/// The start of the local search: the catalog's initial point (or `start`) and, without a start, a
/// grid of `per` points per constant (cell centres); the calibration coordinates of the best point.
std::vector<double> grid_start(const CandidateEffect& c, CalibrationObjective& eval, const std::vector<double>* start, int per) {
  const std::size_t k = c.params.size();
  std::vector<double> x0(k);
  for (std::size_t i = 0; i < k; ++i) x0[i] = scale(c.params[i], start ? (*start)[i] : c.params[i].initial);
  double fbest = eval(x0);
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
  return xbest;
}

/// One constant: golden section on the grid cell around `xbest` (+- one cell), `left` runs at most.
void golden_section(CalibrationObjective& eval, double xbest, int per, int left) {
  double a = std::max(0.0, xbest - 1.0 / per), b = std::min(1.0, xbest + 1.0 / per);
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
}

/// Several constants: BOBYQA from `xbest` (first trust region half a grid cell), restarted from the
/// best point while a restart still gains, until `budget` runs in all (best.evaluations) are spent.
void bobyqa_with_restarts(CalibrationObjective& eval, Calibration& best, std::vector<double> xbest, int per, int left, int budget) {
  const std::size_t k = xbest.size();
  constexpr double kLogRssTol = 1e-4;
  nlopt::opt opt(nlopt::LN_BOBYQA, static_cast<unsigned>(k));
  opt.set_lower_bounds(std::vector<double>(k, 0.0));
  opt.set_upper_bounds(std::vector<double>(k, 1.0));
  opt.set_maxeval(left);
  opt.set_xtol_abs(1e-4);
  opt.set_ftol_abs(kLogRssTol);
  opt.set_initial_step(std::vector<double>(k, 0.5 / per));
  auto fn = [](const std::vector<double>& x, std::vector<double>&, void* data) {
    return (*static_cast<std::function<double(const std::vector<double>&)>*>(data))(x);
  };
  std::function<double(const std::vector<double>&)> f = [&eval](const std::vector<double>& x) { return eval(x); };
  opt.set_min_objective(fn, &f);
  // Restarts. BOBYQA stops when one step gains less than ftol, which also happens early in a walk
  // down a narrow valley, while its trust region is still small. Measured on the hidden
  // viscoelastic recording (tests/data/hidden): it stopped after 17 runs at RSS 79.8 deg^2
  // (gamma 0.27, tau 13.7 s) where the valley leads down to 10 deg^2 (gamma 0.59, tau 3.2 s),
  // and a 3 % coarser pressure grid of the reduced model's path decided between stopping there and
  // walking on. So a stop is trusted only when a fresh start from the best point (a new quadratic
  // model, the first trust region again; its repeated points come from memory) gains no more than
  // ftol either, or the budget is spent.
  std::vector<double> x = std::move(xbest);
  for (double before = std::numeric_limits<double>::infinity(); best.evaluations < budget;) {
    opt.set_maxeval(std::max(1, budget - best.evaluations));
    double fx = 0.0;
    try {
      opt.optimize(x, fx);
    } catch (const std::exception&) {
      // roundoff / forced stop: the best point seen is kept by the objective
    }
    if (!std::isfinite(best.rss)) break;
    const double now = std::log(std::max(best.rss, 1e-300));
    if (!(before - now > kLogRssTol)) break;
    before = now;
    x = eval.best_x();
  }
}

}  // namespace

Calibration calibrate(const CandidateEffect& c, const std::function<double(const std::vector<double>&)>& rss,
                      int budget, const std::vector<double>* start) {
  const std::size_t k = c.params.size();
  Calibration best;
  CalibrationObjective eval(c, rss, best);
  if (k == 0) {
    eval({});
    return best;
  }
  // From a given start (refinement): a local search only, in a cell of +-1/per around it.
  const int per = start ? 6 : (k == 1 ? 5 : 3);
  const std::vector<double> xbest = grid_start(c, eval, start, per);
  const int left = std::max(4, budget - best.evaluations);
  if (k == 1)
    golden_section(eval, xbest[0], per, left);
  else
    bobyqa_with_restarts(eval, best, xbest, per, left, budget);
  return best;
}

TradeOff trade_off(const CandidateEffect& c, const std::function<double(const std::vector<double>&)>& rss,
                   const std::vector<double>& values, double rss_best, double rss_tol) {
  TradeOff out;
  out.rss_tol = rss_tol;
  const int k = static_cast<int>(c.params.size());
  if (k < 2 || values.size() != c.params.size() || !std::isfinite(rss_best)) return out;
  Eigen::VectorXd x0(k);
  for (int i = 0; i < k; ++i) x0[i] = scale(c.params[i], values[i]);
  // A failed run (no equilibrium) is no fit: +infinity, outside every range.
  auto f = [&](const Eigen::VectorXd& x) {
    std::vector<double> v(k);
    for (int i = 0; i < k; ++i) v[i] = unscale(c.params[i], x[i]);
    ++out.evaluations;
    try {
      const double r = rss(v);
      return std::isfinite(r) ? r : std::numeric_limits<double>::infinity();
    } catch (const std::exception&) {
      return std::numeric_limits<double>::infinity();
    }
  };
  // Hessian of the RSS by forward/backward differences with step h = 0.02 in the calibration scale
  // (2 % of a linear range, 10 % of a 150x log range: wide enough that the reduced model's
  // integration tolerances do not show, narrow against the valleys' curvature), centred inside
  // the box so a constant at its bound still gets a two-sided stencil.
  const double h = 0.02;
  Eigen::VectorXd xc = x0.cwiseMax(h).cwiseMin(1.0 - h);
  const double fc = (xc - x0).norm() == 0.0 ? rss_best : f(xc);
  Eigen::MatrixXd H(k, k);
  std::vector<double> fp(k), fm(k);
  for (int i = 0; i < k; ++i) {
    Eigen::VectorXd e = Eigen::VectorXd::Zero(k);
    e[i] = h;
    fp[i] = f(xc + e), fm[i] = f(xc - e);
    H(i, i) = (fp[i] - 2.0 * fc + fm[i]) / (h * h);
  }
  for (int i = 0; i < k; ++i)
    for (int j = i + 1; j < k; ++j) {
      Eigen::VectorXd e = Eigen::VectorXd::Zero(k);
      e[i] = h, e[j] = h;
      H(i, j) = H(j, i) = (f(xc + e) - fp[i] - fp[j] + fc) / (h * h);
    }
  if (!H.allFinite()) return out;
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(H);
  const Eigen::VectorXd dir = eig.eigenvectors().col(0);  // smallest curvature: the valley
  const double limit = (1.0 + rss_tol) * rss_best;
  std::vector<Eigen::VectorXd> accepted = {x0};
  for (const double sign : {1.0, -1.0}) {
    const Eigen::VectorXd d = sign * dir;
    // Largest t keeping x0 + t d inside the box.
    double t_max = std::numeric_limits<double>::infinity();
    for (int i = 0; i < k; ++i) {
      if (d[i] > 1e-12) t_max = std::min(t_max, (1.0 - x0[i]) / d[i]);
      if (d[i] < -1e-12) t_max = std::min(t_max, -x0[i] / d[i]);
    }
    double t_in = 0.0, t_out = -1.0;
    for (double t = 0.05; t_in < t_max; t *= 2.0) {
      const double tt = std::min(t, t_max);
      if (f(x0 + tt * d) <= limit) {
        t_in = tt;
      } else {
        t_out = tt;
        break;
      }
    }
    for (int b = 0; b < 2 && t_out > 0.0; ++b) {
      const double tm = 0.5 * (t_in + t_out);
      (f(x0 + tm * d) <= limit ? t_in : t_out) = tm;
    }
    if (t_in > 0.0) accepted.push_back(x0 + t_in * d);
  }
  out.lo.assign(k, std::numeric_limits<double>::infinity());
  out.hi.assign(k, -std::numeric_limits<double>::infinity());
  for (const Eigen::VectorXd& x : accepted)
    for (int i = 0; i < k; ++i) {
      const double v = unscale(c.params[i], x[i]);
      out.lo[i] = std::min(out.lo[i], v);
      out.hi[i] = std::max(out.hi[i], v);
    }
  return out;
}

namespace {

/// The Hessian of the RSS from its stencil's values (joint_intervals' stencil order: the centre, then
/// +h and -h along each constant, then +h along each pair).
Eigen::MatrixXd hessian_from_stencil(const std::vector<double>& f, int k, double h) {
  const double fc = f[0];
  Eigen::MatrixXd H(k, k);
  for (int i = 0; i < k; ++i) H(i, i) = (f[1 + 2 * i] - 2.0 * fc + f[2 + 2 * i]) / (h * h);
  std::size_t o = 1 + 2 * static_cast<std::size_t>(k);
  for (int i = 0; i < k; ++i)
    for (int j = i + 1; j < k; ++j) H(i, j) = H(j, i) = (f[o++] - f[1 + 2 * i] - f[1 + 2 * j] + fc) / (h * h);
  return H;
}

/// One end of a joint interval: where the profile path of a constant, walked one way from the best
/// point, meets the RSS contour.
struct ProfileEnd {
  Eigen::VectorXd dir;  // profile path direction (component i = +1 or -1)
  double t = 0.0;       // distance along it (the change of constant i, calibration scale)
  double t_max = 0.0;   // the box
};

/// The quadratic model's ends, two per constant (lower, upper): the profile paths of H^-1 (flat
/// directions floored at a curvature of dRSS / 2, as joint_intervals says), cut at the box.
std::vector<ProfileEnd> quadratic_ends(const Eigen::MatrixXd& H, const Eigen::VectorXd& x0, double drss) {
  const int k = static_cast<int>(x0.size());
  // Flat directions: curvature below 2 dRSS / 4 (the RSS would rise by less than dRSS across two
  // calibration ranges), negative ones included.
  const Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(H);
  const Eigen::VectorXd lam = eig.eigenvalues().cwiseMax(0.5 * drss);
  const Eigen::MatrixXd Hinv = eig.eigenvectors() * lam.cwiseInverse().asDiagonal() * eig.eigenvectors().transpose();
  std::vector<ProfileEnd> ends;
  for (int i = 0; i < k; ++i)
    for (const double sign : {-1.0, 1.0}) {
      ProfileEnd e;
      e.dir = sign * Hinv.col(i) / Hinv(i, i);
      e.t_max = std::numeric_limits<double>::infinity();
      for (int j = 0; j < k; ++j) {
        if (e.dir[j] > 1e-12) e.t_max = std::min(e.t_max, (1.0 - x0[j]) / e.dir[j]);
        if (e.dir[j] < -1e-12) e.t_max = std::min(e.t_max, -x0[j] / e.dir[j]);
      }
      e.t = std::min(std::sqrt(2.0 * drss * Hinv(i, i)), e.t_max);
      ends.push_back(e);
    }
  return ends;
}

/// Checks the ends on the real RSS and corrects them: `measure(due)` evaluates the ends flagged in
/// `due` and writes their rises ((RSS - best) / dRSS) into `rise`. Up to three corrections where an
/// end's rise is outside [0.5, 2]: the rise is taken as a power of t along the path, t^2 at first
/// (the quadratic model) and then the power the last two measurements show (a secant in log-log,
/// exact for one power; the power within [1, 8], each step at most 4x out or in). An end that did
/// not rise at all goes 4x out, to the box at most.
template <class Measure>
void correct_ends(std::vector<ProfileEnd>& ends, std::vector<double>& rise, const Measure& measure) {
  std::vector<char> due(ends.size(), 1);  // ends to (re-)measure
  measure(due);
  std::vector<double> t_prev(ends.size(), 0.0), r_prev(ends.size(), 0.0);
  for (int pass = 0; pass < 3; ++pass) {
    bool moved = false;
    for (std::size_t n = 0; n < ends.size(); ++n) {
      ProfileEnd& e = ends[n];
      if (e.t <= 0.0 || (rise[n] >= 0.5 && rise[n] <= 2.0)) continue;
      if (rise[n] < 1.0 && e.t >= e.t_max) continue;  // the contour lies beyond the bound
      double factor = 4.0;
      if (rise[n] > 0.0) {
        double power = 2.0;
        if (t_prev[n] > 0.0 && r_prev[n] > 0.0 && t_prev[n] != e.t)
          power = std::clamp(std::log(rise[n] / r_prev[n]) / std::log(e.t / t_prev[n]), 1.0, 8.0);
        factor = std::clamp(std::pow(1.0 / rise[n], 1.0 / power), 0.25, 4.0);
      }
      t_prev[n] = e.t, r_prev[n] = rise[n];
      e.t = std::min(e.t * factor, e.t_max);
      due[n] = 1;
      moved = true;
    }
    if (!moved) break;
    measure(due);
  }
}

}  // namespace

JointIntervals joint_intervals(const std::vector<CandidateParameter>& params,
                               const std::function<std::vector<double>(const std::vector<std::vector<double>>&)>& rss_batch,
                               const std::vector<double>& values, double rss_tol) {
  JointIntervals out;
  out.rss_tol = rss_tol;
  const int k = static_cast<int>(params.size());
  if (k < 1 || values.size() != params.size()) return out;
  Eigen::VectorXd x0(k);
  for (int i = 0; i < k; ++i) x0[i] = scale(params[i], values[i]);
  auto to_values = [&](const Eigen::VectorXd& x) {
    std::vector<double> v(k);
    for (int i = 0; i < k; ++i) v[i] = unscale(params[i], x[i]);
    return v;
  };
  auto evaluate = [&](const std::vector<Eigen::VectorXd>& xs) {
    std::vector<std::vector<double>> pts;
    for (const Eigen::VectorXd& x : xs) pts.push_back(to_values(x));
    std::vector<double> r = rss_batch(pts);
    out.evaluations += static_cast<int>(pts.size());
    for (double& v : r)
      if (!std::isfinite(v)) v = std::numeric_limits<double>::infinity();
    return r;
  };
  // The Hessian's stencil, as in trade_off: step 0.02 of the calibration scale, centred inside the
  // box so that a constant at its bound still gets a two-sided stencil.
  const double h = 0.02;
  const Eigen::VectorXd xc = x0.cwiseMax(h).cwiseMin(1.0 - h);
  const bool centred = xc == x0;  // else the best point lies within h of a bound: one run more
  std::vector<Eigen::VectorXd> stencil = {xc};
  for (int i = 0; i < k; ++i) {
    stencil.push_back(xc + h * Eigen::VectorXd::Unit(k, i));
    stencil.push_back(xc - h * Eigen::VectorXd::Unit(k, i));
  }
  for (int i = 0; i < k; ++i)
    for (int j = i + 1; j < k; ++j) stencil.push_back(xc + h * (Eigen::VectorXd::Unit(k, i) + Eigen::VectorXd::Unit(k, j)));
  if (!centred) stencil.push_back(x0);
  const std::vector<double> f = evaluate(stencil);
  const double fc = f[0], f0 = centred ? fc : f.back();
  if (!std::isfinite(f0) || !std::isfinite(fc)) return out;
  const Eigen::MatrixXd H = hessian_from_stencil(f, k, h);
  if (!H.allFinite()) return out;
  out.rss_best = f0;
  const double drss = rss_tol * f0;
  // Per constant and side: the quadratic model's end, then the check on the real RSS.
  std::vector<ProfileEnd> ends = quadratic_ends(H, x0, drss);
  std::vector<double> rise(ends.size(), 0.0);
  correct_ends(ends, rise, [&](std::vector<char>& due) {
    std::vector<Eigen::VectorXd> xs;
    std::vector<std::size_t> which;
    for (std::size_t n = 0; n < ends.size(); ++n)
      if (due[n] && ends[n].t > 0.0) xs.push_back(x0 + ends[n].t * ends[n].dir), which.push_back(n);
    const std::vector<double> fe = evaluate(xs);
    for (std::size_t m = 0; m < which.size(); ++m) rise[which[m]] = (fe[m] - f0) / drss;
    std::fill(due.begin(), due.end(), 0);
  });
  out.c.resize(k);
  for (int i = 0; i < k; ++i) {
    JointInterval& ci = out.c[i];
    const ProfileEnd& lo = ends[2 * i];
    const ProfileEnd& hi = ends[2 * i + 1];
    ci.lo = unscale(params[i], x0[i] - lo.t);
    ci.hi = unscale(params[i], x0[i] + hi.t);
    const bool lo_at_bound = lo.t >= lo.t_max && rise[2 * i] < 1.0;
    const bool hi_at_bound = hi.t >= hi.t_max && rise[2 * i + 1] < 1.0;
    ci.rise_lo = lo_at_bound ? std::numeric_limits<double>::quiet_NaN() : rise[2 * i];
    ci.rise_hi = hi_at_bound ? std::numeric_limits<double>::quiet_NaN() : rise[2 * i + 1];
    ci.identified = !(lo_at_bound && hi_at_bound);
  }
  return out;
}

}  // namespace pneufem::diagnose_detail
