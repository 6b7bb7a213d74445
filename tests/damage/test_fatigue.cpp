// Fatigue damage decorator: irreversibility, the exact solution of the rate law at a constant driver,
// first-order convergence of the backward-Euler update, threshold, failure flag.
#include <gtest/gtest.h>

#include <Eigen/Eigenvalues>
#include <cmath>
#include <cstdio>
#include <functional>
#include <random>
#include <string>
#include <vector>

#include "core/errors.h"
#include "damage/effects.h"
#include "damage/material_point.h"
#include "materials/hyperelastic.h"

namespace pneufem {
namespace {

constexpr double C10 = 0.019e6, C20 = 9.0e2, C30 = -4.75;  // Ecoflex 00-50, Pa
constexpr double K = 100.0 * 2.0 * C10;

MaterialPtr ecoflex() { return std::make_shared<InvariantMaterial<Yeoh>>(Yeoh(C10, C20, C30, K)); }

/// Isochoric uniaxial stretch.
Mat3 uniaxial(double lambda) { return Vec3(lambda, 1.0 / std::sqrt(lambda), 1.0 / std::sqrt(lambda)).asDiagonal(); }

double base_energy(const Mat3& F) {
  PointResponse r;
  ecoflex()->evaluate(std::span<const Mat3>(&F, 1), TimeStep{}, {}, {}, std::span<PointResponse>(&r, 1), false);
  return r.psi_iso;
}

double damage(const MaterialPoint& mp) { return FatigueDamage::damage(mp.committed_state()); }

// W_th = 5 kPa: uniaxial lambda = 1.3 (W0 ~ 3.5 kPa) is below, lambda = 2 (W0 ~ 42 kPa) well above.
const FatigueParams kParams{5e3, 10.0, 2.0, 0.5};
// The same law with its failure threshold above every damage the rate-law tests reach (0.86 at
// most): those tests are about the integration of dd/dt, which stops at d_fail.
const FatigueParams kRate{5e3, 10.0, 2.0, 0.99};

TEST(Fatigue, DamageNeverDecreasesAndStaysBelowOne) {
  // tau = 3000 s: without a failure threshold the sequence ends near d = 0.79; it reaches d_fail = 0.7
  // late, after which the damage stays exactly there (the point has failed).
  const FatigueParams p{kParams.W_th_Pa, 3000.0, kParams.q, 0.7};
  MaterialPoint mp(make_fatigue(ecoflex(), p));
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> stretch(0.7, 2.2), dt(0.0, 2.0);
  std::bernoulli_distribution unload(0.3);
  double d_prev = 0.0;
  int grew = 0, held = 0;
  for (int n = 0; n < 400; ++n) {
    const Mat3 F = unload(rng) ? Mat3::Identity() : uniaxial(stretch(rng));
    const PointResponse r = mp.advance(F, dt(rng));
    const double d = damage(mp);
    ASSERT_GE(d, d_prev) << "step " << n;
    ASSERT_LT(d, 1.0) << "step " << n;
    ASSERT_LE(1.0 - mp.committed_state()[0], p.d_fail) << "step " << n;  // capped at d_fail
    ASSERT_TRUE(r.P().allFinite()) << "step " << n;
    EXPECT_EQ(mp.fields().failed, d >= p.d_fail) << "step " << n;
    (d > d_prev ? grew : held)++;
    d_prev = d;
  }
  // The sequence must exercise both branches, or the test says nothing.
  EXPECT_GT(grew, 50);
  EXPECT_GT(held, 50);
  EXPECT_TRUE(mp.fields().failed) << "d = " << d_prev;
}

// Constant W0 above the threshold for a time T: dd/dt = (g/tau)(1 - d) has the exact solution
// 1 - d(T) = (1 - d0) exp(-g T/tau). N backward-Euler steps give (1 - d0) (1 + z)^{-N}, z = gT/(tau N),
// whose error is (1 - d_exact) (gT/tau)^2 / (2N) + O(N^-2) (expand -N ln(1 + z)).
TEST(Fatigue, ConstantDriverMatchesExactSolutionAtFirstOrder) {
  const Mat3 F = uniaxial(1.6);
  const double W0 = base_energy(F);
  const double g = std::pow(W0 / kRate.W_th_Pa - 1.0, kRate.q);
  ASSERT_GT(g, 0.5);
  const double T = 2.0 * kRate.tau_s / g;  // g T / tau = 2: d(T) = 1 - exp(-2) = 0.86
  const double s_exact = std::exp(-g * T / kRate.tau_s);
  std::vector<double> err;
  for (int N : {10, 20, 40, 80, 160, 320}) {
    MaterialPoint mp(make_fatigue(ecoflex(), kRate));
    for (int n = 0; n < N; ++n) mp.advance(F, T / N);
    const double s = 1.0 - damage(mp);
    // The update is exactly backward Euler: equal to the closed form up to rounding of N divisions.
    const double z = g * T / (kRate.tau_s * N);
    EXPECT_NEAR(s, std::pow(1.0 + z, -N), 1e-13 * N * s) << "N = " << N;
    // Backward-Euler error, leading term within 10 % once N is large (the next term is O(1/N^2)).
    const double leading = s_exact * std::pow(g * T / kRate.tau_s, 2) / (2.0 * N);
    err.push_back(s - s_exact);
    // The series of docs/verification.md's figure (docs/figures/verification_figures.py fatigue).
    std::printf("fatigue series n = 1: steps %d integrity %.17g exact %.17g leading %.17g\n", N, s, s_exact, leading);
    if (N >= 80) {
      EXPECT_NEAR(err.back(), leading, 0.1 * leading) << "N = " << N;
    }
  }
  for (std::size_t i = 1; i < err.size(); ++i) {
    const double order = std::log2(err[i - 1] / err[i]);
    if (i + 1 == err.size()) {
      EXPECT_GT(order, 0.9) << "observed order at the finest pair";
    }
    EXPECT_LT(order, 1.1) << "pair " << i;  // first order, not better: the scheme is BE, not exact
  }
}

// Saturating law, integrity exponent n = 3, constant driver: ds/dt = -(g/tau) s^n has the exact
// solution s(T) = (s0^(1-n) + (n-1) g T/tau)^(-1/(n-1)). Every increment must satisfy its backward-Euler
// equation s_new + a s_new^n = s_old to rounding, and N increments must converge to the exact solution
// at first order (the error halves when N doubles: observed order in [0.9, 1.1] once N >= 40).
TEST(Fatigue, SaturatingLawSolvesItsUpdateAndConvergesToTheExactSolution) {
  FatigueParams p = kRate;
  p.n = 3.0;
  const Mat3 F = uniaxial(1.6);
  const double g = std::pow(base_energy(F) / p.W_th_Pa - 1.0, p.q);
  const double T = 4.0 * p.tau_s / g;  // g T / tau = 4: s = 1/3 (n = 1 would give exp(-4) = 0.018)
  const double s_exact = std::pow(1.0 + (p.n - 1.0) * g * T / p.tau_s, -1.0 / (p.n - 1.0));
  std::vector<double> err;
  for (int N : {10, 20, 40, 80, 160, 320}) {
    MaterialPoint mp(make_fatigue(ecoflex(), p));
    const double a = g * (T / N) / p.tau_s;
    double s_prev = 1.0;
    for (int k = 0; k < N; ++k) {
      mp.advance(F, T / N);
      const double s = 1.0 - damage(mp);
      // Residual of the implicit update relative to s_old: a few ulps (Newton stops at 4 eps).
      ASSERT_NEAR(s + a * std::pow(s, p.n), s_prev, 1e-14) << "N = " << N << ", increment " << k;
      ASSERT_LT(s, s_prev);
      s_prev = s;
    }
    err.push_back(s_prev - s_exact);
    std::printf("fatigue series n = 3: steps %d integrity %.17g exact %.17g\n", N, s_prev, s_exact);
  }
  for (std::size_t i = 2; i < err.size(); ++i) {
    const double order = std::log2(err[i - 1] / err[i]);
    EXPECT_GT(order, 0.9) << "pair " << i;
    EXPECT_LT(order, 1.1) << "pair " << i;
  }
  EXPECT_LT(std::abs(err.back()), 0.01 * s_exact);  // N = 320 within 1 % of the exact integrity
}

// At the same damage and driver the saturating law grows (1 - d)^(n-1) times slower than n = 1: one
// short increment from the same committed damage d0 gives Delta d ratio -> (1 - d0)^(n-1) as dt -> 0.
TEST(Fatigue, SaturatingRateScalesWithIntegrityPower) {
  const Mat3 F = uniaxial(2.0);
  FatigueParams p1 = kRate, p3 = kRate;
  p3.n = 3.0;
  const double g = std::pow(base_energy(F) / kRate.W_th_Pa - 1.0, kRate.q);
  MaterialPoint m1(make_fatigue(ecoflex(), p1));
  m1.advance(F, kRate.tau_s / g);  // a = 1: d0 = 0.5 with n = 1
  const double s0 = 1.0 - damage(m1);
  ASSERT_NEAR(s0, 0.5, 1e-12);
  // The n = 3 point with the same committed integrity, reached in one increment of its own update.
  MaterialPoint m3(make_fatigue(ecoflex(), p3));
  // Backward Euler in one increment: s0 + a s0^3 = 1 -> a = (1 - s0) / s0^3, dt = a tau / g.
  m3.advance(F, (1.0 - s0) / std::pow(s0, 3.0) * kRate.tau_s / g);
  ASSERT_NEAR(1.0 - damage(m3), s0, 1e-12);
  const double dt = 1e-5;  // a = g dt / tau ~ 5e-5
  const double d1 = damage(m1), d3 = damage(m3);
  m1.advance(F, dt);
  m3.advance(F, dt);
  const double ratio = (damage(m3) - d3) / (damage(m1) - d1);
  // The two BE updates differ from the rate ratio by O(a) = 5e-5 relative (expand 1/(1 + a) and
  // the Newton root to first order); 1e-3 leaves room for rounding of the small differences.
  EXPECT_NEAR(ratio, s0 * s0, 1e-3 * s0 * s0);
}

TEST(Fatigue, BelowThresholdDamageIsExactlyConstant) {
  MaterialPoint mp(make_fatigue(ecoflex(), kParams));
  for (int n = 0; n < 5; ++n) mp.advance(uniaxial(2.0), 1.0);
  const double d0 = damage(mp);
  ASSERT_GT(d0, 0.05);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> stretch(0.8, 1.3), dt(0.0, 100.0);
  for (int n = 0; n < 200; ++n) {
    const Mat3 F = uniaxial(stretch(rng));
    ASSERT_LT(base_energy(F), kParams.W_th_Pa);
    mp.advance(F, dt(rng));
    ASSERT_EQ(damage(mp), d0) << "step " << n;  // bitwise: (1 - d) / (1 + 0)
  }
}

TEST(Fatigue, ZeroIncrementLeavesDamageUnchanged) {
  MaterialPoint mp(make_fatigue(ecoflex(), kParams));
  mp.advance(uniaxial(2.0), 1.0);
  const double d0 = damage(mp);
  mp.advance(uniaxial(2.5), 0.0);  // a static (pseudo-time) solve: no physical time elapses
  EXPECT_EQ(damage(mp), d0);
}

TEST(Fatigue, FailureFlagAndResidualStiffness) {
  MaterialPoint mp(make_fatigue(ecoflex(), kParams));
  int steps = 0;
  while (!mp.fields().failed && steps < 1000) {
    mp.advance(uniaxial(2.0), 0.05);  // a = 0.27 per step
    ++steps;
  }
  ASSERT_TRUE(mp.fields().failed);
  EXPECT_NEAR(damage(mp), kParams.d_fail, 1e-15);  // the increment that crosses it stops there
  EXPECT_GT(steps, 1);  // it took several increments, not one
  // A failed point keeps the residual stiffness 1 - d_fail however long it stays loaded: damage and
  // stress stop changing, and the stress is exactly that fraction of the base's isochoric stress.
  for (int n = 0; n < 10; ++n) {
    const PointResponse r = mp.advance(uniaxial(2.5), 10.0);
    EXPECT_EQ(mp.committed_state()[0], 1.0 - kParams.d_fail) << "step " << n;
    EXPECT_TRUE(mp.fields().failed);
    const PointResponse r0 = MaterialPoint(ecoflex()).advance(uniaxial(2.5), 10.0);
    EXPECT_NEAR((r.P_iso - (1.0 - kParams.d_fail) * r0.P_iso).norm(), 0.0, 1e-12 * r0.P_iso.norm());
  }
  // Absurd overload for very long increments (a ~ 1e30 per step): the integrity still stops at
  // 1 - d_fail, the stresses and tangents stay finite, the volumetric response is never degraded.
  MaterialPoint hard(make_fatigue(ecoflex(), {1.0, 1e-3, 4.0, 0.9}));
  for (int n = 0; n < 20; ++n) {
    const PointResponse r = hard.advance(1.05 * uniaxial(3.0), 1e6, true);  // J = 1.16
    ASSERT_TRUE(r.P().allFinite() && r.A().allFinite()) << "step " << n;
    ASSERT_EQ(hard.committed_state()[0], 1.0 - 0.9) << "step " << n;
    ASSERT_GT(r.P_vol.norm(), 0.0);
  }
  EXPECT_TRUE(hard.fields().failed);
}

// Stretch driver: one increment at a constant lambda gives 1 - d = 1/(1 + dt g/tau), g = (lambda/lambda_th - 1)^q.
TEST(Fatigue, MaxPrincipalStretchDriver) {
  FatigueParams p{0.0, 10.0, 2.5, 0.5, FatigueDriver::max_principal_stretch, 1.5};
  const MaterialPtr m = make_fatigue(ecoflex(), p);
  MaterialPoint below(m), above(m);
  below.advance(uniaxial(1.45), 5.0);
  EXPECT_EQ(damage(below), 0.0);
  // Rotated, so the largest stretch is not along a coordinate axis.
  const Mat3 R = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  above.advance(R * uniaxial(1.8), 5.0);
  const double g = std::pow(1.8 / 1.5 - 1.0, 2.5);
  EXPECT_NEAR(1.0 - damage(above), 1.0 / (1.0 + 5.0 * g / 10.0), 1e-14);
}

// Where a cheap bound puts lambda_max(C) below lambda_th^2 (with a relative margin of 1e-6), the stretch
// driver skips the eigenvalue problem: g = 0 there whatever the exact value. At the threshold, for a
// uniaxial stretch (where the bound is tight) and a triaxial one, on either side of the margin, the trial
// integrity must still be that of the exact largest eigenvalue, bit for bit: 1 / (1 + dt g / tau) with X
// from Eigen's solver (eigenvectors or not) - in the force-only and tangent evaluations and in stress().
TEST(Fatigue, StretchDriverIsExactAtTheThreshold) {
  const FatigueParams p{0.0, 10.0, 1.0, 0.5, FatigueDriver::max_principal_stretch, 1.5};  // q = 1: g = x
  const MaterialPtr m = make_fatigue(ecoflex(), p);
  const double dt = 5.0, s_old = 1.0;
  const Mat3 R = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  int grew = 0;
  for (double rel : {-1e-3, -1e-6, -5e-7, -2e-7, -1e-9, 0.0, 1e-9, 2e-7, 5e-7, 1e-6, 1e-3}) {
    const double lambda = p.lambda_th * (1.0 + rel);
    for (const Mat3& F : {Mat3(R * uniaxial(lambda)), Mat3(R * Vec3(lambda, 1.1, 0.8).asDiagonal())}) {
      SCOPED_TRACE("lambda = lambda_th (1 + " + std::to_string(rel) + "), F =\n" + ::testing::PrintToString(F));
      const Eigen::SelfAdjointEigenSolver<Mat3> eig(F.transpose() * F);
      const double g = fatigue_rate(std::sqrt(eig.eigenvalues()(2)), p).g;
      const double expected = s_old / (1.0 + dt / p.tau_s * g);
      grew += expected < s_old;
      for (const bool tangent : {false, true}) {
        std::vector<double> trial(1);
        PointResponse r;
        m->evaluate(std::span<const Mat3>(&F, 1), TimeStep{dt, dt}, std::span<const double>(&s_old, 1), trial,
                    std::span<PointResponse>(&r, 1), tangent);
        EXPECT_EQ(trial[0], expected) << (tangent ? "tangent" : "force only");
      }
      StressBatch b;
      b.n = 1;
      b.set_F(0, F);
      b.pad();
      std::vector<double> trial(1);
      m->stress(b, TimeStep{dt, dt}, std::span<const double>(&s_old, 1), trial);
      EXPECT_EQ(trial[0], expected) << "stress()";
    }
  }
  EXPECT_GE(grew, 8);  // above the threshold, including just above it (x ~ 2e-7: s = 1 - 1e-7)
}

TEST(Fatigue, RejectsBadParameters) {
  const auto expect_error = [](const FatigueParams& p, const std::string& text) {
    try {
      make_fatigue(ecoflex(), p);
      ADD_FAILURE() << "no InputError; expected one containing '" << text << "'";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
    }
  };
  expect_error({0.0, 10.0, 2.0, 0.5}, "fatigue: W_th must be > 0 Pa");
  expect_error({5e3, 0.0, 2.0, 0.5}, "fatigue: tau must be > 0 s");
  expect_error({5e3, 10.0, 0.5, 0.5}, "fatigue: q must be >= 1");
  expect_error({5e3, 10.0, 2.0, 1.0}, "fatigue: d_fail must lie in (0, 1)");
  expect_error({5e3, 10.0, 2.0, 0.0}, "fatigue: d_fail must lie in (0, 1)");
  expect_error({5e3, 10.0, 2.0, 0.5, FatigueDriver::energy, 0.0, 0.5}, "fatigue: n must lie in [1, 20]");
  expect_error({5e3, INFINITY, 2.0, 0.5}, "fatigue: tau must be a finite number");
  expect_error({0.0, 10.0, 2.0, 0.5, FatigueDriver::max_principal_stretch, 1.0}, "fatigue: lambda_th must be > 1");
  try {
    make_fatigue(make_viscoelastic(ecoflex(), {{0.5}, {1.0}}), kParams);
    ADD_FAILURE() << "fatigue(viscoelastic(...)) must be rejected";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("viscoelastic(fatigue(mullins(base)))"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace pneufem
