// engine/history_step.h: the history measures of one physical step (change, Milne's error estimate)
// and the linear-drive error of the Prony update, which the quasi-static step control bounds.
#include "engine/history_step.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

namespace pneufem {
namespace {

// Two values per point (damage, viscous strain): the change is the larger sum over a point.
TEST(HistoryStep, ChangeIsTheLargestPointChange) {
  const std::vector<double> cur = {0.1, 0.2, 0.0, 0.5};
  const std::vector<double> next = {0.15, 0.1, 0.0, 0.55};  // point 0: 0.05 + 0.1, point 1: 0.05
  const HistoryStep s = history_step({}, cur, next, 0.0);
  EXPECT_NEAR(s.change, 0.15, 1e-15);
  EXPECT_EQ(s.change_point, 0);
  EXPECT_EQ(s.error, 0.0);  // no previous step: no estimate
  EXPECT_EQ(s.error_point, -1);
  const HistoryStep none = history_step({}, cur, cur, 0.0);
  EXPECT_EQ(none.change, 0.0);
  EXPECT_EQ(none.change_point, -1);
}

// A history changing at a constant rate has no error estimate; a change twice the one extrapolated
// from the previous step (r = h / h_prev) has the estimate |next - cur - r (cur - prev)| r / (1 + r).
TEST(HistoryStep, MilneEstimateVanishesAtConstantRate) {
  const std::vector<double> prev = {0.0, 0.0}, cur = {0.1, 0.02};
  const double r = 2.0;
  const std::vector<double> steady = {0.1 + r * 0.1, 0.02 + r * 0.02};
  EXPECT_NEAR(history_step(prev, cur, steady, r).error, 0.0, 1e-15);
  const std::vector<double> faster = {0.1 + 2.0 * r * 0.1, 0.02 + r * 0.02};
  const HistoryStep s = history_step(prev, cur, faster, r);
  EXPECT_NEAR(s.error, r * 0.1 * r / (1.0 + r), 1e-14);
  EXPECT_EQ(s.error_point, 0);
}

// G(x) = (x/2 - 1)(1 - exp(-x)) + x exp(-x): x^3 / 12 for short steps (the series branch below
// x = 0.1 meets the closed form), x / 2 - 1 for long ones, increasing, 0 for x <= 0.
TEST(HistoryStep, PronyInterpolationG) {
  EXPECT_EQ(prony_interpolation_G(0.0), 0.0);
  EXPECT_EQ(prony_interpolation_G(-1.0), 0.0);
  const double x = 1e-3;
  EXPECT_NEAR(prony_interpolation_G(x), x * x * x / 12.0 - x * x * x * x / 24.0, 1e-6 * x * x * x);
  auto closed = [](double y) { return (0.5 * y - 1.0) * (1.0 - std::exp(-y)) + y * std::exp(-y); };
  EXPECT_NEAR(prony_interpolation_G(0.0999999), closed(0.0999999), 1e-12);
  EXPECT_NEAR(prony_interpolation_G(0.1), closed(0.1), 1e-15);
  EXPECT_NEAR(prony_interpolation_G(60.0), 29.0, 1e-12);
  double last = 0.0;
  for (double y = 0.01; y < 20.0; y *= 1.3) {
    EXPECT_GT(prony_interpolation_G(y), last) << y;
    last = prony_interpolation_G(y);
  }
}

// The error of a drive is c sum_i a_i tau_i^2 G(h / tau_i).
TEST(HistoryStep, LinearDriveErrorSumsTheTerms) {
  Material::LinearDrive d;
  d.terms = 2;
  d.a = {0.5, 2.0, 0.0};
  d.tau_s = {1.0, 4.0, 0.0};
  const double h = 0.8, c = 3.0;
  const double expected = c * (0.5 * 1.0 * prony_interpolation_G(0.8) + 2.0 * 16.0 * prony_interpolation_G(0.2));
  EXPECT_NEAR(linear_drive_error(d, c, h), expected, 1e-15 * expected);
  EXPECT_EQ(linear_drive_error(Material::LinearDrive{}, c, h), 0.0);
}

}  // namespace
}  // namespace pneufem
