#include "materials/invariant_kernel.h"

#include <cmath>

namespace pneufem {

double inverse_cbrt(double x) {
  double y = inverse_cbrt_guess(x);
  for (int k = 0; k < 4; ++k) y = inverse_cbrt_step(x, y);
  return y;
}

Invariants isochoric_invariants(const Mat3& F) {
  Invariants v;
  // Cofactor matrix by columns: cof.col(J) = F.col(J+1) x F.col(J+2); then J = F.col(0) . cof.col(0).
  v.cof.col(0) = F.col(1).cross(F.col(2));
  v.cof.col(1) = F.col(2).cross(F.col(0));
  v.cof.col(2) = F.col(0).cross(F.col(1));
  v.J = F.col(0).dot(v.cof.col(0));
  const Mat3 C = F.transpose() * F;
  v.I1 = C.trace();
  v.I2 = 0.5 * (v.I1 * v.I1 - C.squaredNorm());  // tr(C^2) = |C|^2, C symmetric
  // J <= 0 (an inverted point) has no isochoric part: NaN, which every caller reports as a
  // non-finite stress naming the element (the bit-level guess would return garbage for J < 0).
  const double r = v.J > 0.0 ? inverse_cbrt(v.J) : std::numeric_limits<double>::quiet_NaN();
  v.Jm23 = r * r;
  v.I1b = v.Jm23 * v.I1;
  v.I2b = v.Jm23 * v.Jm23 * v.I2;
  return v;
}

void invariant_response(const Mat3& F, const InvariantDerivatives& d, bool tangent, PointResponse& out) {
  invariant_response(F, isochoric_invariants(F), d, tangent, out);
}

void invariant_response(const Mat3& F, const Invariants& v, const InvariantDerivatives& d, bool tangent,
                        PointResponse& out) {
  const double J = v.J, I1 = v.I1, I2 = v.I2;
  const Mat3 H = v.cof / J;  // F^{-T}
  const double a = v.Jm23;   // J^{-2/3}
  const double b = a * a;    // J^{-4/3}

  const Mat3 g1 = a * (2.0 * F - (2.0 / 3.0) * I1 * H);  // dI1b/dF
  out.psi_iso = d.W;
  out.psi_vol = d.U;
  out.P_vol = d.dU * v.cof;  // U'(J) dJ/dF = U' J H
  // Laws of I1b alone (Yeoh, neo-Hookean) skip the I2b terms: that is the common case.
  const bool has_i2 = d.W2 != 0.0 || d.W12 != 0.0 || d.W22 != 0.0;
  if (!has_i2 && !tangent) {
    out.P_iso = d.W1 * g1;
    return;
  }
  const Mat3 C = F.transpose() * F;
  const Mat3 B = F * F.transpose();
  const Mat3 FC = F * C;
  const Mat3 G2 = 2.0 * (I1 * F - FC);              // dI2/dF
  const Mat3 g2 = b * (G2 - (4.0 / 3.0) * I2 * H);  // dI2b/dF
  out.P_iso = d.W1 * g1 + d.W2 * g2;
  if (!tangent) return;

  const Vec9 v1 = flatten(g1), v2 = flatten(g2), vH = flatten(H);
  Mat9& Ai = out.A_iso;
  Ai = d.W11 * v1 * v1.transpose() + d.W12 * (v1 * v2.transpose() + v2 * v1.transpose()) +
       d.W22 * v2 * v2.transpose();
  Mat9& Av = out.A_vol;
  // d(J H)/dF = J (H (x) H - H_iL H_kJ);  d2U: U'' J^2 H (x) H.
  Av = (d.d2U * J * J + d.dU * J) * vH * vH.transpose();
  for (int i = 0; i < 3; ++i)
    for (int Jx = 0; Jx < 3; ++Jx)
      for (int k = 0; k < 3; ++k)
        for (int L = 0; L < 3; ++L) {
          const int r = flat(i, Jx), c = flat(k, L);
          const double HH = H(i, L) * H(k, Jx);
          const double dik = (i == k) ? 1.0 : 0.0, dJL = (Jx == L) ? 1.0 : 0.0;
          Av(r, c) -= d.dU * J * HH;
          // d2 I1b / dF2
          const double d2I1b = -(2.0 / 3.0) * a * H(k, L) * (2.0 * F(i, Jx) - (2.0 / 3.0) * I1 * H(i, Jx)) +
                               a * (2.0 * dik * dJL - (4.0 / 3.0) * F(k, L) * H(i, Jx) + (2.0 / 3.0) * I1 * HH);
          double acc = d.W1 * d2I1b;
          if (d.W2 != 0.0) {
            const double dG2 = 2.0 * (2.0 * F(i, Jx) * F(k, L) + I1 * dik * dJL - dik * C(L, Jx) -
                                      F(i, L) * F(k, Jx) - dJL * B(i, k));
            const double d2I2b = -(4.0 / 3.0) * b * H(k, L) * (G2(i, Jx) - (4.0 / 3.0) * I2 * H(i, Jx)) +
                                 b * (dG2 - (4.0 / 3.0) * G2(k, L) * H(i, Jx) + (4.0 / 3.0) * I2 * HH);
            acc += d.W2 * d2I2b;
          }
          Ai(r, c) += acc;
        }
}

}  // namespace pneufem
