// engine/path_spline.h: the C2 spline slopes, the Hermite pieces, the monotone slopes and the
// segment index that the reduced models interpolate their path with.
#include "engine/path_spline.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

namespace pneufem {
namespace {

double cubic(double x) { return 2.0 - x + 0.5 * x * x + 0.1 * x * x * x; }
double cubic_slope(double x) { return -1.0 + x + 0.3 * x * x; }
double cubic_curvature(double x) { return 1.0 + 0.6 * x; }

// Not-a-knot ends reproduce any cubic exactly, on unequal spacings too: the slopes are the
// cubic's derivative at every sample, and the Hermite pieces are the cubic between them.
TEST(PathSpline, SplineSlopesReproduceACubicOnUnequalKnots) {
  const std::vector<double> theta = {0.0, 0.7, 1.5, 2.1, 3.4, 4.0};
  const std::vector<double> m = spline_slopes<double>(theta, [&](std::size_t k) { return cubic(theta[k]); });
  ASSERT_EQ(m.size(), theta.size());
  for (std::size_t k = 0; k < theta.size(); ++k) EXPECT_NEAR(m[k], cubic_slope(theta[k]), 1e-12) << k;
  for (std::size_t k = 0; k + 1 < theta.size(); ++k)
    for (double a : {0.0, 0.25, 0.5, 0.9, 1.0}) {
      const double dth = theta[k + 1] - theta[k], x = theta[k] + a * dth;
      const Hermite h(a, dth);
      double slope = 0.0;
      const double y = h(cubic(theta[k]), cubic(theta[k + 1]), m[k], m[k + 1], &slope);
      EXPECT_NEAR(y, cubic(x), 1e-12);
      EXPECT_NEAR(slope, cubic_slope(x), 1e-11);
      EXPECT_NEAR(h.value(cubic(theta[k]), cubic(theta[k + 1]), m[k], m[k + 1]), y, 1e-14);
      EXPECT_NEAR(h.slope(cubic(theta[k]), cubic(theta[k + 1]), m[k], m[k + 1]), slope, 1e-14);
      EXPECT_NEAR(h.curvature(cubic(theta[k]), cubic(theta[k + 1]), m[k], m[k + 1]), cubic_curvature(x), 1e-10);
    }
}

TEST(PathSpline, TwoSamplesTakeTheChordAndThreeAreNatural) {
  const std::vector<double> two = {1.0, 3.0};
  const std::vector<double> m2 = spline_slopes<double>(two, [](std::size_t k) { return k == 0 ? 5.0 : 9.0; });
  EXPECT_DOUBLE_EQ(m2[0], 2.0);
  EXPECT_DOUBLE_EQ(m2[1], 2.0);
  // Three samples of a line: natural ends give the line's slope everywhere.
  const std::vector<double> three = {0.0, 1.0, 3.0};
  const std::vector<double> m3 = spline_slopes<double>(three, [&](std::size_t k) { return 4.0 - 2.0 * three[k]; });
  for (double v : m3) EXPECT_NEAR(v, -2.0, 1e-14);
}

// Outside [0, 1] a piece continues linearly with its end slope, and has no curvature.
TEST(PathSpline, HermiteExtrapolatesLinearly) {
  const Hermite before(-0.5, 2.0), after(1.25, 2.0);
  double s = 0.0;
  EXPECT_DOUBLE_EQ(before(1.0, 3.0, 0.5, 4.0, &s), 1.0 - 1.0 * 0.5);
  EXPECT_DOUBLE_EQ(s, 0.5);
  EXPECT_DOUBLE_EQ(after(1.0, 3.0, 0.5, 4.0, &s), 3.0 + 0.5 * 4.0);
  EXPECT_DOUBLE_EQ(s, 4.0);
  EXPECT_FALSE(before.inside());
  EXPECT_DOUBLE_EQ(after.curvature(1.0, 3.0, 0.5, 4.0), 0.0);
}

// Where the chords change sign (or one is flat) the monotone slope is zero, so the interpolant of a
// pressure that flattens towards a limit point never overshoots its samples.
TEST(PathSpline, MonotoneSlopesDoNotOvershoot) {
  const std::vector<double> theta = {0.0, 1.0, 2.0, 4.0, 5.0};
  const std::vector<double> p = {0.0, 10.0, 10.0, 12.0, 11.0};
  const std::vector<double> m = monotone_slopes(theta, p);
  EXPECT_DOUBLE_EQ(m.front(), 10.0);  // the end chords
  EXPECT_DOUBLE_EQ(m.back(), -1.0);
  EXPECT_EQ(m[1], 0.0);
  EXPECT_EQ(m[2], 0.0);
  EXPECT_EQ(m[3], 0.0);  // a maximum
  for (std::size_t k = 0; k + 1 < theta.size(); ++k)
    for (int j = 0; j <= 20; ++j) {
      const Hermite h(j / 20.0, theta[k + 1] - theta[k]);
      const double v = h.value(p[k], p[k + 1], m[k], m[k + 1]);
      EXPECT_GE(v, std::min(p[k], p[k + 1]) - 1e-12) << k << " " << j;
      EXPECT_LE(v, std::max(p[k], p[k + 1]) + 1e-12) << k << " " << j;
    }
  // Equal chords keep the chord (a straight line stays straight).
  const std::vector<double> line = monotone_slopes({0.0, 1.0, 3.0}, {1.0, 3.0, 7.0});
  for (double v : line) EXPECT_NEAR(v, 2.0, 1e-14);
}

TEST(PathSpline, SegmentIndexIsClampedToThePath) {
  const std::vector<double> theta = {0.0, 1.0, 2.5, 4.0};
  EXPECT_EQ(path_segment_index(theta, -3.0), 0);
  EXPECT_EQ(path_segment_index(theta, 0.0), 0);
  EXPECT_EQ(path_segment_index(theta, 0.99), 0);
  EXPECT_EQ(path_segment_index(theta, 1.0), 1);
  EXPECT_EQ(path_segment_index(theta, 3.9), 2);
  EXPECT_EQ(path_segment_index(theta, 4.0), 2);
  EXPECT_EQ(path_segment_index(theta, 40.0), 2);
}

}  // namespace
}  // namespace pneufem
