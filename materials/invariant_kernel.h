#pragma once
// Generic first Piola-Kirchhoff stress and tangent of a decoupled isotropic hyperelastic law
//   psi(F) = W(I1b, I2b) + U(J),   I1b = J^{-2/3} tr C,  I2b = J^{-4/3} (tr^2 C - tr C^2) / 2,
// given the scalar derivatives of W and U. Each concrete law (Yeoh, neo-Hookean, Mooney-Rivlin)
// only supplies those scalars, so the tensor algebra is written (and tested) once.
//
// Derivation (Holzapfel, Nonlinear Solid Mechanics, 2000, sec. 6.4 in F-form), with H = F^{-T}:
//   dJ/dF = J H,  dH_iJ/dF_kL = -H_iL H_kJ,
//   dI1b/dF = J^{-2/3} (2F - 2/3 I1 H),
//   dI2b/dF = J^{-4/3} (2(I1 F - F C) - 4/3 I2 H),
// and the second derivatives follow by the product rule (invariant_kernel.cpp).
#include "materials/material.h"

namespace pneufem {

/// Scalar derivatives of W(I1b, I2b) and U(J) at one point.
struct InvariantDerivatives {
  double W = 0, W1 = 0, W2 = 0, W11 = 0, W12 = 0, W22 = 0;
  double U = 0, dU = 0, d2U = 0;
};

/// Isochoric invariants of F (J must be > 0), with the intermediate quantities the response
/// reuses (computing them once is half the cost of a force-only evaluation).
struct Invariants {
  double J, I1b, I2b;
  double I1 = 0, I2 = 0;  ///< invariants of C = F^T F
  double Jm23 = 0;        ///< J^{-2/3}
  Mat3 cof;               ///< cofactor matrix J F^{-T}
};
Invariants isochoric_invariants(const Mat3& F);

/// x^{-1/3} for x > 0 to ~4 ulp: a bit-level first guess refined by four Newton steps
/// y <- y (4 - x y^3) / 3 (relative error 3.4 % -> 2e-3 -> 1e-5 -> 3e-10 -> 1e-16). No libm
/// call (whose last bit may differ between libm versions), and ~2x cheaper than cbrt, which was
/// 15 % of a force evaluation.
double inverse_cbrt(double x);

/// Fills `out` (psi, P and, when `tangent`, A) from the scalar derivatives, at the invariants `v`
/// of F computed by isochoric_invariants(F).
void invariant_response(const Mat3& F, const Invariants& v, const InvariantDerivatives& d, bool tangent,
                        PointResponse& out);
/// Same, computing the invariants itself.
void invariant_response(const Mat3& F, const InvariantDerivatives& d, bool tangent, PointResponse& out);

/// Volumetric energy U(J) = K/2 (J - 1)^2, the Abaqus/CalculiX form (D1 = 2/K).
/// It is what the CalculiX reference uses, so results compare like with like.
inline void volumetric_abaqus(double K, double J, InvariantDerivatives& d) {
  d.U = 0.5 * K * (J - 1.0) * (J - 1.0);
  d.dU = K * (J - 1.0);
  d.d2U = K;
}

}  // namespace pneufem
