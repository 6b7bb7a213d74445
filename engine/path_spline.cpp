#include "engine/path_spline.h"

#include <algorithm>

namespace pneufem {

std::vector<double> monotone_slopes(const std::vector<double>& theta, const std::vector<double>& p) {
  const std::size_t ns = theta.size();
  std::vector<double> m(ns, 0.0);
  if (ns < 2) return m;
  std::vector<double> h(ns - 1), d(ns - 1);
  for (std::size_t k = 0; k + 1 < ns; ++k) {
    h[k] = theta[k + 1] - theta[k];
    d[k] = (p[k + 1] - p[k]) / h[k];
  }
  m.front() = d.front();
  m.back() = d.back();
  for (std::size_t k = 1; k + 1 < ns; ++k)
    if (d[k - 1] * d[k] > 0.0) {
      const double w1 = 2 * h[k] + h[k - 1], w2 = h[k] + 2 * h[k - 1];
      m[k] = (w1 + w2) / (w1 / d[k - 1] + w2 / d[k]);
    }
  return m;
}

int path_segment_index(const std::vector<double>& theta, double x) {
  const auto it = std::upper_bound(theta.begin(), theta.end(), x);
  const int k = static_cast<int>(it - theta.begin()) - 1;
  return std::clamp(k, 0, static_cast<int>(theta.size()) - 2);
}

}  // namespace pneufem
