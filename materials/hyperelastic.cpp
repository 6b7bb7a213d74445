#include "materials/hyperelastic.h"

#include <cmath>
#include <limits>

#include "core/errors.h"
#include "core/number_text.h"

namespace pneufem {

namespace {
void require(bool ok, const std::string& law, const std::string& msg) {
  if (!ok) throw InputError(law + ": " + msg);
}
}  // namespace

double bulk_from_ratio(double mu0, double K_over_mu) {
  if (!(K_over_mu > 0.0))
    throw InputError("K0/mu0 must be > 0 (got " + short_num(K_over_mu) + "); typical silicone values are 100-1000");
  return K_over_mu * mu0;
}

Yeoh::Yeoh(double c10, double c20, double c30, double k) : C10(c10), C20(c20), C30(c30), K(k) {
  require(std::isfinite(C10) && std::isfinite(C20) && std::isfinite(C30) && std::isfinite(K), kName,
          "parameters must be finite numbers");
  require(C10 > 0.0, kName, "C10 must be > 0 (initial shear modulus mu0 = 2 C10), got " + short_num(C10) + " Pa");
  require(K > 0.0, kName, "bulk modulus K must be > 0, got " + short_num(K) + " Pa; set K0/mu0 (e.g. 100)");
}

double Yeoh::stability_limit_I1b_minus_3() const {
  // smallest positive root of C10 + 2 C20 x + 3 C30 x^2
  const double a = 3.0 * C30, b = 2.0 * C20, c = C10;
  if (a == 0.0) return b < 0.0 ? -c / b : std::numeric_limits<double>::infinity();
  const double disc = b * b - 4.0 * a * c;
  if (disc < 0.0) return std::numeric_limits<double>::infinity();
  const double r1 = (-b - std::sqrt(disc)) / (2.0 * a), r2 = (-b + std::sqrt(disc)) / (2.0 * a);
  double best = std::numeric_limits<double>::infinity();
  for (double r : {r1, r2})
    if (r > 0.0) best = std::min(best, r);
  return best;
}

NeoHookean::NeoHookean(double c10, double k) : C10(c10), K(k) {
  require(std::isfinite(C10) && std::isfinite(K), kName, "parameters must be finite numbers");
  require(C10 > 0.0, kName, "C10 must be > 0 (mu0 = 2 C10), got " + short_num(C10) + " Pa");
  require(K > 0.0, kName, "bulk modulus K must be > 0, got " + short_num(K) + " Pa");
}

MooneyRivlin::MooneyRivlin(double c10, double c01, double k) : C10(c10), C01(c01), K(k) {
  require(std::isfinite(C10) && std::isfinite(C01) && std::isfinite(K), kName, "parameters must be finite numbers");
  require(C10 + C01 > 0.0, kName, "C10 + C01 must be > 0 (mu0 = 2 (C10 + C01)), got " + short_num(C10 + C01) + " Pa");
  require(C10 >= 0.0 || C01 >= 0.0, kName, "C10 and C01 cannot both be negative");
  require(K > 0.0, kName, "bulk modulus K must be > 0, got " + short_num(K) + " Pa");
}

SaintVenantKirchhoff::SaintVenantKirchhoff(double E, double nu) : E_(E), nu_(nu) {
  require(std::isfinite(E) && std::isfinite(nu), "linear_elastic", "E and nu must be finite numbers");
  require(E > 0.0, "linear_elastic", "Young's modulus E must be > 0, got " + short_num(E) + " Pa");
  require(nu > -1.0 && nu < 0.5, "linear_elastic", "Poisson ratio must lie in (-1, 0.5), got " + short_num(nu));
  lambda_ = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
  mu_ = E / (2.0 * (1.0 + nu));
}

// Force only, batched (material.h: StressBatch): evaluate's arithmetic lane by lane, each sum in the
// order Eigen evaluates it there (F^T F and rows 0-1 of F S left to right, row 2 of F S and the traces
// right to left), so the results are evaluate's bit for bit. The (lambda tr E) * 0 of the off-diagonal
// S entries is kept: it fixes the sign of a zero exactly as the scalar path does.
void SaintVenantKirchhoff::stress(StressBatch& b, const TimeStep&, std::span<const double>, std::span<double>) const {
  constexpr int N = StressBatch::kLanes;
  const auto& F = b.F;
  double E[9][N], S[9][N], trE[N];
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      const double delta = i == j ? 1.0 : 0.0;
      for (int l = 0; l < N; ++l) {  // E = (F^T F - I) / 2, F^T F(i,j) = F.col(i) . F.col(j)
        const double C = (F[3 * i][l] * F[3 * j][l] + F[3 * i + 1][l] * F[3 * j + 1][l]) + F[3 * i + 2][l] * F[3 * j + 2][l];
        E[i + 3 * j][l] = 0.5 * (C - delta);
      }
    }
  for (int l = 0; l < N; ++l) {
    trE[l] = E[0][l] + (E[4][l] + E[8][l]);
    const double EE0 = E[0][l] * E[0][l] + (E[3][l] * E[1][l] + E[6][l] * E[2][l]);  // diagonal of E E
    const double EE1 = E[1][l] * E[3][l] + (E[4][l] * E[4][l] + E[7][l] * E[5][l]);
    const double EE2 = E[2][l] * E[6][l] + (E[5][l] * E[7][l] + E[8][l] * E[8][l]);
    b.psi_iso[l] = 0.5 * lambda_ * trE[l] * trE[l] + mu_ * (EE0 + (EE1 + EE2));
    b.psi_vol[l] = 0.0;
  }
  for (int k = 0; k < 9; ++k) {
    const double delta = k % 4 == 0 ? 1.0 : 0.0;
    for (int l = 0; l < N; ++l) S[k][l] = lambda_ * trE[l] * delta + 2.0 * mu_ * E[k][l];
  }
  for (int j = 0; j < 3; ++j) {  // P = F S: rows 0-1 left to right, row 2 right to left
    for (int i = 0; i < 2; ++i)
      for (int l = 0; l < N; ++l)
        b.P_iso[i + 3 * j][l] = (F[i][l] * S[3 * j][l] + F[i + 3][l] * S[1 + 3 * j][l]) + F[i + 6][l] * S[2 + 3 * j][l];
    for (int l = 0; l < N; ++l)
      b.P_iso[2 + 3 * j][l] = F[2][l] * S[3 * j][l] + (F[5][l] * S[1 + 3 * j][l] + F[8][l] * S[2 + 3 * j][l]);
  }
  for (int k = 0; k < 9; ++k)
    for (int l = 0; l < N; ++l) b.P_vol[k][l] = 0.0;
}

void SaintVenantKirchhoff::evaluate(std::span<const Mat3> Fs, const TimeStep&, std::span<const double>,
                                    std::span<double>, std::span<PointResponse> out, bool tangent) const {
  for (std::size_t q = 0; q < Fs.size(); ++q) {
    const Mat3& F = Fs[q];
    const Mat3 E = 0.5 * (F.transpose() * F - Mat3::Identity());
    const double trE = E.trace();
    const Mat3 S = lambda_ * trE * Mat3::Identity() + 2.0 * mu_ * E;
    PointResponse& r = out[q];
    r.psi_iso = 0.5 * lambda_ * trE * trE + mu_ * (E * E).trace();
    r.psi_vol = 0.0;
    r.P_iso = F * S;
    r.P_vol.setZero();
    if (!tangent) continue;
    // A_iJkL = delta_ik S_JL + F_iM F_kN (lambda d_MJ d_NL + mu (d_MN d_JL + d_ML d_JN))
    r.A_vol.setZero();
    Mat9& A = r.A_iso;
    for (int i = 0; i < 3; ++i)
      for (int J = 0; J < 3; ++J)
        for (int k = 0; k < 3; ++k)
          for (int L = 0; L < 3; ++L) {
            double v = (i == k ? S(J, L) : 0.0);
            v += lambda_ * F(i, J) * F(k, L) + mu_ * ((F.row(i).dot(F.row(k))) * (J == L ? 1.0 : 0.0) + F(i, L) * F(k, J));
            A(flat(i, J), flat(k, L)) = v;
          }
  }
}

}  // namespace pneufem
