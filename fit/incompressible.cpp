#include "fit/incompressible.h"

#include <cmath>
#include <memory>

#include "core/errors.h"
#include "materials/hyperelastic.h"
#include "materials/ogden.h"

namespace pneufem::fit {

const char* mode_name(TestMode m) {
  switch (m) {
    case TestMode::uniaxial: return "uniaxial";
    case TestMode::biaxial: return "biaxial";
    case TestMode::planar: return "planar";
  }
  return "?";
}

const char* law_name(Law law) {
  switch (law) {
    case Law::neo_hookean: return "neo_hookean";
    case Law::mooney_rivlin: return "mooney_rivlin";
    case Law::yeoh: return "yeoh";
    case Law::ogden: return "ogden";
  }
  return "?";
}

Vec3 mode_stretches(TestMode m, double l) {
  switch (m) {
    case TestMode::uniaxial: return Vec3(l, 1.0 / std::sqrt(l), 1.0 / std::sqrt(l));
    case TestMode::biaxial: return Vec3(l, l, 1.0 / (l * l));
    case TestMode::planar: return Vec3(l, 1.0, 1.0 / l);
  }
  return Vec3::Ones();
}

double Constants::mu0() const {
  switch (law) {
    case Law::neo_hookean:
    case Law::yeoh: return 2.0 * c.at(0);
    case Law::mooney_rivlin: return 2.0 * (c.at(0) + c.at(1));
    case Law::ogden: {
      double s = 0.0;
      for (double m : c) s += m;
      return s;
    }
  }
  return 0.0;
}

int modulus_count(Law law, int ogden_terms) {
  switch (law) {
    case Law::neo_hookean: return 1;
    case Law::mooney_rivlin: return 2;
    case Law::yeoh: return 3;
    case Law::ogden: return ogden_terms;
  }
  return 0;
}

Eigen::MatrixXd kirchhoff_basis(Law law, const std::vector<double>& alpha, const Vec3& lambda) {
  const int n = modulus_count(law, static_cast<int>(alpha.size()));
  Eigen::MatrixXd B(n, 3);
  const double I1 = lambda.squaredNorm();
  for (int a = 0; a < 3; ++a) {
    const double l2 = lambda[a] * lambda[a];
    switch (law) {
      case Law::neo_hookean: B(0, a) = 2.0 * l2; break;  // tau_a = 2 W1 l_a^2, W1 = C10
      case Law::mooney_rivlin:                          // ... - 2 W2 l_a^-2, W2 = C01
        B(0, a) = 2.0 * l2;
        B(1, a) = -2.0 / l2;
        break;
      case Law::yeoh: {  // W1 = C10 + 2 C20 x + 3 C30 x^2, x = I1 - 3
        const double x = I1 - 3.0;
        B(0, a) = 2.0 * l2;
        B(1, a) = 2.0 * l2 * 2.0 * x;
        B(2, a) = 2.0 * l2 * 3.0 * x * x;
        break;
      }
      case Law::ogden:
        for (int i = 0; i < n; ++i) B(i, a) = 2.0 / alpha[i] * std::pow(lambda[a], alpha[i]);
        break;
    }
  }
  return B;
}

Eigen::VectorXd nominal_stress_basis(Law law, const std::vector<double>& alpha, TestMode m, double l) {
  if (law != Law::ogden) {
    const Eigen::MatrixXd B = kirchhoff_basis(law, alpha, mode_stretches(m, l));
    return (B.col(0) - B.col(2)) / l;
  }
  // (tau_1 - tau_3)/l per mu_i without the cancellation of l^alpha - l^(-c alpha) near l = 1.
  const double c = m == TestMode::uniaxial ? 0.5 : m == TestMode::biaxial ? 2.0 : 1.0;
  const double L = std::log(l);
  Eigen::VectorXd b(static_cast<Eigen::Index>(alpha.size()));
  for (std::size_t i = 0; i < alpha.size(); ++i) {
    const double a = alpha[i];
    const double ratio = a == 0.0 ? (1.0 + c) * L : (std::expm1(a * L) - std::expm1(-c * a * L)) / a;
    b[static_cast<Eigen::Index>(i)] = 2.0 * ratio / l;
  }
  return b;
}

double nominal_stress(const Constants& k, TestMode m, double lambda) {
  const Eigen::VectorXd b = nominal_stress_basis(k.law, k.alpha, m, lambda);
  return b.dot(Eigen::Map<const Eigen::VectorXd>(k.c.data(), static_cast<Eigen::Index>(k.c.size())));
}

double strain_energy(const Constants& k, const Vec3& l) {
  if (k.law == Law::ogden) {
    double W = 0.0;
    for (std::size_t i = 0; i < k.c.size(); ++i) {
      const double a = k.alpha[i];
      double s = 0.0;
      for (int c = 0; c < 3; ++c) s += std::expm1(a * std::log(l[c]));
      W += 2.0 * k.c[i] / (a * a) * s;
    }
    return W;
  }
  Invariants v{};
  v.J = 1.0;
  v.I1b = l.squaredNorm();
  v.I2b = l.cwiseInverse().squaredNorm();
  switch (k.law) {
    case Law::neo_hookean: return NeoHookean(k.c[0], 1.0).derivatives(v).W;
    case Law::mooney_rivlin: return MooneyRivlin(k.c[0], k.c[1], 1.0).derivatives(v).W;
    default: return Yeoh(k.c[0], k.c[1], k.c[2], 1.0).derivatives(v).W;
  }
}

MaterialPtr make_law_material(const Constants& k, double K) {
  switch (k.law) {
    case Law::neo_hookean: return std::make_shared<InvariantMaterial<NeoHookean>>(NeoHookean(k.c.at(0), K));
    case Law::mooney_rivlin:
      return std::make_shared<InvariantMaterial<MooneyRivlin>>(MooneyRivlin(k.c.at(0), k.c.at(1), K));
    case Law::yeoh: return std::make_shared<InvariantMaterial<Yeoh>>(Yeoh(k.c.at(0), k.c.at(1), k.c.at(2), K));
    case Law::ogden: return std::make_shared<Ogden>(k.c, k.alpha, K);
  }
  throw InputError("unknown law");
}

}  // namespace pneufem::fit
