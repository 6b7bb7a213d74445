#pragma once
// Internal robust-statistics helpers of analysis/ (not part of the library's API).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace pneufem::robust {

/// 1 / Phi^-1(3/4): turns a median absolute deviation into a standard deviation for Gaussian data.
constexpr double kMadToSigma = 1.4826;

/// Median of v, which is reordered; the mean of the middle two for an even count. v non-empty.
inline double median(std::vector<double>& v) {
  const std::size_t mid = v.size() / 2;
  std::nth_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid), v.end());
  const double upper = v[mid];
  if (v.size() % 2 == 1) return upper;
  return 0.5 * (upper + *std::max_element(v.begin(), v.begin() + static_cast<std::ptrdiff_t>(mid)));
}

/// Median absolute deviation from the median; v is overwritten. v non-empty.
inline double mad(std::vector<double>& v) {
  const double m = median(v);
  for (double& x : v) x = std::abs(x - m);
  return median(v);
}

/// Noise standard deviation of a sampled signal from its first differences, 1.4826 MAD / sqrt(2):
/// a step or a spike changes only a few differences, so it does not inflate the estimate.
inline double difference_noise(const std::vector<double>& x) {
  if (x.size() < 3) return 0.0;
  std::vector<double> d;
  d.reserve(x.size() - 1);
  for (std::size_t i = 1; i < x.size(); ++i) d.push_back(x[i] - x[i - 1]);
  return kMadToSigma * mad(d) / std::sqrt(2.0);
}

}  // namespace pneufem::robust
