// Viscoelastic (Prony series) decorator at a material point: ramp-and-hold relaxation against the
// standard linear solid, exact Prony decay after a finite step strain, creep convergence, Abaqus g_i.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "core/errors.h"
#include "damage/effects.h"
#include "damage/material_point.h"
#include "materials/hyperelastic.h"
#include "materials/scaled.h"

namespace pneufem {
namespace {

constexpr double C10 = 0.019e6, C20 = 9.0e2, C30 = -4.75;  // Ecoflex 00-50, Pa
constexpr double K = 100.0 * 2.0 * C10;
constexpr double mu_inf = 2.0 * C10;

MaterialPtr ecoflex() { return std::make_shared<InvariantMaterial<Yeoh>>(Yeoh(C10, C20, C30, K)); }

Mat3 simple_shear(double gamma_s) {
  Mat3 F = Mat3::Identity();
  F(0, 1) = gamma_s;
  return F;
}

PointResponse base_response(const Mat3& F) {
  PointResponse r;
  ecoflex()->evaluate(std::span<const Mat3>(&F, 1), TimeStep{}, {}, {}, std::span<PointResponse>(&r, 1), false);
  return r;
}

// Small-strain simple shear, ramp gamma_s = rate t up to t_r, then held. Standard linear solid with
// branches (gamma_i mu_inf, tau_i): tau_12 = mu_inf (gamma_s + sum gamma_i q_i), dq_i/dt + q_i/tau_i = dgamma_s/dt:
//   ramp: q_i = rate tau_i (1 - exp(-t/tau_i)),   hold: q_i = q_i(t_r) exp(-(t - t_r)/tau_i).
// The update is exact for S0 linear in time, so even coarse steps (dt = tau_1 / 2) must reproduce it.
// Tolerance: the material is finite-strain Yeoh; at gamma_max = 1e-4 its departures from the linear
// solid are O(gamma^2) = 1e-8 relative (C20/C10 gamma^2 in W1, gamma Q_22 and the F^{-1} in S0), so
// 1e-6 of mu_inf gamma_max is 100x above them, while a midpoint-rule update (exp(-x/2) instead of k)
// is off by ~1 % here.
TEST(Viscoelastic, SmallStrainRampAndHoldMatchesStandardLinearSolid) {
  const std::vector<double> g{0.8, 0.4}, tau{0.5, 5.0};
  MaterialPoint mp(make_viscoelastic(ecoflex(), {g, tau}));
  const double gamma_max = 1e-4, t_r = 2.0, rate = gamma_max / t_r, dt = 0.25;
  const auto expected = [&](double t) {
    const double gs = rate * std::min(t, t_r);
    double tau12 = gs;
    for (std::size_t i = 0; i < g.size(); ++i) {
      double q = rate * tau[i] * (1.0 - std::exp(-std::min(t, t_r) / tau[i]));
      if (t > t_r) q *= std::exp(-(t - t_r) / tau[i]);
      tau12 += g[i] * q;
    }
    return mu_inf * tau12;
  };
  double max_overstress = 0.0;
  for (int n = 1; n * dt <= 40.0 + 1e-12; ++n) {
    const double t = n * dt;
    const PointResponse r = mp.advance(simple_shear(rate * std::min(t, t_r)), dt);
    EXPECT_NEAR(r.P()(0, 1), expected(t), 1e-6 * mu_inf * gamma_max) << "t = " << t;
    max_overstress = std::max(max_overstress, r.P()(0, 1) - mu_inf * rate * std::min(t, t_r));
  }
  EXPECT_GT(max_overstress, 0.3 * mu_inf * gamma_max);  // the branches carried a real share of the load
  // Relaxed after 40 s = 8 tau_2: only the long-term response remains (exp(-7.6) = 5e-4 of the overstress).
  EXPECT_NEAR(mp.fields().viscous_strain, 0.0, 1e-3 * gamma_max);
}

// After a step strain applied instantaneously (dt = 0) and held, S0 is constant, so
// Q_i = gamma_i S0 exp(-t/tau_i) exactly and P_iso = P0_iso (1 + sum gamma_i exp(-t/tau_i)) at FINITE strain,
// with any step sizes: only the rounding of a few operations (1e-12 relative is ~5000 eps).
TEST(Viscoelastic, FiniteStepStrainRelaxesWithPronyExponentials) {
  const std::vector<double> g{0.5, 0.25, 0.1}, tau{0.2, 2.0, 20.0};
  MaterialPoint mp(make_viscoelastic(ecoflex(), {g, tau}));
  const Mat3 F = 1.02 * Mat3(Vec3(2.0, 1.0 / std::sqrt(2.0), 1.0 / std::sqrt(2.0)).asDiagonal());  // J = 1.06
  const PointResponse r0 = base_response(F);
  const double scale = r0.P_iso.norm();
  double t = 0.0;
  for (double dt : {0.0, 0.01, 0.1, 0.37, 1.0, 2.5, 10.0, 50.0, 100.0, 500.0}) {
    t += dt;
    const PointResponse r = mp.advance(F, dt);
    double factor = 1.0;
    for (std::size_t i = 0; i < g.size(); ++i) factor += g[i] * std::exp(-t / tau[i]);
    EXPECT_LE((r.P_iso - factor * r0.P_iso).norm(), 1e-12 * scale) << "t = " << t;
    EXPECT_EQ(r.P_vol, r0.P_vol) << "the volumetric part must pass through unchanged";
    EXPECT_EQ(r.psi_vol, r0.psi_vol);
  }
  EXPECT_LE(mp.fields().viscous_strain, 1e-12);  // t = 664 s = 33 tau_3: exp(-33) = 5e-15
}

// Creep under a constant small shear stress tau0, one branch: the standard linear solid gives
//   gamma_s(t) = tau0/mu_inf [1 - gamma/(1 + gamma) exp(-t/tau_r)],  tau_r = tau (1 + gamma).
// With the stress prescribed, S0 is no longer linear in time within a step; the update interpolates it
// linearly, which is second order in dt. Observed order at the finest pair must exceed 1.8.
TEST(Viscoelastic, SmallStrainCreepConvergesAtSecondOrder) {
  const double gam = 1.0, tau = 1.0, tau_r = tau * (1.0 + gam), tau0 = 1e-5 * mu_inf, T = 3.0 * tau_r;
  const auto creep = [&](int N) {
    MaterialPoint mp(make_viscoelastic(ecoflex(), {{gam}, {tau}}));
    double gs = 0.0;
    for (int n = 0; n <= N; ++n) {
      const double dt = n == 0 ? 0.0 : T / N;  // n = 0: the load is applied instantaneously
      for (int it = 0; it < 30; ++it) {
        const PointResponse r = mp.trial(simple_shear(gs), dt);
        const double dgs = (tau0 - r.P()(0, 1)) / r.A()(flat(0, 1), flat(0, 1));
        gs += dgs;
        if (std::abs(dgs) <= 1e-15 * std::abs(gs)) break;
      }
      mp.advance(simple_shear(gs), dt);
    }
    return gs;
  };
  const double exact = tau0 / mu_inf * (1.0 - gam / (1.0 + gam) * std::exp(-T / tau_r));
  std::vector<double> err;
  for (int N : {10, 20, 40, 80}) err.push_back(std::abs(creep(N) - exact));
  for (std::size_t i = 1; i < err.size(); ++i)
    EXPECT_GT(std::log2(err[i - 1] / err[i]), i + 1 == err.size() ? 1.8 : 1.5) << "pair " << i;
  EXPECT_LT(err.back(), 1e-4 * exact);
}

// Abaqus's g_i with its default MODULI=INSTANTANEOUS: the base (mu = 2 C10) is the instantaneous
// modulus G_0 and G_inf = (1 - sum g) G_0. With MODULI=LONG TERM the base is G_inf and G_0 = G_inf / (1 - sum g).
// (initial_shear_modulus is the instantaneous one, which stable-step estimates need.)
TEST(Viscoelastic, AbaqusPronyConversionAndInstantaneousModulus) {
  const ViscoParams p = prony_from_abaqus({0.3, 0.2}, {1.0, 10.0});
  // gamma_i = g_i / (1 - sum g) = g_i / 0.5
  ASSERT_EQ(p.gamma.size(), 2u);
  EXPECT_DOUBLE_EQ(p.gamma[0], 0.6);
  EXPECT_DOUBLE_EQ(p.gamma[1], 0.4);
  EXPECT_EQ(p.moduli, ViscoModuli::instantaneous);
  const MaterialPtr m = make_viscoelastic(ecoflex(), p);
  const auto& v = dynamic_cast<const Viscoelastic&>(*m);
  EXPECT_DOUBLE_EQ(m->initial_shear_modulus(), mu_inf);       // G_0: the base
  EXPECT_DOUBLE_EQ(v.long_term_shear_modulus(), 0.5 * mu_inf);  // (1 - sum g) G_0
  EXPECT_DOUBLE_EQ(m->initial_bulk_modulus(), K);
  EXPECT_EQ(m->name(), "viscoelastic(yeoh)");
  EXPECT_EQ(m->state_size(), 6 * 3);
  const MaterialPtr lt = make_viscoelastic(ecoflex(), prony_from_abaqus({0.3, 0.2}, {1.0, 10.0}, ViscoModuli::long_term));
  EXPECT_DOUBLE_EQ(lt->initial_shear_modulus(), 2.0 * mu_inf);  // G_0 = G_inf / (1 - sum g)
  EXPECT_DOUBLE_EQ(dynamic_cast<const Viscoelastic&>(*lt).long_term_shear_modulus(), mu_inf);
  EXPECT_STREQ(to_string(ViscoModuli::instantaneous), "instantaneous");
  EXPECT_STREQ(to_string(ViscoModuli::long_term), "long_term");
}

// Step strain in both moduli conventions, uniaxial at finite strain (lambda = 1.5, J = 1.03). From
// damage/viscoelastic.h, with S0 constant after the step the branches decay exactly,
// Q_i = a_i S0 exp(-t/tau_i), so P_iso(t) = (beta + sum a_i exp(-t/tau_i)) P0_iso, i.e. with
// g_i = gamma_i / (1 + sum gamma) (Abaqus's relative moduli; sum gamma = 0.75 here, so sum g = 3/7):
//   instantaneous: P_iso(t) / P0_iso = 1 - sum g_i (1 - exp(-t/tau_i)):  1 at t = 0+, 1 - sum g = 4/7 at t -> inf;
//   long_term:     P_iso(t) / P0_iso = 1 + sum gamma_i exp(-t/tau_i):    1 + sum gamma = 1/(1 - sum g) = 7/4 at
//                  t = 0+, 1 at t -> inf.
// At every time the long-term material is 1 + sum gamma times the instantaneous one (same Prony terms,
// base constants read as G_inf instead of G_0). The volumetric part is the base's in both (k_i = 0).
// Tolerance: only the rounding of a few operations on O(|P0|) numbers (1e-12 relative, ~5000 eps);
// the instantaneous ratio at t = 0+ is 1 exactly by construction (b = 1 - sum a_i (1 - k_i), k_i = 1).
TEST(Viscoelastic, StepStrainRelaxesFromAndToTheRightModulusInBothConventions) {
  const std::vector<double> gam{0.5, 0.25}, tau{0.3, 3.0};
  const double sum_gamma = 0.75, sum_g = sum_gamma / (1.0 + sum_gamma);
  const Mat3 F = std::cbrt(1.03) * Mat3(Vec3(1.5, 1.0 / std::sqrt(1.5), 1.0 / std::sqrt(1.5)).asDiagonal());
  const PointResponse r0 = base_response(F);
  const double scale = r0.P_iso.norm();
  MaterialPoint inst(make_viscoelastic(ecoflex(), {gam, tau, ViscoModuli::instantaneous}));
  MaterialPoint lt(make_viscoelastic(ecoflex(), {gam, tau, ViscoModuli::long_term}));
  double t = 0.0;
  for (double dt : {0.0, 0.05, 0.25, 1.0, 4.0, 20.0, 100.0}) {
    t += dt;
    const PointResponse ri = inst.advance(F, dt), rl = lt.advance(F, dt);
    double relax_inst = 1.0, relax_lt = 1.0;
    for (std::size_t i = 0; i < gam.size(); ++i) {
      const double gi = gam[i] / (1.0 + sum_gamma);
      relax_inst -= gi * (1.0 - std::exp(-t / tau[i]));
      relax_lt += gam[i] * std::exp(-t / tau[i]);
    }
    EXPECT_LE((ri.P_iso - relax_inst * r0.P_iso).norm(), 1e-12 * scale) << "t = " << t;
    EXPECT_LE((rl.P_iso - relax_lt * r0.P_iso).norm(), 1e-12 * scale) << "t = " << t;
    EXPECT_LE((rl.P_iso - (1.0 + sum_gamma) * ri.P_iso).norm(), 1e-12 * scale) << "t = " << t;
    EXPECT_EQ(ri.P_vol, r0.P_vol);
    EXPECT_EQ(rl.P_vol, r0.P_vol);
    if (t == 0.0) {
      EXPECT_EQ(ri.P_iso, r0.P_iso);  // the given constants are the instantaneous response, exactly
    }
  }
  // t = 125 s = 42 tau_2: exp(-42) ~ 6e-19, fully relaxed.
  const PointResponse ri = inst.advance(F, 0.0), rl = lt.advance(F, 0.0);
  EXPECT_LE((ri.P_iso - (1.0 - sum_g) * r0.P_iso).norm(), 1e-12 * scale);
  EXPECT_LE((rl.P_iso - r0.P_iso).norm(), 1e-12 * scale);
  EXPECT_LE(inst.fields().viscous_strain, 1e-12);  // relaxed: exp(-42) ~ 6e-19 of a strain ~0.5
}

// The instantaneous convention is the long-term one on the base scaled by beta = 1 - sum g: the same
// physical material, whatever the history. Ramp, hold, unload and reload with uneven steps; stress,
// tangent and viscous strain agree to rounding (1e-12 of the stress and tangent scales: a few hundred
// operations on O(1) factors), but not bit for bit (b is evaluated in another order).
TEST(Viscoelastic, InstantaneousIsLongTermOnTheScaledBaseForAnyHistory) {
  const std::vector<double> gam{0.8, 0.1, 0.3}, tau{0.2, 2.0, 15.0};
  const double beta = 1.0 / (1.0 + 0.8 + 0.1 + 0.3);
  MaterialPoint inst(make_viscoelastic(ecoflex(), {gam, tau, ViscoModuli::instantaneous}));
  MaterialPoint lt(make_viscoelastic(scale_material(ecoflex(), beta), {gam, tau, ViscoModuli::long_term}));
  EXPECT_NEAR(inst.material().initial_shear_modulus(), lt.material().initial_shear_modulus(), 1e-12 * mu_inf);
  const double dts[] = {0.0, 0.1, 0.1, 0.4, 1.3, 0.05, 2.0, 7.0, 0.3, 0.3};
  for (int n = 0; n < 10; ++n) {
    const double lambda = 1.0 + 0.6 * std::sin(0.5 * n);  // 1 -> 1.6 -> 0.93 -> ...
    const Mat3 F = Eigen::AngleAxisd(0.2 * n, Vec3(1.0, 2.0, 0.5).normalized()).toRotationMatrix() *
                   Mat3(Vec3(lambda, 1.0 / std::sqrt(lambda), 1.0 / std::sqrt(lambda)).asDiagonal()) * simple_shear(0.1 * n);
    const PointResponse ri = inst.advance(F, dts[n], true), rl = lt.advance(F, dts[n], true);
    const double P_scale = std::max(ri.P_iso.norm(), 1e-3 * mu_inf), A_scale = ri.A_iso.norm();
    EXPECT_LE((ri.P_iso - rl.P_iso).norm(), 1e-12 * P_scale) << "step " << n;
    EXPECT_LE((ri.A_iso - rl.A_iso).norm(), 1e-12 * A_scale) << "step " << n;
    EXPECT_NEAR(ri.psi_iso, rl.psi_iso, 1e-12 * std::abs(rl.psi_iso) + 1e-12 * mu_inf) << "step " << n;
    EXPECT_NEAR(inst.fields().viscous_strain, lt.fields().viscous_strain, 1e-12 * (1.0 + lt.fields().viscous_strain));
  }
}

TEST(Viscoelastic, RejectsBadParameters) {
  const auto expect_error = [](const std::function<void()>& f, const std::string& text) {
    try {
      f();
      ADD_FAILURE() << "no InputError; expected one containing '" << text << "'";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
    }
  };
  expect_error([] { make_viscoelastic(ecoflex(), {{}, {}}); }, "viscoelastic: gamma and tau need the same number");
  expect_error([] { make_viscoelastic(ecoflex(), {{0.1, 0.1, 0.1, 0.1}, {1, 2, 3, 4}}); },
               "1 to 3; got 4 gamma and 4 tau");
  expect_error([] { make_viscoelastic(ecoflex(), {{0.1, 0.2}, {1.0}}); }, "got 2 gamma and 1 tau");
  expect_error([] { make_viscoelastic(ecoflex(), {{0.1, -0.2}, {1.0, 2.0}}); }, "viscoelastic: gamma_2 must be >= 0");
  expect_error([] { make_viscoelastic(ecoflex(), {{0.1}, {0.0}}); }, "viscoelastic: tau_1 must be > 0 s");
  expect_error([] { prony_from_abaqus({0.6, 0.4}, {1.0, 2.0}); }, "viscoelastic: the Abaqus g_i must sum to < 1");
  expect_error([] { prony_from_abaqus({-0.1}, {1.0}); }, "viscoelastic: g_1 must be >= 0");
  expect_error([] { make_viscoelastic(std::make_shared<SaintVenantKirchhoff>(6.5e9, 0.2), {{0.5}, {1.0}}); },
               "only applies to split (isochoric/volumetric) laws such as yeoh");
}

}  // namespace
}  // namespace pneufem
