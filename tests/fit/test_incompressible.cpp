// The incompressible test modes (fit/incompressible.h) against the 3D laws of materials/ at the same
// homogeneous deformation. The Drucker tangent and stability (fit/stability.h): test_stability.cpp.
#include <gtest/gtest.h>

#include <cmath>

#include "fit/incompressible.h"
#include "materials/hyperelastic.h"
#include "materials/ogden.h"
#include "tests/fit/literature_laws.h"

namespace pneufem::fit {
namespace {

using testing::literature_laws;

// P = (sigma_11 - sigma_33)/l from the 3D law at F = diag(mode_stretches): at J = 1 the Cauchy stress
// is P F^T, so sigma_aa = P_aa l_a, and the volumetric part (a pressure) cancels in the difference.
// The two sides share no code: the 3D laws go through the invariant kernel or the SVD of F. Their
// difference is round-off: ~1e-15 relative per operation over a few hundred operations, and the
// difference sigma_11 - sigma_33 loses up to |sigma_11|/|P l| ~ 10x near l = 1; 1e-11 of
// (|P| + mu0) leaves a margin of ~100 over what is seen (< 1e-13).
TEST(IncompressibleModes, NominalStressEqualsThe3DLawAtTheHomogeneousState) {
  for (const Constants& k : literature_laws()) {
    const MaterialPtr m = make_law_material(k, 100.0 * k.mu0());
    for (TestMode mode : {TestMode::uniaxial, TestMode::biaxial, TestMode::planar})
      for (double l : {0.5, 0.8, 0.99, 1.01, 1.3, 2.0, 4.0, 7.0}) {
        SCOPED_TRACE(std::string(law_name(k.law)) + " " + mode_name(mode) + " l = " + std::to_string(l));
        const Vec3 s = mode_stretches(mode, l);
        const Mat3 F = s.asDiagonal();
        PointResponse r;
        m->evaluate(std::span<const Mat3>(&F, 1), TimeStep{}, {}, {}, std::span<PointResponse>(&r, 1), false);
        const Mat3 P = r.P();
        const double P3d = (P(0, 0) * s[0] - P(2, 2) * s[2]) / s[0];
        const double P1d = nominal_stress(k, mode, l);
        EXPECT_NEAR(P1d, P3d, 1e-11 * (std::abs(P3d) + k.mu0()));
        EXPECT_GT(P1d * (l - 1.0), 0.0);  // tension pulls, compression pushes
      }
  }
}

// Small-strain limit: every mode's slope at l = 1 is its textbook modulus, uniaxial 3 mu0 (E),
// equibiaxial 6 mu0, planar 4 mu0, whatever the law. Central difference with h = 1e-4: the error is
// O(h^2) P''' ~ 1e-8 mu0, against a tolerance of 1e-6 mu0.
TEST(IncompressibleModes, SmallStrainModuliAreThreeSixAndFourMu0) {
  for (const Constants& k : literature_laws()) {
    SCOPED_TRACE(law_name(k.law));
    const double h = 1e-4;
    const auto slope = [&](TestMode m) { return (nominal_stress(k, m, 1.0 + h) - nominal_stress(k, m, 1.0 - h)) / (2 * h); };
    EXPECT_NEAR(slope(TestMode::uniaxial), 3.0 * k.mu0(), 1e-6 * k.mu0());
    EXPECT_NEAR(slope(TestMode::biaxial), 6.0 * k.mu0(), 1e-6 * k.mu0());
    EXPECT_NEAR(slope(TestMode::planar), 4.0 * k.mu0(), 1e-6 * k.mu0());
    EXPECT_EQ(nominal_stress(k, TestMode::uniaxial, 1.0), 0.0);
  }
}

// Ogden's basis near alpha = 0 (expm1 form) is continuous with its limit 2 (1 + c) ln(l) / l.
TEST(IncompressibleModes, OgdenBasisIsContinuousAtAlphaZero) {
  for (TestMode m : {TestMode::uniaxial, TestMode::biaxial, TestMode::planar}) {
    const double at0 = nominal_stress_basis(Law::ogden, {0.0}, m, 2.5)[0];
    const double near0 = nominal_stress_basis(Law::ogden, {1e-7}, m, 2.5)[0];
    EXPECT_NEAR(near0, at0, 1e-6 * std::abs(at0));  // O(alpha) change
  }
}

}  // namespace
}  // namespace pneufem::fit
