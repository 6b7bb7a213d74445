// materials/hyperelastic.h against truth: Yeoh's closed-form incompressible uniaxial curve (the seed
// paper's Ecoflex 00-50 constants to a stretch of 6), and Yeoh's stability limit as the first sign
// change of W1. (The derivative battery of every law is test_materials.cpp.)
#include "materials/hyperelastic.h"

#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "tests/materials/material_test_utils.h"

namespace pneufem {
namespace {

using test::check_uniaxial;

// Ecoflex 00-50 (the seed paper's Yeoh constants), K = 1e4 mu0, lambda up to 6.
// Incompressible: P = 2 (lambda - lambda^-2) dW/dI1 at I1 = lambda^2 + 2/lambda.
TEST(UniaxialTension, YeohEcoflexMatchesIncompressibleCurve) {
  const Yeoh law(0.019e6, 9.0e2, -4.75, 1e4 * 2.0 * 0.019e6);
  const auto P_inc = [&](double l) {
    const double x = l * l + 2.0 / l - 3.0;
    return 2.0 * (l - 1.0 / (l * l)) * (law.C10 + x * (2.0 * law.C20 + 3.0 * law.C30 * x));
  };
  check_uniaxial(InvariantMaterial<Yeoh>(law), P_inc, 6.0);
}

// Yeoh::stability_limit_I1b_minus_3() is the smallest positive root of W1 = dW/dI1b: W1 must vanish there,
// be positive on [0, x*) and negative just beyond; +inf means W1 > 0 for all x >= 0.
TEST(YeohStability, LimitIsFirstSignChangeOfW1) {
  struct Case {
    double C10, C20, C30;
  };
  const Case cases[] = {
      {0.019e6, 9.0e2, -4.75},  // Ecoflex 00-50: x* = 136.1, i.e. lambda = 11.8 in uniaxial tension
      {1.0, -0.5, 0.0},         // linear W1: x* = 1
      {1.0, -1.0, 0.2},         // two positive roots 0.61 and 2.72: the first one
      {1.0, 0.5, 0.0},          // never
      {1.0, -1.0, 1.0},         // W1 = 1 - 2x + 3x^2 > 0: never
  };
  for (const Case& c : cases) {
    const Yeoh law(c.C10, c.C20, c.C30, 1e3 * c.C10);
    SCOPED_TRACE("C10, C20, C30 = " + std::to_string(c.C10) + ", " + std::to_string(c.C20) + ", " +
                 std::to_string(c.C30));
    const auto W1 = [&](double x) {
      Invariants v;
      v.J = 1.0;
      v.I1b = 3.0 + x;
      v.I2b = 3.0;
      return law.derivatives(v).W1;
    };
    const double xs = law.stability_limit_I1b_minus_3();
    const double x_scan = std::isfinite(xs) ? xs : 1e4;
    for (int k = 0; k < 1000; ++k) EXPECT_GT(W1(x_scan * k / 1000.0), 0.0) << "x = " << x_scan * k / 1000.0;
    if (!std::isfinite(xs)) continue;
    // Round-off in W1 near its root: ~eps (C10 + 2|C20| x + 3|C30| x^2) << 1e-10 C10 here.
    EXPECT_NEAR(W1(xs), 0.0, 1e-10 * c.C10);
    EXPECT_LT(W1(xs * (1.0 + 1e-6)), 0.0);
  }
  EXPECT_NEAR(Yeoh(0.019e6, 9.0e2, -4.75, 3.8e6).stability_limit_I1b_minus_3(), 136.1, 0.05);
}

}  // namespace
}  // namespace pneufem
