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
#include <cstdint>
#include <cstring>
#include <limits>

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
/// The two halves of inverse_cbrt, shared with the batched path so that both round alike.
inline double inverse_cbrt_guess(double x) {
  std::uint64_t i;
  std::memcpy(&i, &x, sizeof i);
  i = 0x553ef0ff289dd796ULL - i / 3;  // exponent / -3 with a tuned mantissa: within 3.4 %
  double y;
  std::memcpy(&y, &i, sizeof y);
  return y;
}
inline double inverse_cbrt_step(double x, double y) { return y * (4.0 - x * y * y * y) * (1.0 / 3.0); }

/// Fills `out` (psi, P and, when `tangent`, A) from the scalar derivatives, at the invariants `v`
/// of F computed by isochoric_invariants(F).
void invariant_response(const Mat3& F, const Invariants& v, const InvariantDerivatives& d, bool tangent,
                        PointResponse& out);
/// Same, computing the invariants itself.
void invariant_response(const Mat3& F, const InvariantDerivatives& d, bool tangent, PointResponse& out);

/// Force-only response of a batch (material.h: StressBatch) of the law `law`: the arithmetic of
/// isochoric_invariants, law.derivatives and invariant_response(tangent = false), written as loops
/// over the lanes, which the compiler vectorises. Each lane performs the scalar path's operations in
/// the same order - the sums are ordered as Eigen evaluates the scalar path's expressions: the dot
/// product and the entries of F^T F left to right, the trace as Eigen's pairwise reduction,
/// x0 + (x1 + x2) - so the results are those of evaluate() bit for bit (test
/// MaterialBattery.StressBatchIsEvaluateBitForBit). A law of I2b (Law::kUsesI2, Mooney-Rivlin)
/// takes the scalar path point by point: the batched arithmetic covers laws of I1b alone.
template <class Law>
void invariant_stress_batch(const Law& law, StressBatch& b) {
  if constexpr (Law::kUsesI2) {  // the scalar path, point by point
    for (int l = 0; l < b.n; ++l) {
      const Mat3 Fl = b.F_of(l);
      const Invariants v = isochoric_invariants(Fl);
      PointResponse r;
      invariant_response(Fl, v, law.derivatives(v), false, r);
      b.set_response(l, r);
    }
    return;
  }
  constexpr int N = StressBatch::kLanes;
  const auto& F = b.F;
  double cof[9][N], J[N], I1[N], y[N], Jm23[N], W1[N], dU[N];
  for (int l = 0; l < N; ++l) {
    // Columns of the cofactor matrix: cof.col(j) = F.col(j+1) x F.col(j+2).
    cof[0][l] = F[4][l] * F[8][l] - F[5][l] * F[7][l];
    cof[1][l] = F[5][l] * F[6][l] - F[3][l] * F[8][l];
    cof[2][l] = F[3][l] * F[7][l] - F[4][l] * F[6][l];
    cof[3][l] = F[7][l] * F[2][l] - F[8][l] * F[1][l];
    cof[4][l] = F[8][l] * F[0][l] - F[6][l] * F[2][l];
    cof[5][l] = F[6][l] * F[1][l] - F[7][l] * F[0][l];
    cof[6][l] = F[1][l] * F[5][l] - F[2][l] * F[4][l];
    cof[7][l] = F[2][l] * F[3][l] - F[0][l] * F[5][l];
    cof[8][l] = F[0][l] * F[4][l] - F[1][l] * F[3][l];
    J[l] = (F[0][l] * cof[0][l] + F[1][l] * cof[1][l]) + F[2][l] * cof[2][l];
    // tr C = tr F^T F
    const double C00 = (F[0][l] * F[0][l] + F[1][l] * F[1][l]) + F[2][l] * F[2][l];
    const double C11 = (F[3][l] * F[3][l] + F[4][l] * F[4][l]) + F[5][l] * F[5][l];
    const double C22 = (F[6][l] * F[6][l] + F[7][l] * F[7][l]) + F[8][l] * F[8][l];
    I1[l] = C00 + (C11 + C22);
  }
  for (int l = 0; l < N; ++l) y[l] = inverse_cbrt_guess(J[l]);  // integer arithmetic: stays scalar
  for (int l = 0; l < N; ++l) {
    double yl = y[l];
    for (int k = 0; k < 4; ++k) yl = inverse_cbrt_step(J[l], yl);
    Jm23[l] = yl * yl;
  }
  for (int l = 0; l < N; ++l)  // an inverted point has no isochoric part (as isochoric_invariants)
    if (!(J[l] > 0.0)) Jm23[l] = std::numeric_limits<double>::quiet_NaN();
  for (int l = 0; l < N; ++l) {
    Invariants v;  // lane l, for the law (which reads neither I2 nor I2b)
    v.J = J[l];
    v.I1 = I1[l];
    v.Jm23 = Jm23[l];
    v.I1b = v.Jm23 * v.I1;
    v.I2b = 0.0;
    const InvariantDerivatives d = law.derivatives(v);
    b.psi_iso[l] = d.W;
    b.psi_vol[l] = d.U;
    W1[l] = d.W1;
    dU[l] = d.dU;
  }
  for (int k = 0; k < 9; ++k)
    for (int l = 0; l < N; ++l) {
      const double H = cof[k][l] / J[l];                                       // F^{-T}
      const double g1 = Jm23[l] * (2.0 * F[k][l] - ((2.0 / 3.0) * I1[l]) * H);  // dI1b/dF
      b.P_iso[k][l] = W1[l] * g1;
      b.P_vol[k][l] = dU[l] * cof[k][l];
    }
}

/// Volumetric energy U(J) = K/2 (J - 1)^2, the Abaqus/CalculiX form (D1 = 2/K).
/// It is what the CalculiX reference uses, so results compare like with like.
inline void volumetric_abaqus(double K, double J, InvariantDerivatives& d) {
  d.U = 0.5 * K * (J - 1.0) * (J - 1.0);
  d.dU = K * (J - 1.0);
  d.d2U = K;
}

}  // namespace pneufem
