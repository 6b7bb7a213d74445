#include "analysis/paper_metrics.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "core/errors.h"
#include "core/json_writer.h"

namespace pneufem {

namespace {
// Every digit that reads back the same number (round trip), null for a non-finite one: json::num.
using json::num;
std::string arr(const std::vector<double>& v) {
  std::string s = "[";
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + num(v[i]);
  return s + "]";
}
}  // namespace

TrialMetrics paper_metrics(const StepAngles& a, const StepAngles& ref) {
  const std::size_t n = ref.at_mark_deg.size();
  if (a.at_mark_deg.size() != n || a.at_end_deg.size() != n)
    throw InputError("metrics: trial " + std::to_string(a.trial) + " has " + std::to_string(a.at_mark_deg.size()) +
                     " steps, the reference has " + std::to_string(n));
  if (n == 0) throw InputError("metrics: no steps to compare");
  const auto [lo, hi] = std::minmax_element(ref.at_mark_deg.begin(), ref.at_mark_deg.end());
  const double range = *hi - *lo;
  if (!(range > 0.0)) throw InputError("metrics: the reference angles do not vary; NRMSE is undefined");
  TrialMetrics m;
  m.trial = a.trial;
  double sq = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    const double e = a.at_mark_deg[i] - ref.at_mark_deg[i];
    sq += e * e;
    m.abs_error_deg.push_back(std::abs(e));
    m.spread_deg.push_back(a.at_end_deg[i] - a.at_mark_deg[i]);
  }
  m.nrmse = std::sqrt(sq / static_cast<double>(n)) / range;
  m.mark_deg = a.at_mark_deg;
  m.reference_deg = ref.at_mark_deg;
  return m;
}

std::string metrics_json(const std::vector<TrialMetrics>& trials, const std::vector<double>& levels) {
  std::ostringstream s;
  s << "{\n  \"trials\": [\n";
  for (std::size_t i = 0; i < trials.size(); ++i) {
    const TrialMetrics& t = trials[i];
    s << "    {\"trial\": " << t.trial << ", \"nrmse\": " << num(t.nrmse) << ", \"abs_error_deg\": " << arr(t.abs_error_deg)
      << ", \"spread_deg\": " << arr(t.spread_deg) << ", \"angle_at_mark_deg\": " << arr(t.mark_deg)
      << ", \"reference_at_mark_deg\": " << arr(t.reference_deg) << (t.extrapolated ? ", \"extrapolated\": true" : "") << "}" << (i + 1 < trials.size() ? "," : "") << "\n";
  }
  s << "  ],\n  \"levels_kPa\": " << arr(levels) << "\n}\n";
  return s.str();
}

}  // namespace pneufem
