// The incompressible test modes (fit/incompressible.h) against the 3D laws of materials/
// at the same homogeneous deformation, and the Drucker tangent (stability.h) against central
// differences of the principal stresses.
#include <gtest/gtest.h>

#include <cmath>

#include "fit/incompressible.h"
#include "fit/stability.h"
#include "materials/hyperelastic.h"
#include "materials/ogden.h"

namespace pneufem::fit {
namespace {

constexpr double kMPa = 1e6;

/// Laws with constants from the literature: Kulkarni's Ecoflex 00-50 Yeoh (the default scene), a
/// Mooney-Rivlin, a neo-Hookean and Ogden's 1972 Treloar fit (Abaqus convention, README of
/// tests/data/treloar1944).
std::vector<Constants> literature_laws() {
  return {
      {Law::yeoh, {0.019 * kMPa, 9.0e-4 * kMPa, -4.75e-6 * kMPa}, {}},
      {Law::mooney_rivlin, {0.15 * kMPa, 0.03 * kMPa}, {}},
      {Law::neo_hookean, {0.2 * kMPa}, {}},
      {Law::ogden, {0.4095 * kMPa, 0.003 * kMPa, 0.01 * kMPa}, {1.3, 5.0, -2.0}},
  };
}

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

// D = d sigma_i / d eps_j from the analytic M (stability.h) against central differences of
// sigma_i = tau_i - tau_3 from the Kirchhoff basis, with l_3 = 1/(l_1 l_2). h = 1e-5 in log strain:
// truncation O(h^2) ~ 1e-10 relative, round-off ~ 1e-16 / 1e-5 = 1e-11; 1e-7 of the largest entry.
TEST(DruckerTangent, MatchesCentralDifferencesOfThePrincipalStresses) {
  for (const Constants& k : literature_laws()) {
    const auto sigma = [&](double e1, double e2) {
      const Vec3 l(std::exp(e1), std::exp(e2), std::exp(-e1 - e2));
      const Eigen::VectorXd c = Eigen::Map<const Eigen::VectorXd>(k.c.data(), static_cast<Eigen::Index>(k.c.size()));
      const Eigen::Vector3d tau = kirchhoff_basis(k.law, k.alpha, l).transpose() * c;
      return Eigen::Vector2d(tau[0] - tau[2], tau[1] - tau[2]);
    };
    for (const auto& [e1, e2] : std::vector<std::pair<double, double>>{{0.0, 0.0}, {0.7, -0.35}, {1.2, 1.2}, {-0.4, 0.3}, {1.9, 0.0}}) {
      SCOPED_TRACE(std::string(law_name(k.law)) + " eps = " + std::to_string(e1) + ", " + std::to_string(e2));
      const double h = 1e-5;
      Eigen::Matrix2d D_fd;
      D_fd.col(0) = (sigma(e1 + h, e2) - sigma(e1 - h, e2)) / (2 * h);
      D_fd.col(1) = (sigma(e1, e2 + h) - sigma(e1, e2 - h)) / (2 * h);
      const Eigen::Matrix2d D = drucker_tangent(k, Vec3(std::exp(e1), std::exp(e2), std::exp(-e1 - e2)));
      EXPECT_LE((D - D_fd).cwiseAbs().maxCoeff(), 1e-7 * D_fd.cwiseAbs().maxCoeff());
    }
  }
}

// Ogden with every mu_i > 0 is stable everywhere (M diagonal positive: Ogden 1972's condition);
// Kulkarni's Yeoh (C30 < 0) is stable over Abaqus's range but not beyond W1 = 0: there M = 4 W11 l l^T
// has rank one, D = T^T M T too, det D = 0, so each tension path is unstable at or before the stretch
// where W1 = 0 (Yeoh::stability_limit_I1b_minus_3: I1 - 3 = 136.1, uniaxial l = 11.8).
TEST(DruckerStability, OgdenStableYeohUnstableAtOrBeforeW1Zero) {
  const std::vector<Constants> laws = literature_laws();
  EXPECT_TRUE(drucker_stability(laws[3], -0.9, 20.0).stable());
  EXPECT_TRUE(drucker_stability(laws[2]).stable());
  const Constants& yeoh = laws[0];
  const StabilityReport r = drucker_stability(yeoh, -0.9, 12.0);
  const double x_star = Yeoh(yeoh.c[0], yeoh.c[1], yeoh.c[2], 1.0).stability_limit_I1b_minus_3();
  for (const StabilityLimit& s : r.limits) {
    SCOPED_TRACE(std::string(mode_name(s.mode)) + (s.tension ? " tension" : " compression"));
    if (!s.tension || std::isnan(s.strain)) continue;
    const Vec3 l = mode_stretches(s.mode, 1.0 + s.strain);
    EXPECT_LE(l.squaredNorm() - 3.0, x_star + 1e-9);
    EXPECT_TRUE(drucker_stable(yeoh, mode_stretches(s.mode, 1.0 + s.strain - 0.01)));
  }
  // uniaxial reaches W1 = 0 at l = 11.8 (< 13): its limit must be found
  EXPECT_FALSE(std::isnan(r.limits[0].strain));
}

}  // namespace
}  // namespace pneufem::fit
