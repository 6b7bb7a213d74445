#include "engine/history_step.h"

#include <cmath>

namespace pneufem {

HistoryStep history_step(const std::vector<double>& prev, const std::vector<double>& cur, const std::vector<double>& next,
                         double r) {
  HistoryStep out;
  for (std::size_t i = 0; i < next.size(); i += 2) {
    const int point = static_cast<int>(i / 2);
    const double c = std::abs(next[i] - cur[i]) + std::abs(next[i + 1] - cur[i + 1]);
    if (c > out.change) out.change = c, out.change_point = point;
    if (prev.empty()) continue;
    double e = 0.0;
    for (std::size_t k = i; k < i + 2; ++k) e += std::abs((next[k] - cur[k]) - r * (cur[k] - prev[k]));
    e *= r / (1.0 + r);
    if (e > out.error) out.error = e, out.error_point = point;
  }
  return out;
}

}  // namespace pneufem
