#include "scenes/pressure_lag.h"

#include <cmath>
#include <sstream>

#include "core/errors.h"

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
      double s = 0.0;
      const double len = tb - ta;
      // Shortest interval worth a breakpoint: 1e-9 of the segment (the staircase's jumps are 1e-9
      // hold long); keeps the loop finite for any C.
      const double h_min = 1e-9 * len;
      while (s < len) {
        const double amp = std::abs(C) * std::exp(-s / tau);
        double h = amp <= tol ? len - s : tau * std::sqrt(8.0 * tol / amp);
        h = std::max(h, h_min);
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
    });
    tl.time_s = std::move(ts);
    tl.pressure_Pa = std::move(ps);
  }
  std::ostringstream s;
  s << inlet.description << ", chamber lagging the inlet by tau = " << tau << " s";
  out.description = s.str();
  return out;
}

}  // namespace pneufem
