// analysis/robust.h: the median, the median absolute deviation and the noise estimate from first
// differences that the step finder and the Hampel filter use.
#include "analysis/robust.h"

#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

namespace pneufem {
namespace {

TEST(Robust, MedianOfOddAndEvenCounts) {
  std::vector<double> odd = {5.0, 1.0, 3.0};
  EXPECT_EQ(robust::median(odd), 3.0);
  std::vector<double> even = {4.0, 1.0, 3.0, 2.0};
  EXPECT_EQ(robust::median(even), 2.5);  // the mean of the middle two, exact in binary
  std::vector<double> one = {-7.0};
  EXPECT_EQ(robust::median(one), -7.0);
}

TEST(Robust, MadIgnoresAnOutlier) {
  // median 3; deviations {2, 1, 0, 1, 97}: their median is 1 whatever the outlier's size.
  std::vector<double> v = {1.0, 2.0, 3.0, 4.0, 100.0};
  EXPECT_EQ(robust::mad(v), 1.0);
  std::vector<double> w = {1.0, 2.0, 3.0, 4.0, 1e9};
  EXPECT_EQ(robust::mad(w), 1.0);
}

TEST(Robust, DifferenceNoiseIsTheNoiseSigmaThroughStepsAndSpikes) {
  // White Gaussian noise of sigma 0.2 on a staircase with spikes: the estimate must be sigma, where
  // the standard deviation of the differences / sqrt(2) is inflated by the steps and spikes.
  const double sigma = 0.2;
  const int n = 20000;
  std::mt19937 rng(12345);
  std::normal_distribution<double> noise(0.0, sigma);
  std::vector<double> x(n);
  for (int i = 0; i < n; ++i) x[i] = 10.0 * (i / 2000) + noise(rng);  // ten steps of 10
  for (int i = 500; i < n; i += 1000) x[i] += 50.0;                      // twenty spikes
  const double est = robust::difference_noise(x);
  // The MAD estimate of sigma from n = 2e4 correlated differences has a relative standard error of
  // about 1.2 %; 5 % is four of them, and far below the factor the steps and spikes would give.
  EXPECT_NEAR(est, sigma, 0.05 * sigma);

  double sum2 = 0.0;
  for (int i = 1; i < n; ++i) sum2 += (x[i] - x[i - 1]) * (x[i] - x[i - 1]);
  const double naive = std::sqrt(sum2 / (n - 1)) / std::sqrt(2.0);
  EXPECT_GT(naive, 3.0 * sigma);  // what the robust estimate avoids
}

TEST(Robust, DifferenceNoiseOfTooShortOrConstantSignalsIsZero) {
  EXPECT_EQ(robust::difference_noise({}), 0.0);
  EXPECT_EQ(robust::difference_noise({1.0, 2.0}), 0.0);
  EXPECT_EQ(robust::difference_noise({4.0, 4.0, 4.0, 4.0}), 0.0);
  // A linear ramp: every difference equal, so no noise.
  EXPECT_EQ(robust::difference_noise({0.0, 0.5, 1.0, 1.5, 2.0, 2.5}), 0.0);
}

}  // namespace
}  // namespace pneufem
