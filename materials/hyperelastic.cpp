#include "materials/hyperelastic.h"

#include <cmath>
#include <limits>
#include <sstream>

#include "materials/errors.h"

namespace pneufem {

namespace {
void require(bool ok, const std::string& law, const std::string& msg) {
  if (!ok) throw InputError(law + ": " + msg);
}
std::string num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}
}  // namespace

double bulk_from_ratio(double mu0, double K_over_mu) {
  if (!(K_over_mu > 0.0))
    throw InputError("K0/mu0 must be > 0 (got " + num(K_over_mu) + "); typical silicone values are 100-1000");
  return K_over_mu * mu0;
}

Yeoh::Yeoh(double c10, double c20, double c30, double k) : C10(c10), C20(c20), C30(c30), K(k) {
  require(std::isfinite(C10) && std::isfinite(C20) && std::isfinite(C30) && std::isfinite(K), kName,
          "parameters must be finite numbers");
  require(C10 > 0.0, kName, "C10 must be > 0 (initial shear modulus mu0 = 2 C10), got " + num(C10) + " Pa");
  require(K > 0.0, kName, "bulk modulus K must be > 0, got " + num(K) + " Pa; set K0/mu0 (e.g. 100)");
}

InvariantDerivatives Yeoh::derivatives(const Invariants& v) const {
  const double x = v.I1b - 3.0;
  InvariantDerivatives d;
  d.W = x * (C10 + x * (C20 + x * C30));
  d.W1 = C10 + x * (2.0 * C20 + 3.0 * C30 * x);
  d.W11 = 2.0 * C20 + 6.0 * C30 * x;
  volumetric_abaqus(K, v.J, d);
  return d;
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
  require(C10 > 0.0, kName, "C10 must be > 0 (mu0 = 2 C10), got " + num(C10) + " Pa");
  require(K > 0.0, kName, "bulk modulus K must be > 0, got " + num(K) + " Pa");
}

InvariantDerivatives NeoHookean::derivatives(const Invariants& v) const {
  InvariantDerivatives d;
  d.W = C10 * (v.I1b - 3.0);
  d.W1 = C10;
  volumetric_abaqus(K, v.J, d);
  return d;
}

MooneyRivlin::MooneyRivlin(double c10, double c01, double k) : C10(c10), C01(c01), K(k) {
  require(std::isfinite(C10) && std::isfinite(C01) && std::isfinite(K), kName, "parameters must be finite numbers");
  require(C10 + C01 > 0.0, kName, "C10 + C01 must be > 0 (mu0 = 2 (C10 + C01)), got " + num(C10 + C01) + " Pa");
  require(C10 >= 0.0 || C01 >= 0.0, kName, "C10 and C01 cannot both be negative");
  require(K > 0.0, kName, "bulk modulus K must be > 0, got " + num(K) + " Pa");
}

InvariantDerivatives MooneyRivlin::derivatives(const Invariants& v) const {
  InvariantDerivatives d;
  d.W = C10 * (v.I1b - 3.0) + C01 * (v.I2b - 3.0);
  d.W1 = C10;
  d.W2 = C01;
  volumetric_abaqus(K, v.J, d);
  return d;
}

SaintVenantKirchhoff::SaintVenantKirchhoff(double E, double nu) : E_(E), nu_(nu) {
  require(std::isfinite(E) && std::isfinite(nu), "linear_elastic", "E and nu must be finite numbers");
  require(E > 0.0, "linear_elastic", "Young's modulus E must be > 0, got " + num(E) + " Pa");
  require(nu > -1.0 && nu < 0.5, "linear_elastic", "Poisson ratio must lie in (-1, 0.5), got " + num(nu));
  lambda_ = E * nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
  mu_ = E / (2.0 * (1.0 + nu));
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
