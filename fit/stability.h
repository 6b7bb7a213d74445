#pragma once
// Drucker stability of an incompressible hyperelastic law, checked as Abaqus checks a fitted
// material (Abaqus Analysis User's Guide, "Hyperelastic behavior of rubberlike materials",
// stability of the material): a law is stable where d sigma : d eps > 0 for every increment, which
// under plane stress (sigma_3 = 0, the principal axes fixed) with logarithmic strains eps_i = ln l_i
// means that the 2x2 tangent D_ij = d sigma_i / d eps_j (i, j = 1, 2) is positive definite:
//   D11 + D22 > 0  and  D11 D22 - D12 D21 > 0.
// With sigma_i = tau_i - tau_3 (incompressible.h) and ln l_3 = -eps_1 - eps_2,
//   D_ij = M_ij - M_i3 - M_3j + M_33,   M_ab = d tau_a / d ln l_b = d^2 W / d ln l_a d ln l_b,
// so D is symmetric. For the invariant laws M_ab = 4 W11 l_a^2 l_b^2 + delta_ab (4 W1 l_a^2 + 4 W2 l_a^-2)
// (W12 = W22 = 0 for neo-Hookean, Mooney-Rivlin and Yeoh), with W1, W11 from the laws of materials/;
// for Ogden M_ab = delta_ab sum 2 mu_i l_a^alpha_i.
// Abaqus evaluates D along the six paths uniaxial, equibiaxial and planar tension and compression,
// nominal strain -0.9 to 9 in steps of 0.01, and names the strain where each path first turns
// unstable; drucker_stability does the same (the range and step are arguments).
#include <vector>

#include <Eigen/Core>

#include "fit/incompressible.h"

namespace pneufem::fit {

/// D = d sigma / d eps (plane stress, Pa) at the principal stretches `lambda` (J = 1). The constants
/// must be valid for their law (make_law_material accepts them).
Eigen::Matrix2d drucker_tangent(const Constants& k, const Vec3& lambda);
/// D positive definite at `lambda` (the two conditions above, strictly).
bool drucker_stable(const Constants& k, const Vec3& lambda);

/// Where one path turns unstable: the first nominal strain from 0 outwards (in tension upwards, in
/// compression downwards) at which D is not positive definite; NaN if it stays stable to the end.
struct StabilityLimit {
  TestMode mode;
  bool tension;
  double strain;
};

struct StabilityReport {
  double strain_lo, strain_hi, step;
  std::vector<StabilityLimit> limits;  ///< six: uniaxial, biaxial, planar, each tension then compression
  bool stable() const;
};

/// The six paths on the grid 0, +-step, ... within [strain_lo, strain_hi] (strain_lo in (-1, 0]).
StabilityReport drucker_stability(const Constants& k, double strain_lo = -0.9, double strain_hi = 9.0,
                                  double step = 0.01);

}  // namespace pneufem::fit
