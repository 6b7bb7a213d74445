// materials/invariant_kernel.h: the tensor algebra that every law of the invariants shares - the
// isochoric invariants, the fast inverse cube root, and the stress and tangent from the scalar
// derivatives of W(I1b, I2b) and U(J) - against direct formulas and finite differences, for a made-up
// law whose every second derivative is non-zero (the laws' own tests cover only their own terms).
#include "materials/invariant_kernel.h"

#include <algorithm>
#include <cmath>

#include <Eigen/LU>
#include <gtest/gtest.h>

namespace pneufem {
namespace {

// W = c1 x + c2 y + c3 x^2 + c4 x y + c5 y^2 with x = I1b - 3, y = I2b - 3; U = kappa/2 (J-1)^2 + m3 (J-1)^3.
constexpr double c1 = 0.3, c2 = 0.1, c3 = 0.05, c4 = -0.02, c5 = 0.03, kappa = 20.0, m3 = 4.0;

InvariantDerivatives derivatives(const Invariants& v) {
  const double x = v.I1b - 3.0, y = v.I2b - 3.0, j = v.J - 1.0;
  InvariantDerivatives d;
  d.W = c1 * x + c2 * y + c3 * x * x + c4 * x * y + c5 * y * y;
  d.W1 = c1 + 2.0 * c3 * x + c4 * y;
  d.W2 = c2 + c4 * x + 2.0 * c5 * y;
  d.W11 = 2.0 * c3;
  d.W12 = c4;
  d.W22 = 2.0 * c5;
  d.U = 0.5 * kappa * j * j + m3 * j * j * j;
  d.dU = kappa * j + 3.0 * m3 * j * j;
  d.d2U = kappa + 6.0 * m3 * j;
  return d;
}

PointResponse response(const Mat3& F, bool tangent) {
  const Invariants v = isochoric_invariants(F);
  PointResponse r;
  invariant_response(F, v, derivatives(v), tangent, r);
  return r;
}

Mat3 deformation() {
  Mat3 F;
  F << 1.15, 0.12, -0.05, 0.03, 0.92, 0.08, -0.07, 0.04, 1.04;
  return F;
}

TEST(InvariantKernel, InvariantsAreTheDirectFormulas) {
  const Mat3 F = deformation();
  const Invariants v = isochoric_invariants(F);
  const Mat3 C = F.transpose() * F;
  const double J = F.determinant();
  const double I1 = C.trace(), I2 = 0.5 * (I1 * I1 - (C * C).trace());
  // Relative 1e-13: a few roundings of O(1) quantities by two different orders of operations.
  EXPECT_NEAR(v.J, J, 1e-13);
  EXPECT_NEAR(v.I1, I1, 1e-13);
  EXPECT_NEAR(v.I2, I2, 1e-13);
  EXPECT_NEAR(v.Jm23, std::pow(J, -2.0 / 3.0), 1e-13);
  EXPECT_NEAR(v.I1b, std::pow(J, -2.0 / 3.0) * I1, 1e-13);
  EXPECT_NEAR(v.I2b, std::pow(J, -4.0 / 3.0) * I2, 1e-13);
  EXPECT_LT((v.cof - J * F.inverse().transpose()).norm(), 1e-13);
  // Isochoric: a volumetric stretch changes J only.
  const Invariants s = isochoric_invariants(1.1 * F);
  EXPECT_NEAR(s.I1b, v.I1b, 1e-13);
  EXPECT_NEAR(s.I2b, v.I2b, 1e-13);
}

TEST(InvariantKernel, AnInvertedPointHasNoIsochoricPart) {
  Mat3 F = deformation();
  F.col(0) *= -1.0;  // J < 0
  const Invariants v = isochoric_invariants(F);
  EXPECT_LT(v.J, 0.0);
  EXPECT_TRUE(std::isnan(v.I1b));  // reported by the callers as a non-finite stress
}

// inverse_cbrt replaces libm's cbrt in the invariant kernel (materials/invariant_kernel.h). Over
// 16 decades of J (far beyond any admissible deformation) it must agree with 1 / cbrt(x) to a few
// ulp: the analysis of the four Newton steps gives ~1e-16 relative, and both sides round, so
// 2e-15 (~9 ulp) is a bound that still fails for three steps (~3e-10).
TEST(InverseCbrt, AgreesWithLibmToAFewUlp) {
  double worst = 0.0;
  for (double x = 1e-8; x < 1e8; x *= 1.001) {
    const double ref = 1.0 / std::cbrt(x);
    worst = std::max(worst, std::abs(inverse_cbrt(x) - ref) / ref);
  }
  EXPECT_LT(worst, 2e-15);
  EXPECT_EQ(inverse_cbrt(1.0), 1.0);  // exactly: the reference state has zero stress
  EXPECT_EQ(inverse_cbrt(8.0), 0.5);
}

TEST(InvariantKernel, StressIsTheDerivativeOfTheEnergy) {
  const Mat3 F = deformation();
  const PointResponse r = response(F, false);
  const PointResponse rt = response(F, true);
  EXPECT_EQ(r.P_iso, rt.P_iso);  // the force-only path and the tangent path agree bit for bit
  const double h = 1e-6;
  for (int i = 0; i < 3; ++i)
    for (int J = 0; J < 3; ++J) {
      Mat3 Fp = F, Fm = F;
      Fp(i, J) += h;
      Fm(i, J) -= h;
      const PointResponse p = response(Fp, false), q = response(Fm, false);
      // Central differences: truncation O(h^2) ~ 1e-12, rounding eps |psi| / h ~ 1e-10.
      EXPECT_NEAR(r.P_iso(i, J), (p.psi_iso - q.psi_iso) / (2.0 * h), 1e-8) << i << J;
      EXPECT_NEAR(r.P_vol(i, J), (p.psi_vol - q.psi_vol) / (2.0 * h), 1e-8) << i << J;
    }
}

TEST(InvariantKernel, TangentIsTheDerivativeOfTheStress) {
  const Mat3 F = deformation();
  const PointResponse r = response(F, true);
  const double h = 1e-6;
  double scale = 0.0;
  for (int c = 0; c < 81; ++c) scale = std::max(scale, std::abs(r.A()(c / 9, c % 9)));
  for (int k = 0; k < 3; ++k)
    for (int L = 0; L < 3; ++L) {
      Mat3 Fp = F, Fm = F;
      Fp(k, L) += h;
      Fm(k, L) -= h;
      const PointResponse p = response(Fp, false), q = response(Fm, false);
      for (int i = 0; i < 3; ++i)
        for (int J = 0; J < 3; ++J) {
          const double fd_iso = (p.P_iso(i, J) - q.P_iso(i, J)) / (2.0 * h);
          const double fd_vol = (p.P_vol(i, J) - q.P_vol(i, J)) / (2.0 * h);
          // As above, on stresses of O(scale): 1e-7 relative holds both error terms with margin.
          EXPECT_NEAR(r.A_iso(flat(i, J), flat(k, L)), fd_iso, 1e-7 * scale) << i << J << k << L;
          EXPECT_NEAR(r.A_vol(flat(i, J), flat(k, L)), fd_vol, 1e-7 * scale) << i << J << k << L;
        }
    }
}

}  // namespace
}  // namespace pneufem
