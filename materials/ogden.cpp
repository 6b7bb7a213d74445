#include "materials/ogden.h"

#include <Eigen/SVD>
#include <cassert>
#include <cmath>

#include "core/errors.h"
#include "core/number_text.h"
#include "materials/invariant_kernel.h"

namespace pneufem {

namespace {

void require(bool ok, const std::string& msg) {
  if (!ok) throw InputError(std::string(Ogden::kName) + ": " + msg);
}

// Divided difference (x^p - y^p) / (x - y) with x = y e^t, written as y^{p-1} expm1(p t) / expm1(t).
// expm1 is accurate to about an ulp for every t, so the ratio keeps full relative accuracy as t -> 0
// (an error delta in t changes it by only O(|p - 1| delta)) and t = 0 takes the exact limit p y^{p-1}.
// This is why equal or nearly equal stretches need neither a threshold nor a perturbation.
double power_divided_difference(double p, double log_y, double t) {
  const double ratio = (t == 0.0) ? p : std::expm1(p * t) / std::expm1(t);
  return std::exp((p - 1.0) * log_y) * ratio;
}

}  // namespace

Ogden::Ogden(const std::vector<double>& mu, const std::vector<double>& alpha, double K) : K_(K) {
  require(mu.size() == alpha.size(), "mu and alpha must have the same number of terms (got " +
                                         std::to_string(mu.size()) + " mu_i and " + std::to_string(alpha.size()) +
                                         " alpha_i)");
  require(!mu.empty() && mu.size() <= static_cast<std::size_t>(kMaxTerms),
          "1 to 3 terms (mu_i, alpha_i) are supported, got " + std::to_string(mu.size()));
  n_ = static_cast<int>(mu.size());
  for (int i = 0; i < n_; ++i) {
    const std::string id = std::to_string(i + 1);
    require(std::isfinite(mu[i]) && std::isfinite(alpha[i]),
            "mu_" + id + " and alpha_" + id + " must be finite numbers");
    require(alpha[i] != 0.0, "alpha_" + id + " must be non-zero (W divides by alpha_i^2)");
    mu_[i] = mu[i];
    alpha_[i] = alpha[i];
    mu0_ += mu[i];
  }
  require(std::isfinite(K_), "bulk modulus K must be a finite number");
  require(mu0_ > 0.0, "initial shear modulus mu0 = sum mu_i must be > 0, got " + short_num(mu0_) + " Pa");
  for (int i = 0; i < n_; ++i) {
    const std::string id = std::to_string(i + 1);
    require(mu_[i] > 0.0,
            "mu_" + id + " = " + short_num(mu_[i]) + " Pa (alpha_" + id + " = " + short_num(alpha_[i]) +
                ") violates Ogden's (1972) Drucker-type stability condition mu_p alpha_p > 0, which in the "
                "Abaqus convention used here reads mu_i > 0. If your constants follow W = sum mu_p/alpha_p "
                "(lambda_1^alpha_p + ... - 3), convert them with mu_i = mu_p alpha_p / 2 (Ogden::from_ogden1972)");
  }
  require(K_ > 0.0, "bulk modulus K must be > 0, got " + short_num(K_) + " Pa; set K0/mu0 (e.g. 100)");
}

Ogden Ogden::from_ogden1972(const std::vector<double>& mu_p, const std::vector<double>& alpha, double K) {
  std::vector<double> mu(mu_p);
  for (std::size_t i = 0; i < mu.size() && i < alpha.size(); ++i) mu[i] = 0.5 * mu_p[i] * alpha[i];
  return Ogden(mu, alpha, K);  // the constructor reports size mismatches
}

void Ogden::evaluate(std::span<const Mat3> F, const TimeStep&, std::span<const double>, std::span<double>,
                     std::span<PointResponse> out, bool tangent) const {
  for (std::size_t q = 0; q < F.size(); ++q) {
    // Volumetric part through the invariant kernel with W == 0, so U(J) is the same code (and the
    // same tests) as for the invariant laws; its isochoric terms come out zero and are overwritten.
    InvariantDerivatives d;
    volumetric_abaqus(K_, F[q].determinant(), d);
    invariant_response(F[q], d, tangent, out[q]);
    CalcIsochoric(F[q], tangent, out[q]);
  }
}

// Spectral form of the isochoric part, on the SVD F = U diag(lambda) V^T (lambda > 0 since det F > 0):
//   W = sum_i 2 mu_i/alpha_i^2 (Sb_i - 3),  Sb_i = sum_a lb_a^alpha_i,  lb_a = J^{-1/3} lambda_a,
//   tau_a = lambda_a dW/dlambda_a = sum_i 2 mu_i/alpha_i (lb_a^alpha_i - Sb_i/3)      (Kirchhoff, deviatoric),
//   dtau_a/dln lambda_b = sum_i 2 mu_i (delta_ab lb_a^alpha_i - (lb_a^alpha_i + lb_b^alpha_i)/3 + Sb_i/9),
// (principal-stretch form of Holzapfel 2000, ch. 6). With w_a = dW/dlambda_a = tau_a/lambda_a:
//   P = U diag(w) V^T,   w_ab = (dtau_a/dln lambda_b - delta_ab tau_a) / (lambda_a lambda_b),
// and in the (U, V) frame A = dP/dF couples only (aa, bb) through w_ab and, for a != b, the pair
// (ab, ba) through the 2x2 block [[D + S, D - S], [D - S, D + S]] / 2 (first-order perturbation of the
// SVD; the block structure of Teran, Sifakis, Irving and Fedkiw, SCA 2005), with
//   S = (w_a + w_b)/(lambda_a + lambda_b),  D = (w_a - w_b)/(lambda_a - lambda_b).
// D is the divided difference of g(x) = sum_i 2 mu_i/alpha_i (J^{-alpha_i/3} x^{alpha_i-1} - Sb_i/(3x)),
// which by homogeneity is D = J^{-2/3} sum_i 2 mu_i/alpha_i (dd_{alpha_i-1}(lb_a, lb_b) + Sb_i/(3 lb_a lb_b)),
// dd_p(x, y) = (x^p - y^p)/(x - y), evaluated without cancellation (power_divided_difference), so equal
// stretches (F = I, uniaxial states) use the exact limit D = w_aa - w_ab instead of 0/0.
// Powers are taken as exp(alpha ln lb) and W, tau use expm1, so they stay accurate near F = I.
void Ogden::CalcIsochoric(const Mat3& F, bool tangent, PointResponse& out) const {
  assert(F.determinant() > 0.0 && "Ogden: det F must be > 0 (checked by the assembler)");
  const Eigen::JacobiSVD<Mat3> svd(F, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Vec3 lambda = svd.singularValues();
  const Mat3& U = svd.matrixU();
  const Mat3& V = svd.matrixV();
  const Vec3 ln_lambda = lambda.array().log();
  const double ln_J = ln_lambda.sum();
  const Vec3 ln_lb = ln_lambda.array() - ln_J / 3.0;

  double W = 0.0;
  Vec3 tau = Vec3::Zero();
  Mat3 dtau = Mat3::Zero();  // dtau_a / dln lambda_b
  Mat3 D = Mat3::Zero();     // divided differences, upper triangle only
  for (int i = 0; i < n_; ++i) {
    const double a = alpha_[i], m = mu_[i];
    Vec3 pm1, p;  // lb^alpha - 1 and lb^alpha
    for (int c = 0; c < 3; ++c) {
      pm1[c] = std::expm1(a * ln_lb[c]);
      p[c] = 1.0 + pm1[c];
    }
    const double Sb_m3 = pm1.sum();
    const double Sb = 3.0 + Sb_m3;
    W += 2.0 * m / (a * a) * Sb_m3;
    tau += 2.0 * m / a * (pm1.array() - Sb_m3 / 3.0).matrix();
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) dtau(r, c) += 2.0 * m * ((r == c ? p[r] : 0.0) - (p[r] + p[c]) / 3.0 + Sb / 9.0);
    for (int r = 0; r < 3; ++r)
      for (int c = r + 1; c < 3; ++c)
        D(r, c) += 2.0 * m / a *
                   (power_divided_difference(a - 1.0, ln_lb[c], ln_lb[r] - ln_lb[c]) +
                    Sb / 3.0 * std::exp(-(ln_lb[r] + ln_lb[c])));
  }
  const Vec3 w = tau.array() / lambda.array();
  out.psi_iso = W;
  out.P_iso = U * w.asDiagonal() * V.transpose();
  if (!tangent) return;

  const double Jm23 = std::exp(-2.0 * ln_J / 3.0);
  Mat9 Ahat = Mat9::Zero();  // dP/dF in the (U, V) frame
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      Ahat(flat(r, r), flat(c, c)) = (dtau(r, c) - (r == c ? tau[r] : 0.0)) / (lambda[r] * lambda[c]);
  for (int r = 0; r < 3; ++r)
    for (int c = r + 1; c < 3; ++c) {
      const double Dab = Jm23 * D(r, c);
      const double Sab = (w[r] + w[c]) / (lambda[r] + lambda[c]);
      Ahat(flat(r, c), flat(r, c)) = Ahat(flat(c, r), flat(c, r)) = 0.5 * (Dab + Sab);
      Ahat(flat(r, c), flat(c, r)) = Ahat(flat(c, r), flat(r, c)) = 0.5 * (Dab - Sab);
    }
  // vec(U X V^T) = (V kron U) vec(X) for column-major vec, so A = T Ahat T^T with T = V kron U.
  Mat9 T;
  for (int a = 0; a < 3; ++a)
    for (int b = 0; b < 3; ++b)
      for (int i = 0; i < 3; ++i)
        for (int Jx = 0; Jx < 3; ++Jx) T(flat(i, Jx), flat(a, b)) = U(i, a) * V(Jx, b);
  out.A_iso = T * Ahat * T.transpose();
}

}  // namespace pneufem
