#include "engine/load_history.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <utility>

#include "core/errors.h"
#include "core/number_text.h"

namespace pneufem {

double TrialLoad::pressure(double t) const {
  if (time_s.empty()) return 0.0;
  if (t <= time_s.front()) return pressure_Pa.front();
  if (t >= time_s.back()) return pressure_Pa.back();
  const auto it = std::upper_bound(time_s.begin(), time_s.end(), t);
  const std::size_t i = static_cast<std::size_t>(it - time_s.begin());
  const double t0 = time_s[i - 1], t1 = time_s[i];
  const double w = (t - t0) / (t1 - t0);
  return (1.0 - w) * pressure_Pa[i - 1] + w * pressure_Pa[i];
}

StaircaseSize staircase_size(double p_max, double dp, double hold_s, int trials, double output_every_s) {
  StaircaseSize z;
  z.levels = std::floor(p_max / dp + 1e-9) + 1.0;  // 1e-9: 45/5 is 9 even when the division rounds below
  const double extra = output_every_s > 0.0 ? std::ceil(hold_s / output_every_s) : 0.0;
  z.reports = static_cast<double>(trials) * z.levels * (2.0 + extra);  // the mark, the end, the extras
  return z;
}

LoadHistory staircase(double p_max, double dp, double hold_s, double ramp_s, int trials, double mark_s,
                      double rest_s, double output_every_s) {
  auto bad = [](const std::string& key, const std::string& what) {
    throw InputError("load." + key + ": " + what);
  };
  if (!(std::isfinite(dp) && dp > 0)) bad("step_kPa", "must be > 0");
  if (!(std::isfinite(p_max) && p_max >= 0)) bad("max_kPa", "must be >= 0");
  if (!(std::isfinite(hold_s) && hold_s > 0)) bad("hold_s", "must be > 0");
  if (!(ramp_s >= 0 && ramp_s < hold_s)) bad("ramp_s", "must be >= 0 and shorter than hold_s");
  if (trials < 1) bad("trials", "must be >= 1");
  if (!(mark_s >= ramp_s && mark_s <= hold_s)) bad("mark_s", "must lie within the hold, after the ramp");
  if (!(std::isfinite(rest_s) && rest_s >= 0)) bad("rest_s", "must be >= 0");
  if (!(std::isfinite(output_every_s) && output_every_s >= 0)) bad("output_every_s", "must be >= 0 (0 = off)");
  const StaircaseSize size = staircase_size(p_max, dp, hold_s, trials, output_every_s);
  if (!(size.levels <= kMaxStaircaseLevels))
    bad("step_kPa", "gives " + short_num(size.levels) + " levels up to max_kPa; the limit is " +
                        short_num(kMaxStaircaseLevels) + "; use a larger step");
  if (!(size.reports <= kMaxReports))
    bad("output_every_s", "the protocol would make " + short_num(size.reports) + " reports; the limit is " +
                              short_num(kMaxReports) + "; report less often or run fewer trials");
  const int nlev = static_cast<int>(size.levels);  // <= kMaxStaircaseLevels: the cast is exact
  TrialLoad tl;
  double prev = 0.0;
  tl.time_s.push_back(0.0);
  tl.pressure_Pa.push_back(0.0);
  for (int k = 0; k < nlev; ++k) {
    const double level = k * dp;
    const double t0 = k * hold_s;
    if (k > 0) {
      if (ramp_s > 0) {
        tl.time_s.push_back(t0 + ramp_s);
        tl.pressure_Pa.push_back(level);
      } else {
        // a jump: represent by an infinitesimally short ramp
        tl.time_s.push_back(t0 + 1e-9 * hold_s);
        tl.pressure_Pa.push_back(level);
      }
    }
    tl.time_s.push_back(t0 + hold_s);
    tl.pressure_Pa.push_back(level);
    tl.step_start_s.push_back(t0);
    tl.step_end_s.push_back(t0 + hold_s);
    tl.step_level_Pa.push_back(level);
    tl.output_s.push_back(t0 + mark_s);
    if (output_every_s > 0)
      for (double t = t0 + output_every_s; t < t0 + hold_s - 1e-9; t += output_every_s) tl.output_s.push_back(t);
    tl.output_s.push_back(t0 + hold_s);
    prev = level;
  }
  (void)prev;
  // Insert the start of each ramp (level k-1 held until t0): breakpoints must be increasing.
  TrialLoad clean;
  for (std::size_t i = 0; i < tl.time_s.size(); ++i) {
    if (!clean.time_s.empty() && tl.time_s[i] <= clean.time_s.back() + 1e-12) {
      clean.pressure_Pa.back() = tl.pressure_Pa[i];
      continue;
    }
    clean.time_s.push_back(tl.time_s[i]);
    clean.pressure_Pa.push_back(tl.pressure_Pa[i]);
  }
  clean.output_s = tl.output_s;
  std::sort(clean.output_s.begin(), clean.output_s.end());
  clean.output_s.erase(std::unique(clean.output_s.begin(), clean.output_s.end(),
                                   [](double a, double b) { return std::abs(a - b) < 1e-9; }),
                       clean.output_s.end());
  clean.step_start_s = tl.step_start_s;
  clean.step_end_s = tl.step_end_s;
  clean.step_level_Pa = tl.step_level_Pa;
  clean.mark_s = mark_s;
  LoadHistory h;
  h.trials.assign(trials, clean);
  h.rest_between_trials_s = rest_s;
  std::ostringstream s;
  s << "staircase 0-" << p_max * 1e-3 << " kPa in " << dp * 1e-3 << " kPa steps, " << hold_s << " s hold, " << trials
    << " trial(s)";
  h.description = s.str();
  return h;
}

std::vector<char> rdp_keep(const std::vector<double>& t, const std::vector<double>& p, double tol) {
  std::vector<char> keep(t.size(), 0);
  if (t.empty()) return keep;
  keep.front() = keep.back() = 1;
  std::vector<std::pair<std::size_t, std::size_t>> todo{{0, t.size() - 1}};
  while (!todo.empty()) {
    const auto [a, b] = todo.back();
    todo.pop_back();
    if (b <= a + 1) continue;
    double worst = -1.0;
    std::size_t wi = a;
    for (std::size_t i = a + 1; i < b; ++i) {
      const double w = (t[i] - t[a]) / (t[b] - t[a]);
      const double d = std::abs(p[i] - ((1 - w) * p[a] + w * p[b]));
      if (d > worst) {
        worst = d;
        wi = i;
      }
    }
    if (worst > tol) {
      keep[wi] = 1;
      todo.emplace_back(a, wi);
      todo.emplace_back(wi, b);
    }
  }
  return keep;
}

}  // namespace pneufem
