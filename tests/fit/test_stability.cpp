// fit/stability.h: the Drucker tangent against central differences of the principal stresses, and
// Drucker stability of the literature laws (Ogden stable, Kulkarni's Yeoh unstable at or before W1 = 0).
#include "fit/stability.h"

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "fit/incompressible.h"
#include "materials/hyperelastic.h"
#include "tests/fit/literature_laws.h"

namespace pneufem::fit {
namespace {

using testing::literature_laws;

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
