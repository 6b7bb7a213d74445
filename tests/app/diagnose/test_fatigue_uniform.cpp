// The uniform fatigue law (damage/fatigue_uniform.h), the third form of the diagnose catalog's fatigue
// family (issue 35): its material point, its registration and its place in the catalog. The diagnosis
// with it is tested in test_othermeans_recordings.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "app/diagnose/effect_catalog.h"
#include "core/errors.h"
#include "damage/fatigue_uniform.h"
#include "damage/material_point.h"
#include "damage/registry.h"
#include "materials/hyperelastic.h"
#include "scenes/scene.h"

namespace pneufem {
namespace {

constexpr double C10 = 0.019e6, C20 = 9.0e2, C30 = -4.75;  // Ecoflex 00-50, Pa (as tests/damage)
constexpr double K = 100.0 * 2.0 * C10;
MaterialPtr ecoflex() { return std::make_shared<InvariantMaterial<Yeoh>>(Yeoh(C10, C20, C30, K)); }

/// Isochoric uniaxial stretch.
Mat3 uniaxial(double lambda) { return Vec3(lambda, 1.0 / std::sqrt(lambda), 1.0 / std::sqrt(lambda)).asDiagonal(); }

PointResponse base_at(const Mat3& F) {
  PointResponse r;
  ecoflex()->evaluate(std::span<const Mat3>(&F, 1), TimeStep{}, {}, {}, std::span<PointResponse>(&r, 1), false);
  return r;
}

const UniformFatigueParams kP{0.05, 2.0};

/// The isochoric stiffness fraction P_iso / P0_iso of a point after `history` (pairs stretch, dt).
double fraction_after(const std::vector<std::pair<double, double>>& history, double scale) {
  MaterialPoint mp(std::make_shared<const UniformFatigue>(ecoflex(), kP));
  PointResponse r;
  Mat3 F = Mat3::Identity();
  for (const auto& [lambda, dt] : history) {
    F = uniaxial(1.0 + scale * (lambda - 1.0));
    r = mp.advance(F, dt);
  }
  return r.P_iso(0, 0) / base_at(F).P_iso(0, 0);
}

// Two points loaded proportionally (one to twice the other's strain, the same time history) soften
// by the same fraction: the count is weighted by each point's load relative to its own peak. A
// threshold law (damage/fatigue.h) would damage the more strained point only, or far more.
TEST(UniformFatigue, PointsLoadedProportionallySoftenAlike) {
  std::vector<std::pair<double, double>> h;
  for (int cycle = 0; cycle < 5; ++cycle)
    for (double lambda : {1.0, 1.1, 1.2, 1.3, 1.2, 1.1})
      h.emplace_back(lambda, 0.5);
  const double a = fraction_after(h, 1.0), b = fraction_after(h, 0.5);
  std::printf("stiffness fraction after the history: %.6f at the full strain, %.6f at half of it\n", a, b);
  EXPECT_LT(a, 0.97);  // a visible softening (~6 s of counted load, D ~ 0.07; measured 0.9344)
  // Not exactly equal: W0 of a Yeoh solid is not the same function of time at two strain amplitudes
  // (its C20, C30 terms), so W0/W_max differs slightly below the peak; 1 % of the softening's size
  // (measured: 0.9344 and 0.9347, 0.5 % of it).
  EXPECT_NEAR(a, b, 0.01 * (1.0 - a));
}

// Held at its peak the count is the time under load; held at a fraction of the peak energy it counts
// that fraction; D = a ln(1 + N/t0) and the stress is P0 / (1 + D) (backward Euler is exact here:
// r is constant over each increment).
TEST(UniformFatigue, CountsTheTimeWeightedByTheLoadRelativeToThePeak) {
  MaterialPoint mp(std::make_shared<const UniformFatigue>(ecoflex(), kP));
  const Mat3 peak = uniaxial(1.4);
  mp.advance(peak, 3.0);  // on the primary curve: r = 1
  EXPECT_NEAR(mp.committed_state()[0], 3.0, 1e-12);
  EXPECT_NEAR(mp.committed_state()[1], base_at(peak).psi_iso, 1e-9 * base_at(peak).psi_iso);
  const Mat3 half = uniaxial(1.2);
  const double r = base_at(half).psi_iso / base_at(peak).psi_iso;
  const PointResponse p = mp.advance(half, 4.0);
  EXPECT_NEAR(mp.committed_state()[0], 3.0 + 4.0 * r, 1e-12);
  const double D = kP.a * std::log1p((3.0 + 4.0 * r) / kP.t0_s);
  EXPECT_NEAR(p.P_iso(0, 0), base_at(half).P_iso(0, 0) / (1.0 + D), 1e-12 * std::abs(base_at(half).P_iso(0, 0)));
  EXPECT_NEAR(mp.fields().damage, D / (1.0 + D), 1e-12);
  // Unloaded: nothing counts, the softening stays (a compliance growth at zero load moves nothing).
  mp.advance(Mat3::Identity(), 100.0);
  EXPECT_NEAR(mp.committed_state()[0], 3.0 + 4.0 * r, 1e-12);
}

// A virgin point at rest does not count (below the floor, W0 / W_max would be 1 at any rounding).
TEST(UniformFatigue, AVirginPointAtRestDoesNotCount) {
  MaterialPoint mp(std::make_shared<const UniformFatigue>(ecoflex(), kP));
  mp.advance(Mat3::Identity(), 1000.0);
  mp.advance(uniaxial(1.0 + 1e-5), 1000.0);  // W0 ~ 1e-10 mu: below the 1e-6 mu floor
  EXPECT_EQ(mp.committed_state()[0], 0.0);
}

// The consistent tangent, by central differences of the first Piola stress (below the peak, where
// the count depends on F within the increment).
TEST(UniformFatigue, TangentMatchesFiniteDifferences) {
  MaterialPoint mp(std::make_shared<const UniformFatigue>(ecoflex(), kP));
  mp.advance(uniaxial(1.5), 2.0);
  Mat3 F;
  F << 1.2, 0.1, 0.0, -0.05, 0.9, 0.08, 0.02, 0.0, 0.95;
  const double dt = 1.5;
  const Mat9 A = mp.trial(F, dt, true).A();
  ASSERT_GT(mp.trial_state()[0], 2.0);  // counting, below the peak
  const double h = 1e-6;
  double err = 0.0, ref = 0.0;
  for (int k = 0; k < 9; ++k) {
    Mat3 Fp = F, Fm = F;
    Fp(k % 3, k / 3) += h;
    Fm(k % 3, k / 3) -= h;
    const Mat3 dP = (mp.trial(Fp, dt, false).P() - mp.trial(Fm, dt, false).P()) / (2.0 * h);
    for (int m = 0; m < 9; ++m) {
      err = std::max(err, std::abs(dP(m % 3, m / 3) - A(m, k)));
      ref = std::max(ref, std::abs(A(m, k)));
    }
  }
  // Central differences at h = 1e-6 of a stress of ~1e5 Pa: truncation ~h^2, rounding ~1e-16/h of
  // the stress, both far below 1e-6 of the tangent's size.
  EXPECT_LT(err, 1e-6 * ref) << "A(m, k) is dP_m/dF_k in the flatten() order";
}

// Registered (a scene reads it as any registered effect) and in the catalog as a form of fatigue.
TEST(UniformFatigue, IsRegisteredAndAFormOfTheFatigueFamily) {
  const MaterialEffect* fx = find_material_effect("fatigue_uniform");
  ASSERT_NE(fx, nullptr);
  EXPECT_FALSE(is_builtin_effect("fatigue_uniform"));
  EXPECT_TRUE(fx->history);
  const CandidateEffect& c = candidate_effect("fatigue_uniform");
  EXPECT_EQ(c.family, "fatigue");
  EXPECT_TRUE(c.history);
  ASSERT_EQ(c.params.size(), 2u);
  EXPECT_EQ(c.params[0].lo, fx->param("a").lo);
  EXPECT_EQ(c.params[1].hi, fx->param("t0_s").hi);
  int n = 0;
  for (const CandidateEffect& e : candidate_effects()) n += e.name == "fatigue_uniform";
  EXPECT_EQ(n, 1);  // described by the catalog, not added a second time as a registered effect
  const std::vector<std::string> sets = c.sets(Scene::load("", {"geometry.chambers=3", "mesh.h_mm=6.0"}), {0.04, 5.0});
  EXPECT_NE(std::find(sets.begin(), sets.end(), "materials.silicone.fatigue_uniform.enabled=true"), sets.end());
  EXPECT_THROW(std::make_shared<const UniformFatigue>(ecoflex(), UniformFatigueParams{0.0, 1.0}), InputError);
}

}  // namespace
}  // namespace pneufem
