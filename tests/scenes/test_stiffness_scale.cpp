// Stiffness scales in scenes (materials.<m>.stiffness_scale, regions.<tag>.stiffness_scale): the
// angle of a scaled actuator, region scales splitting parts, bad values. The scaled law itself is
// tests/materials/test_scaled.cpp; the chamber pressure lag, tests/scenes/test_pressure_lag.cpp.
#include <algorithm>
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
#include "tests/support/input_error.h"
#include "tests/support/tiny_scene.h"

namespace pneufem {
namespace {

using pneufem::test::error_of;
using pneufem::test::tiny;  // 3 chambers at h = 6 mm

/// Angles at every report of the scene's load.
std::vector<double> angles(const Scene& s) {
  auto bm = build_model(s);
  Assembler A(bm->model);
  QuasiStaticRun run(A, bm->solver.quasi_static);
  std::vector<double> out;
  run.run(bm->load, [&](const StateRecord& r, const Eigen::VectorXd&, const std::vector<double>&) { out.push_back(r.angle_deg); });
  return out;
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

}  // namespace
}  // namespace pneufem
