// Stiffness scales (materials.<m>.stiffness_scale, regions.<tag>.stiffness_scale, materials/scaled.h)
// and the chamber pressure lag (load.pressure_lag_s, scenes/pressure_lag.h).
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>

#include <gtest/gtest.h>

#include "core/errors.h"
#include "engine/quasi_static.h"
#include "materials/hyperelastic.h"
#include "materials/scaled.h"
#include "scenes/build_model.h"
#include "scenes/pressure_lag.h"
#include "tests/support/input_error.h"

namespace pneufem {
namespace {

// 3 chambers at h = 6 mm: a few hundred Tet10, each equilibrium takes milliseconds.
const std::vector<std::string> kTiny = {"geometry.chambers=3", "mesh.h_mm=6.0", "output.vtu=none"};

std::vector<std::string> tiny(std::vector<std::string> more) {
  std::vector<std::string> s = kTiny;
  s.insert(s.end(), more.begin(), more.end());
  return s;
}

using pneufem::test::error_of;

/// Angles at every report of the scene's load.
std::vector<double> angles(const Scene& s) {
  auto bm = build_model(s);
  Assembler A(bm->model);
  QuasiStaticRun run(A, bm->solver.quasi_static);
  std::vector<double> out;
  run.run(bm->load, [&](const StateRecord& r, const Eigen::VectorXd&, const std::vector<double>&) { out.push_back(r.angle_deg); });
  return out;
}

// ---- ScaledMaterial ----

TEST(ScaledMaterial, EnergyStressAndTangentAreExactlyScaled) {
  const double C10 = 0.019e6, s = 1.7;
  const std::vector<MaterialPtr> bases = {
      std::make_shared<InvariantMaterial<Yeoh>>(Yeoh(C10, 900.0, -4.75, 100 * 2 * C10)),
      std::make_shared<SaintVenantKirchhoff>(6.5e9, 0.2)};
  Mat3 F;
  F << 1.2, 0.1, -0.05, 0.02, 0.9, 0.1, 0.0, -0.1, 1.05;
  for (const MaterialPtr& base : bases) {
    const ScaledMaterial m(base, s);
    PointResponse r0, r;
    base->evaluate(std::span<const Mat3>(&F, 1), {}, {}, {}, std::span<PointResponse>(&r0, 1), true);
    m.evaluate(std::span<const Mat3>(&F, 1), {}, {}, {}, std::span<PointResponse>(&r, 1), true);
    // One multiplication per entry: exact (the same operation as s * x).
    EXPECT_EQ(r.psi_iso, s * r0.psi_iso);
    EXPECT_EQ(r.psi_vol, s * r0.psi_vol);
    EXPECT_EQ(r.P_iso, (s * r0.P_iso).eval());
    EXPECT_EQ(r.P_vol, (s * r0.P_vol).eval());
    EXPECT_EQ(r.A_iso, (s * r0.A_iso).eval());
    EXPECT_EQ(r.A_vol, (s * r0.A_vol).eval());
    EXPECT_EQ(m.initial_shear_modulus(), s * base->initial_shear_modulus());
    EXPECT_EQ(m.initial_bulk_modulus(), s * base->initial_bulk_modulus());
    EXPECT_EQ(m.is_split(), base->is_split());
  }
  EXPECT_EQ(scale_material(bases[0], 1.0), bases[0]);  // scale 1: the law itself, bit for bit
}

TEST(ScaledMaterial, RejectsNonPositiveScale) {
  const MaterialPtr base = std::make_shared<SaintVenantKirchhoff>(1e6, 0.3);
  for (double s : {0.0, -1.0, std::nan(""), std::numeric_limits<double>::infinity()})
    EXPECT_NE(error_of([&] { ScaledMaterial(base, s); }).find("stiffness_scale must be a finite number > 0"), std::string::npos) << s;
}

// ---- Scales in scenes ----

// Homogeneous hyperelastic body: the residual s f_int(u) - s p g(u) vanishes where f_int(u) - p g(u)
// does, so every material scaled by s at pressure s p has the unscaled equilibrium at p. The two
// runs follow the same path (same Newton increments in p/s) and stop at |R| <= 1e-8 |f|; the angle
// error that leaves is <= rel_tol times the tangent's condition (<~1e4 with the 6.5 GPa fabric),
// so 1e-4 relative is a safe bound; observed 5e-10.
TEST(StiffnessScale, GlobalScaleEqualsPressureOverScale) {
  const double s = 2.5;
  const std::vector<double> a = angles(Scene::load("", tiny({"load.max_kPa=6", "load.step_kPa=3", "load.hold_s=1",
                                                             "load.ramp_s=0.5", "load.mark_s=0.5"})));
  const std::vector<double> b = angles(Scene::load(
      "", tiny({"load.max_kPa=15", "load.step_kPa=7.5", "load.hold_s=1", "load.ramp_s=0.5", "load.mark_s=0.5",
                "materials.silicone.stiffness_scale=2.5", "materials.fabric.stiffness_scale=2.5"})));
  ASSERT_EQ(a.size(), b.size());
  ASSERT_GT(a.back(), 0.1);  // a real bend (0.29 deg for this short actuator at 6 kPa)
  double worst = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_NEAR(b[i], a[i], 1e-4 * std::abs(a.back())) << "report " << i;
    worst = std::max(worst, std::abs(b[i] - a[i]) / std::abs(a.back()));
  }
  std::printf("global scale %.2f: max relative angle difference %.3g\n", s, worst);
}

TEST(StiffnessScale, RegionScaleOfOneChangesNothingBitForBit) {
  const std::vector<std::string> load = {"load.max_kPa=5", "load.step_kPa=5", "load.hold_s=1", "load.ramp_s=0.5",
                                         "load.mark_s=0.5"};
  std::vector<std::string> ones = load;
  for (const char* tag : {"interior_wall", "roof", "side_wall", "end_cap", "base", "fabric"})
    ones.push_back(std::string("regions.") + tag + ".stiffness_scale=1.0");
  const Scene a = Scene::load("", tiny(load)), b = Scene::load("", tiny(ones));
  EXPECT_EQ(build_model(b)->model.parts.size(), build_model(a)->model.parts.size());
  EXPECT_EQ(angles(b), angles(a));
}

TEST(StiffnessScale, RegionScalesSplitPartsAndEqualTheMaterialScaleWhenAllAreScaled) {
  const std::vector<std::string> load = {"load.max_kPa=5", "load.step_kPa=5", "load.hold_s=1", "load.ramp_s=0.5",
                                         "load.mark_s=0.5"};
  std::vector<std::string> roof = load;
  roof.push_back("regions.roof.stiffness_scale=0.5");
  auto bm = build_model(Scene::load("", tiny(roof)));
  const Model& m = bm->model;
  const int r_roof = m.mesh.find_region("roof");
  ASSERT_GE(r_roof, 0);
  int n_roof = 0;
  for (int e = 0; e < m.mesh.num_elements(); ++e) {
    const Part& p = m.parts[m.element_part[e]];
    if (m.mesh.region[e] == r_roof) {
      ++n_roof;
      EXPECT_EQ(p.name, "SILICONE@roof");
      EXPECT_EQ(p.material->initial_shear_modulus(), 0.5 * 2 * 0.019e6);
    } else {
      EXPECT_EQ(p.name.find('@'), std::string::npos);
    }
  }
  EXPECT_GT(n_roof, 0);
  // Every silicone region at 0.7 = the silicone's own scale 0.7: the same scaled law in every element.
  std::vector<std::string> regions = load, material = load;
  for (const char* tag : {"interior_wall", "roof", "side_wall", "end_cap", "base"})
    regions.push_back(std::string("regions.") + tag + ".stiffness_scale=0.7");
  material.push_back("materials.silicone.stiffness_scale=0.7");
  const std::vector<double> ar = angles(Scene::load("", tiny(regions))), am = angles(Scene::load("", tiny(material)));
  ASSERT_EQ(ar.size(), am.size());
  for (std::size_t i = 0; i < ar.size(); ++i) EXPECT_NEAR(ar[i], am[i], 1e-12 * std::abs(am.back()));
  // And the scaled region does change the answer: a softer roof bends more.
  EXPECT_GT(angles(Scene::load("", tiny(roof))).back(), angles(Scene::load("", tiny(load))).back());
}

TEST(StiffnessScale, BadValuesAreRejectedNamingTheKey) {
  auto err = [](const std::vector<std::string>& sets) { return error_of([&] { build_model(Scene::load("", tiny(sets))); }); };
  std::string e = err({"materials.silicone.stiffness_scale=0"});
  EXPECT_NE(e.find("materials.silicone.stiffness_scale"), std::string::npos) << e;
  EXPECT_NE(e.find("> 0"), std::string::npos) << e;
  e = err({"regions.roof.stiffness_scale=-2"});
  EXPECT_NE(e.find("regions.roof.stiffness_scale"), std::string::npos) << e;
  e = err({"regions.rooof.stiffness_scale=0.8"});
  EXPECT_NE(e.find("regions.rooof"), std::string::npos) << e;
  EXPECT_NE(e.find("valid region tags: "), std::string::npos) << e;
  EXPECT_NE(e.find("interior_wall"), std::string::npos) << e;
  e = err({"regions.roof.stifness_scale=0.8"});
  EXPECT_NE(e.find("regions.roof.stifness_scale"), std::string::npos) << e;
  EXPECT_NE(e.find("stiffness_scale"), std::string::npos) << e;
}

TEST(StiffnessScale, MembraneFabricTakesTheScaledModulus) {
  auto bm = build_model(Scene::load("", tiny({"mesh.fabric_model=membrane", "materials.fabric.stiffness_scale=0.5"})));
  ASSERT_EQ(bm->model.membranes.size(), 1u);
  auto ref = build_model(Scene::load("", tiny({"mesh.fabric_model=membrane"})));
  // Plane-stress SVK energy is linear in E: the membrane's stress at any strain halves.
  const Eigen::Matrix2d E = (Eigen::Matrix2d() << 0.01, 0.002, 0.002, -0.004).finished();
  EXPECT_NEAR(bm->model.membranes[0].law.S(E).norm(), 0.5 * ref->model.membranes[0].law.S(E).norm(),
              1e-12 * ref->model.membranes[0].law.S(E).norm());
}

// ---- Pressure lag ----

TrialLoad step_load(double p_Pa, double t_jump, double T) {
  TrialLoad tl;
  tl.time_s = {0.0, t_jump, t_jump + 1e-9, T};
  tl.pressure_Pa = {0.0, 0.0, p_Pa, p_Pa};
  return tl;
}

// Step response p_c = P (1 - exp(-(t - t0)/tau)) and ramp response p_c = b (t - tau (1 - exp(-t/tau)))
// (the solutions of tau p' = p_in - p with p(0) = 0), evaluated through the closed form (1): agreement
// to rounding (1e-12 of the step; the 1e-9 s jump shifts the step response by <= P 1e-9/tau = 2e-9 P).
TEST(PressureLag, ClosedFormMatchesStepAndRampResponses) {
  const double tau = 0.5, P = 5e3;
  const TrialLoad step = step_load(P, 1.0, 6.0);
  for (double t : {0.5, 1.1, 1.5, 2.0, 3.7, 6.0, 7.0}) {
    const double exact = t <= 1.0 ? 0.0 : P * (1.0 - std::exp(-(t - 1.0) / tau));
    EXPECT_NEAR(lagged_pressure(step, tau, t), exact, 3e-9 * P) << t;
  }
  TrialLoad ramp;
  ramp.time_s = {0.0, 2.0, 5.0};
  ramp.pressure_Pa = {0.0, 2.0 * P, 2.0 * P};  // b = P per second, then hold
  const double b = P;
  for (double t : {0.1, 0.7, 1.9, 2.0}) EXPECT_NEAR(lagged_pressure(ramp, tau, t), b * (t - tau * -std::expm1(-t / tau)), 1e-12 * P);
  const double p2 = b * (2.0 - tau * -std::expm1(-2.0 / tau));
  for (double t : {2.5, 4.0}) EXPECT_NEAR(lagged_pressure(ramp, tau, t), 2 * P + (p2 - 2 * P) * std::exp(-(t - 2.0) / tau), 1e-12 * P);
}

// The emitted piecewise-linear history is within the tolerance everywhere (dense check), and not
// needlessly dense: per step of size P the breakpoints needed are about the integral of 1/h(s) =
// 2 sqrt(P / (8 tol)) (h(s) from the header), 10 for tol = 0.5 % of P; allow 2x.
TEST(PressureLag, BreakpointsMeetTheToleranceWithoutWaste) {
  const double tau = 0.5, P = 5e3, tol = 0.005 * P;
  LoadHistory h;
  h.trials.push_back(step_load(P, 1.0, 9.0));
  TrialLoad ramp;
  ramp.time_s = {0.0, 0.5, 4.0, 4.3, 9.0};
  ramp.pressure_Pa = {0.0, P, P, 0.3 * P, 0.3 * P};
  h.trials.push_back(ramp);
  const LoadHistory lag = apply_pressure_lag(h, tau, tol);
  for (std::size_t k = 0; k < h.trials.size(); ++k) {
    double worst = 0.0;
    for (double t = 0.0; t <= 9.0; t += 1e-4)
      worst = std::max(worst, std::abs(lag.trials[k].pressure(t) - lagged_pressure(h.trials[k], tau, t)));
    EXPECT_LE(worst, tol) << "trial " << k;
    EXPECT_GT(worst, 0.2 * tol) << "trial " << k << ": breakpoints denser than needed";
  }
  EXPECT_LE(lag.trials[0].time_s.size(), h.trials[0].time_s.size() + 20);
  // Only the pressure breakpoints change: reports, steps and marks refer to the inlet command times.
  EXPECT_EQ(lag.trials[1].output_s, h.trials[1].output_s);
}

TEST(PressureLag, SceneKeyLagsTheStaircaseAndKeepsItsMetadata) {
  const std::vector<std::string> load = {"load.max_kPa=10", "load.step_kPa=5", "load.hold_s=3", "load.ramp_s=0.5",
                                         "load.mark_s=1"};
  std::vector<std::string> lagged = load, zero = load;
  lagged.push_back("load.pressure_lag_s=0.4");
  zero.push_back("load.pressure_lag_s=0");
  const auto a = build_model(Scene::load("", tiny(load))), b = build_model(Scene::load("", tiny(lagged))),
             z = build_model(Scene::load("", tiny(zero)));
  const TrialLoad &ta = a->load.trials[0], &tb = b->load.trials[0];
  EXPECT_EQ(z->load.trials[0].time_s, ta.time_s);  // lag 0: the staircase itself
  EXPECT_EQ(z->load.trials[0].pressure_Pa, ta.pressure_Pa);
  EXPECT_EQ(tb.output_s, ta.output_s);
  EXPECT_EQ(tb.step_start_s, ta.step_start_s);
  EXPECT_EQ(tb.step_level_Pa, ta.step_level_Pa);
  EXPECT_GT(tb.time_s.size(), ta.time_s.size());
  // Exact response of the ramp to 5 kPa at 3..3.5 s: at the ramp's end the chamber lags the inlet by
  // b (t - tau (1 - e^{-t/tau})) = 2.9 kPa; at the hold's end (2.5 s = 6 tau later) it has caught up
  // to within 5 kPa e^-6.
  const double tol = 0.005 * 5e3;
  EXPECT_NEAR(tb.pressure(4.0), lagged_pressure(ta, 0.4, 4.0), tol);
  EXPECT_LT(tb.pressure(3.5), ta.pressure(3.5) - 500.0);
  EXPECT_NEAR(tb.pressure(6.0), 5e3, 5e3 * std::exp(-6.0) + tol);
  const std::string e = error_of([&] { build_model(Scene::load("", tiny({"load.pressure_lag_s=-1"}))); });
  EXPECT_NE(e.find("load.pressure_lag_s"), std::string::npos) << e;
}

}  // namespace
}  // namespace pneufem
