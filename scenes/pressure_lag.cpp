#include "scenes/pressure_lag.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

#include "core/errors.h"
#include "scenes/scene.h"

namespace pneufem {

namespace {

/// Walks the segments of `tl`, calling visit(t_a, t_b, a, b, pc_a) with the chamber pressure pc_a at t_a.
template <class Visit>
void for_each_segment(const TrialLoad& tl, double tau, Visit&& visit) {
  double pc = tl.pressure_Pa.front();
  for (std::size_t i = 0; i + 1 < tl.time_s.size(); ++i) {
    const double ta = tl.time_s[i], tb = tl.time_s[i + 1];
    const double a = tl.pressure_Pa[i], b = (tl.pressure_Pa[i + 1] - a) / (tb - ta);
    if (!visit(ta, tb, a, b, pc)) return;
    const double C = pc - a + b * tau;
    pc = a + b * (tb - ta) - b * tau + C * std::exp(-(tb - ta) / tau);
  }
}

/// Appends the breakpoints inside one inlet segment [ta, tb] (s = t - ta), and its end: from
/// s = 0 in steps step(s) (the largest step whose chord stays within the tolerance, from the
/// transient's size at s), each at least 1e-9 of the segment (the staircase's jumps are 1e-9 of a
/// hold long; keeps the loop finite whatever the transient), the last landing on the segment's end.
/// Returns false, with the breakpoints so far, when `ts` would grow past `limit` (see
/// breakpoint_limit): the caller reports it instead of filling the memory.
template <class Step, class PressureAt>
bool append_breakpoints(double ta, double tb, Step&& step, PressureAt&& p_at, std::vector<double>& ts,
                        std::vector<double>& ps, std::size_t limit) {
  const double len = tb - ta, h_min = 1e-9 * len;
  double s = 0.0;
  while (s < len) {
    if (ts.size() >= limit) return false;
    double h = std::max(step(s), h_min);
    if (s + h >= len * (1.0 - 1e-12)) h = len - s;
    s += h;
    if (s < len) {
      ts.push_back(ta + s);
      ps.push_back(p_at(s));
    }
  }
  ts.push_back(tb);
  ps.push_back(p_at(len));
  return true;
}

/// The most breakpoints one trial's chamber history may take: 64 per inlet point and 10^5 more.
/// A lag the tolerance resolves takes a few per inlet point (a staircase's jumps some hundreds);
/// a second-order lag whose fast stage is many decades below the inlet's sampling (tau2 -> 0, as a
/// calibration may try) asked for ~10^9 through the step's floor and filled the memory (24 GB in a
/// diagnosis); past this bound it is an error the caller (or the calibration) sees.
std::size_t breakpoint_limit(const TrialLoad& tl) { return 64 * tl.time_s.size() + 100000; }

[[noreturn]] void too_many_breakpoints(const TrialLoad& tl, double tau_s, double tau2_s, double tol) {
  std::ostringstream m;
  m << "pressure lag (load.pressure_lag_s = " << tau_s << " s, load.pressure_lag2_s = " << tau2_s
    << " s): the chamber history needs more than " << breakpoint_limit(tl) << " breakpoints for "
    << tl.time_s.size() << " inlet points to stay within " << tol << " Pa; a lag this fast against the inlet's "
    << "sampling is not resolved: use a first-order lag (load.pressure_lag2_s = 0) or a longer load.pressure_lag2_s";
  throw PhysicsError(m.str());
}

}  // namespace

double lagged_pressure(const TrialLoad& tl, double tau, double t) {
  if (tl.time_s.empty()) return 0.0;
  if (t <= tl.time_s.front()) return tl.pressure_Pa.front();
  double out = 0.0;
  bool found = false;
  for_each_segment(tl, tau, [&](double ta, double tb, double a, double b, double pc) {
    if (t > tb) return true;
    const double s = t - ta, C = pc - a + b * tau;
    out = a + b * s - b * tau + C * std::exp(-s / tau);
    found = true;
    return false;
  });
  if (found) return out;
  // Past the last breakpoint the inlet is constant: relax towards it.
  const double t_end = tl.time_s.back(), pc_end = lagged_pressure(tl, tau, t_end);
  const double p_last = tl.pressure_Pa.back();
  return p_last + (pc_end - p_last) * std::exp(-(t - t_end) / tau);
}

LoadHistory apply_pressure_lag(const LoadHistory& inlet, double tau, double tol) {
  if (!(std::isfinite(tau) && tau > 0.0)) throw InputError("load.pressure_lag_s: must be > 0 to apply a lag");
  if (!(tol > 0.0)) throw InputError("pressure lag: the tolerance must be > 0");
  LoadHistory out = inlet;
  for (TrialLoad& tl : out.trials) {
    if (tl.time_s.size() < 2) continue;
    std::vector<double> ts{tl.time_s.front()}, ps{tl.pressure_Pa.front()};
    for_each_segment(tl, tau, [&](double ta, double tb, double a, double b, double pc) {
      const double C = pc - a + b * tau;
      auto p_at = [&](double s) { return a + b * s - b * tau + C * std::exp(-s / tau); };
      const double len = tb - ta;
      auto step = [&](double s) {
        const double amp = std::abs(C) * std::exp(-s / tau);
        return amp <= tol ? len - s : tau * std::sqrt(8.0 * tol / amp);
      };
      if (!append_breakpoints(ta, tb, step, p_at, ts, ps, breakpoint_limit(tl))) too_many_breakpoints(tl, tau, 0.0, tol);
      return true;
    });
    tl.time_s = std::move(ts);
    tl.pressure_Pa = std::move(ps);
  }
  std::ostringstream s;
  s << inlet.description << ", chamber lagging the inlet by tau = " << tau << " s";
  out.description = s.str();
  return out;
}


// ---- Second order (2), (3) ----

namespace {

/// The transient basis E, F of (3) for tau2^2 e'' + tau e' + e = 0 (tau, tau2 > 0).
class Transient {
 public:
  explicit Transient(const PressureLag& l) : tau_(l.tau_s), b_(l.tau2_s * l.tau2_s), sigma_(l.tau_s / (2.0 * b_)) {
    // q = (tau - 2 tau2)(tau + 2 tau2) / (4 tau2^4): the factored form keeps its sign and digits near zeta = 1.
    const double q = (l.tau_s - 2.0 * l.tau2_s) * (l.tau_s + 2.0 * l.tau2_s) / (4.0 * b_ * b_);
    under_ = q < 0.0;
    root_ = std::sqrt(std::abs(q));                  // w (under-damped) or g
    k_ = under_ ? sigma_ : (1.0 / b_) / (sigma_ + root_);  // the slow rate 1/T1 = sigma - g, without cancelling
  }
  double tau() const { return tau_; }
  double b() const { return b_; }
  /// e and e' at s of the transient starting at e0, e0'.
  void at(double e0, double de0, double s, double& e, double& de) const {
    double E, F;
    if (under_) {
      const double d = std::exp(-sigma_ * s);
      E = d * std::cos(root_ * s);
      F = d * (root_ > 0.0 ? std::sin(root_ * s) / root_ : s);
    } else {
      const double d = std::exp(-k_ * s), m = std::expm1(-2.0 * root_ * s);  // m = exp(-2 g s) - 1
      E = d * (1.0 + 0.5 * m);
      F = d * (root_ > 0.0 ? -m / (2.0 * root_) : s);
    }
    e = e0 * E + (de0 + sigma_ * e0) * F;
    de = de0 * E - (e0 / b_ + sigma_ * de0) * F;
  }

 private:
  double tau_, b_, sigma_, root_ = 0.0, k_ = 0.0;
  bool under_ = false;
};

/// Walks the segments of `tl` as for_each_segment, calling visit(t_a, t_b, a, b, e0, e0') with the
/// transient (3) at t_a; the chamber pressure there is a - b tau + e0.
template <class Visit>
void for_each_segment2(const TrialLoad& tl, const Transient& T, Visit&& visit) {
  double x = tl.pressure_Pa.front(), v = 0.0;  // p_c, p_c'
  for (std::size_t i = 0; i + 1 < tl.time_s.size(); ++i) {
    const double ta = tl.time_s[i], tb = tl.time_s[i + 1];
    const double a = tl.pressure_Pa[i], b = (tl.pressure_Pa[i + 1] - a) / (tb - ta);
    const double e0 = x - a + b * T.tau(), de0 = v - b;
    if (!visit(ta, tb, a, b, e0, de0)) return;
    double e, de;
    T.at(e0, de0, tb - ta, e, de);
    x = a + b * (tb - ta - T.tau()) + e;
    v = b + de;
  }
}

double lagged_pressure2(const TrialLoad& tl, const PressureLag& lag, double t) {
  const Transient T(lag);
  double out = 0.0, x = tl.pressure_Pa.front(), v = 0.0;
  bool found = false;
  for_each_segment2(tl, T, [&](double ta, double tb, double a, double b, double e0, double de0) {
    const double s = std::min(t, tb) - ta;
    double e, de;
    T.at(e0, de0, s, e, de);
    x = a + b * (s - T.tau()) + e, v = b + de;  // at t, or at the segment's end
    found = t <= tb;
    if (found) out = x;
    return !found;
  });
  if (found) return out;
  // Past the last breakpoint the inlet is constant: the transient from (x, v) at the end.
  const double p_last = tl.pressure_Pa.back();
  double e, de;
  T.at(x - p_last, v, t - tl.time_s.back(), e, de);
  return p_last + e;
}

/// The breakpoints of one trial through (2), within tol (the header's rule).
void lag_trial2(TrialLoad& tl, const PressureLag& lag, double tol) {
  const Transient T(lag);
  const double b2 = T.b();
  std::vector<double> ts{tl.time_s.front()}, ps{tl.pressure_Pa.front()};
  for_each_segment2(tl, T, [&](double ta, double tb, double a, double b, double e0, double de0) {
    auto p_at = [&](double s) {
      double e, de;
      T.at(e0, de0, s, e, de);
      return a + b * (s - T.tau()) + e;
    };
    const double len = tb - ta;
    auto step = [&](double s) {
      double e, de;
      T.at(e0, de0, s, e, de);
      if (std::sqrt(e * e + b2 * de * de) <= 0.5 * tol) return len - s;
      const double e2 = -(T.tau() * de + e) / b2, e3 = -(T.tau() * e2 + de) / b2;  // from the equation
      return std::sqrt(8.0 * tol / std::sqrt(e2 * e2 + b2 * e3 * e3));
    };
    if (!append_breakpoints(ta, tb, step, p_at, ts, ps, breakpoint_limit(tl)))
      too_many_breakpoints(tl, lag.tau_s, lag.tau2_s, tol);
    return true;
  });
  tl.time_s = std::move(ts);
  tl.pressure_Pa = std::move(ps);
}

}  // namespace

double lagged_pressure(const TrialLoad& tl, const PressureLag& lag, double t) {
  if (lag.tau2_s == 0.0) return lagged_pressure(tl, lag.tau_s, t);
  if (tl.time_s.empty()) return 0.0;
  if (t <= tl.time_s.front()) return tl.pressure_Pa.front();
  return lagged_pressure2(tl, lag, t);
}

LoadHistory apply_pressure_lag(const LoadHistory& inlet, const PressureLag& lag, double tol) {
  if (!(std::isfinite(lag.tau2_s) && lag.tau2_s >= 0.0))
    throw InputError("load.pressure_lag2_s: must be >= 0 (0 = a first-order lag)");
  if (lag.tau2_s == 0.0) return apply_pressure_lag(inlet, lag.tau_s, tol);
  if (!(std::isfinite(lag.tau_s) && lag.tau_s > 0.0))
    throw InputError("load.pressure_lag_s: must be > 0 to apply a lag (load.pressure_lag2_s needs it)");
  if (!(tol > 0.0)) throw InputError("pressure lag: the tolerance must be > 0");
  LoadHistory out = inlet;
  for (TrialLoad& tl : out.trials)
    if (tl.time_s.size() >= 2) lag_trial2(tl, lag, tol);
  std::ostringstream s;
  s << inlet.description << ", chamber lagging the inlet by tau = " << lag.tau_s << " s, tau2 = " << lag.tau2_s
    << " s (second order, zeta = " << lag.tau_s / (2.0 * lag.tau2_s) << ")";
  out.description = s.str();
  return out;
}

PressureLag scene_pressure_lag(const Scene& s) {
  PressureLag l;
  if (s.has("load.pressure_lag_s")) l.tau_s = s.number("load.pressure_lag_s");
  if (s.has("load.pressure_lag2_s")) l.tau2_s = s.number("load.pressure_lag2_s");
  if (!(std::isfinite(l.tau_s) && l.tau_s >= 0.0))
    s.fail("load.pressure_lag_s", "must be >= 0 s (0 = the chamber follows the inlet instantly)");
  if (!(std::isfinite(l.tau2_s) && l.tau2_s >= 0.0))
    s.fail("load.pressure_lag2_s", "must be >= 0 s (0 = a first-order lag, load.pressure_lag_s alone)");
  if (l.tau2_s > 0.0 && l.tau_s == 0.0)
    s.fail("load.pressure_lag2_s", "a second-order lag needs load.pressure_lag_s > 0 too (the mean delay; with 0 the "
                                   "chamber would ring undamped)");
  return l;
}

}  // namespace pneufem
