#pragma once
// Helpers shared by the material tests: single-point evaluation, the deformation states of the
// derivative battery, and homogeneous uniaxial tension solved with the material's own tangent and
// checked against an incompressible curve.
#include <cmath>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "materials/material.h"
#include "materials/ogden.h"

namespace pneufem::test {

inline PointResponse eval(const Material& m, const Mat3& F, bool tangent = true) {
  PointResponse r;
  m.evaluate(std::span<const Mat3>(&F, 1), TimeStep{}, {}, {}, std::span<PointResponse>(&r, 1), tangent);
  return r;
}

template <class Derived>
double max_abs(const Eigen::MatrixBase<Derived>& a) {
  return a.cwiseAbs().maxCoeff();
}

/// Uniformly distributed rotation (normalised Gaussian quaternion), reproducible through `rng`.
inline Mat3 random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  q.normalize();
  return q.toRotationMatrix();
}

/// Ogden's (1972) fit of Treloar's rubber, first `terms` terms, K = K_over_mu0 * mu0. Constants in
/// Ogden's convention as given in tests/data/treloar1944/README.md: mu_p = 0.63, 0.0012, -0.01 MPa.
inline Ogden treloar_ogden1972(double K_over_mu0, int terms = 3) {
  const std::vector<double> mu_p{0.63e6, 0.0012e6, -0.01e6}, alpha{1.3, 5.0, -2.0};
  const std::vector<double> m(mu_p.begin(), mu_p.begin() + terms), a(alpha.begin(), alpha.begin() + terms);
  const double mu0 = Ogden::from_ogden1972(m, a, 1.0).initial_shear_modulus();
  return Ogden::from_ogden1972(m, a, K_over_mu0 * mu0);
}

struct State {
  std::string label;
  Mat3 F;
  bool generic;  ///< random state with |J - 1| >= 0.1: every stress part must be clearly non-zero
};

/// F = I, degenerate and nearly degenerate principal stretches (the spectral laws' hard cases), a pure
/// dilatation, and 6 random F = R1 diag(s) R2^T with s in [0.6, 2.5], J in [0.5, 2], |J - 1| >= 0.1.
/// Independent R1, R2 make F non-symmetric, so rotation and stretch are both exercised.
inline std::vector<State> battery_states() {
  std::mt19937 rng(20240611);
  std::vector<State> s;
  const Mat3 R1 = random_rotation(rng), R2 = random_rotation(rng);
  const auto stretch = [&](double a, double b, double c) { return Mat3(R1 * Vec3(a, b, c).asDiagonal() * R2.transpose()); };
  const double l = 1.8;
  s.push_back({"identity", Mat3::Identity(), false});
  s.push_back({"uniaxial lambda2 == lambda3", stretch(l, 1.0 / std::sqrt(l), 1.0 / std::sqrt(l)), false});
  s.push_back({"lambda2 / lambda3 = 1 + 1e-7", stretch(1.5, 0.8, 0.8 * (1.0 + 1e-7)), false});
  s.push_back({"dilatation 1.1 I (rotated)", stretch(1.1, 1.1, 1.1), false});
  std::uniform_real_distribution<double> u(0.6, 2.5);
  while (s.size() < 10) {
    const Vec3 d(u(rng), u(rng), u(rng));
    const double J = d.prod();
    if (J < 0.5 || J > 2.0 || std::abs(J - 1.0) < 0.1) continue;
    const Mat3 Ra = random_rotation(rng), Rb = random_rotation(rng);
    s.push_back({"random " + std::to_string(s.size() - 3), Ra * d.asDiagonal() * Rb.transpose(), true});
  }
  return s;
}

struct Uniaxial {
  double P11, P22, P33, lateral;
};

/// Homogeneous uniaxial tension F = diag(lambda, s, s): 1-D Newton on the lateral stretch s for
/// P22 = 0 (P33 = P22 by symmetry) with dP22/ds = A(22,22) + A(22,33) from the material itself.
inline Uniaxial solve_uniaxial(const Material& m, double lambda) {
  const auto F = [lambda](double s) { return Mat3(Vec3(lambda, s, s).asDiagonal()); };
  double s = 1.0 / std::sqrt(lambda);  // incompressible guess
  for (int it = 0; it < 50; ++it) {
    const PointResponse r = eval(m, F(s));
    const Mat9 A = r.A();
    const double ds = -r.P()(1, 1) / (A(flat(1, 1), flat(1, 1)) + A(flat(1, 1), flat(2, 2)));
    s += ds;
    if (std::abs(ds) <= 1e-15 * s) break;
  }
  const Mat3 P = eval(m, F(s), false).P();
  return {P(0, 0), P(1, 1), P(2, 2), s};
}

/// Checks uniaxial tension of a nearly incompressible decoupled law against its incompressible
/// nominal stress P_inc(lambda) for lambda in [1, lambda_max].
///
/// Compressibility error. With sigma_22 = 0 the mean Cauchy stress is sigma/3, so J = 1 + delta,
/// delta = sigma/(3K). A decoupled law with U = U(J) gives exactly sigma_11 = sigma_inc(lb)/J,
/// lb = lambda J^{-1/3}, where sigma_inc(x) = x P_inc(x); hence P11 = sigma_inc(lb)/lambda and
///   P11 / P_inc(lambda) - 1 = -lambda sigma_inc'(lambda) / (9K) + O(delta^2),
/// which is -mu0/(3K) at small strain (the expected O(mu0/K)) and grows with the tangent stiffness
/// at large stretch. The first check allows twice that first-order error; the second checks the exact
/// identity P11 = sigma_inc(lb)/lambda to round-off (the Newton solve converges to |ds| <= 1e-15 s).
inline void check_uniaxial(const Material& m, const std::function<double(double)>& P_inc, double lambda_max) {
  const double K = m.initial_bulk_modulus(), mu0 = m.initial_shear_modulus();
  const auto sigma_inc = [&](double x) { return x * P_inc(x); };
  for (double lambda = 1.0; lambda <= lambda_max + 1e-12; lambda += 0.25) {
    SCOPED_TRACE("lambda = " + std::to_string(lambda));
    const test::Uniaxial u = solve_uniaxial(m, lambda);
    EXPECT_LE(std::abs(u.P22), 1e-12 * K);
    EXPECT_LE(std::abs(u.P33), 1e-12 * K);
    const double dsigma = (sigma_inc(lambda * (1 + 1e-6)) - sigma_inc(lambda * (1 - 1e-6))) / (2e-6 * lambda);
    const double rel_first_order = lambda * dsigma / (9.0 * K);
    EXPECT_NEAR(u.P11, P_inc(lambda), 2.0 * rel_first_order * std::abs(P_inc(lambda)) + 1e-9 * mu0);
    const double J = lambda * u.lateral * u.lateral;
    const double lb = lambda * std::cbrt(1.0 / J);
    EXPECT_NEAR(u.P11, sigma_inc(lb) / lambda, 1e-9 * std::abs(u.P11) + 1e-9 * mu0);
  }
}

}  // namespace pneufem::test
