// fit/volumetric.h: the bulk modulus from volumetric test data (Abaqus's *VOLUMETRIC TEST DATA), a
// round trip with noise, and the error for data in the wrong sign convention.
#include "fit/volumetric.h"

#include <random>
#include <string>

#include <gtest/gtest.h>

#include "tests/support/input_error.h"

namespace pneufem::fit {
namespace {

using test::error_of;
constexpr double kMPa = 1e6;

// The bulk modulus from p = K (1 - J) with 1 % multiplicative noise, relative weights (then the
// matching, homoscedastic weighting): K within 4 standard errors; and an error for p falling with J.
TEST(BulkModulus, RoundTripWithNoiseAndTheSignConvention) {
  const double K = 2.0 * kMPa;
  std::mt19937 rng(5);
  std::normal_distribution<double> g(0.0, 1.0);
  VolumetricCurve c{"vol.csv", {}};
  for (int i = 1; i <= 15; ++i) {
    const double J = 1.0 - 0.002 * i;
    c.points.push_back({J, K * (1.0 - J) * (1.0 + 0.01 * g(rng)), i + 1});
  }
  const BulkFit f = fit_bulk_modulus(c, Weighting::relative);
  EXPECT_NEAR(f.K_Pa, K, 4.0 * f.std_error_Pa);
  EXPECT_LT(f.std_error_Pa, 0.01 * K);
  for (VolumetricPoint& q : c.points) q.p_Pa = -q.p_Pa;  // tension-positive: the wrong convention
  const std::string e = error_of([&] { fit_bulk_modulus(c, Weighting::relative); });
  EXPECT_NE(e.find("vol.csv: the fitted bulk modulus is"), std::string::npos) << e;
  EXPECT_NE(e.find("p > 0 in compression"), std::string::npos) << e;
}

}  // namespace
}  // namespace pneufem::fit
