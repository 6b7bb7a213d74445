// The membrane fabric option (PneuNetParams::fabric_model, scene key mesh.fabric_model): the
// mesher's FABRIC_MEMBRANE surface against the closed-form area, the solid default unchanged,
// the scene wiring and its input errors.
#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <set>
#include <string>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "core/errors.h"
#include "scenes/build_model.h"
#include "scenes/calculix_deck.h"
#include "scenes/pneunet.h"
#include "tests/support/input_error.h"

namespace pneufem {
namespace {

// Areas and volumes are sums of a few thousand exact terms: 1e-12 relative is ~1e4 ulps, far
// below one missing or doubled face (> 1e-3 relative on these coarse meshes).
constexpr double kRelTol = 1e-12;

PneuNetParams coarse(ElementType type, bool half, FabricModel fabric) {
  PneuNetParams p;
  p.h = 4e-3;
  p.element = type;
  p.half = half;
  p.fabric_model = fabric;
  return p;
}

double face_area(const Mesh& m, FaceRef f) {
  const int* ln = face_local_nodes(m.type, f.local_face);
  const int* n = m.element(f.element);
  return 0.5 * (m.X[n[ln[1]]] - m.X[n[ln[0]]]).cross(m.X[n[ln[2]]] - m.X[n[ln[0]]]).norm();
}

double volume_of_region(const Mesh& m, const std::string& region) {
  const int r = m.find_region(region);
  double v = 0.0;
  for (int e = 0; e < m.num_elements(); ++e)
    if (m.region[e] == r) v += corner_volume(m, e);
  return v;
}

struct Case {
  ElementType type;
  bool half;
};

class FabricMembraneMesh : public ::testing::TestWithParam<Case> {};

TEST_P(FabricMembraneMesh, SurfaceCoversTheMidPlaneOnceAndTheLayerIsSilicone) {
  const auto [type, half] = GetParam();
  const PneuNetParams p = coarse(type, half, FabricModel::Membrane);
  const Mesh m = build_pneunet(p);
  const double W = half ? 0.5 * p.width : p.width, L = p.length();
  const double z_mid = p.fabric_z0 + 0.5 * p.fabric_thickness;

  ASSERT_TRUE(m.surfaces.count("FABRIC_MEMBRANE"));
  const auto& faces = m.surfaces.at("FABRIC_MEMBRANE");
  double area = 0.0;
  std::set<std::array<int, 3>> seen;
  for (FaceRef f : faces) {
    const int* ln = face_local_nodes(m.type, f.local_face);
    const int* n = m.element(f.element);
    std::array<int, 3> corners{};
    for (int a = 0; a < nodes_per_face(m.type); ++a) {
      EXPECT_NEAR(m.X[n[ln[a]]].z(), z_mid, 1e-15) << "a membrane node off the mid-plane";
      if (a < 3) corners[a] = n[ln[a]];
    }
    std::sort(corners.begin(), corners.end());
    EXPECT_TRUE(seen.insert(corners).second) << "face listed twice";
    area += face_area(m, f);
  }
  EXPECT_NEAR(area, W * L, kRelTol * W * L);

  // No fabric elements: FABRIC is empty, the layer is base silicone, the solid is unchanged.
  ASSERT_TRUE(m.element_sets.count("FABRIC"));
  EXPECT_TRUE(m.element_sets.at("FABRIC").empty());
  EXPECT_EQ(m.element_sets.at("SILICONE").size(), static_cast<std::size_t>(m.num_elements()));
  EXPECT_EQ(volume_of_region(m, regions::kFabric), 0.0);
  EXPECT_NEAR(volume_of_region(m, regions::kBase), W * L * p.base_thickness, kRelTol * W * L * p.base_thickness);
  const Mesh solid = build_pneunet(coarse(type, half, FabricModel::Solid));
  EXPECT_NEAR(compute_stats(m).volume_m3, compute_stats(solid).volume_m3, kRelTol * compute_stats(solid).volume_m3);
}

TEST_P(FabricMembraneMesh, SolidDefaultIsUnchanged) {
  const auto [type, half] = GetParam();
  PneuNetParams p;
  EXPECT_EQ(p.fabric_model, FabricModel::Solid);
  p = coarse(type, half, FabricModel::Solid);
  const Mesh m = build_pneunet(p);
  EXPECT_FALSE(m.surfaces.count("FABRIC_MEMBRANE"));
  const double W = half ? 0.5 * p.width : p.width;
  const double fabric = W * p.length() * p.fabric_thickness;
  EXPECT_NEAR(volume_of_region(m, regions::kFabric), fabric, kRelTol * fabric);
  EXPECT_FALSE(m.element_sets.at("FABRIC").empty());
}

std::string case_name(const ::testing::TestParamInfo<Case>& i) {
  return std::string(i.param.type == ElementType::Tet4 ? "Tet4" : "Tet10") + (i.param.half ? "Half" : "Full");
}
INSTANTIATE_TEST_SUITE_P(Cases, FabricMembraneMesh,
                         ::testing::Values(Case{ElementType::Tet4, true}, Case{ElementType::Tet10, true},
                                           Case{ElementType::Tet10, false}),
                         case_name);

using pneufem::test::error_of;

TEST(FabricMembraneScene, BuildsTheMembraneFromTheFabricMaterial) {
  const Scene s = Scene::load("", {"mesh.h_mm=4", "mesh.fabric_model=membrane"});
  const auto bm = build_model(s);
  const Model& model = bm->model;
  ASSERT_EQ(model.membranes.size(), 1u);
  const MembraneSet& ms = model.membranes[0];
  EXPECT_EQ(ms.name, "FABRIC_MEMBRANE");
  EXPECT_DOUBLE_EQ(ms.thickness_m, 0.4e-3);
  EXPECT_DOUBLE_EQ(ms.law.youngs_modulus(), 6.5e9);
  EXPECT_DOUBLE_EQ(ms.law.poisson_ratio(), 0.2);
  EXPECT_DOUBLE_EQ(ms.density_kg_m3, 1070.0);
  EXPECT_EQ(ms.nodes.size(), model.mesh.surfaces.at("FABRIC_MEMBRANE").size() * 6);
  ASSERT_EQ(model.parts.size(), 1u) << "the empty FABRIC part is skipped";
  EXPECT_EQ(model.parts[0].name, "SILICONE");
  EXPECT_NE(error_of([&] { (void)calculix_deck(s, *bm); }).find("mesh.fabric_model"), std::string::npos);

  const auto solid = build_model(Scene::load("", {"mesh.h_mm=4"}));
  EXPECT_TRUE(solid->model.membranes.empty());
  EXPECT_EQ(solid->model.parts.size(), 2u);
}

TEST(FabricMembraneScene, BadInputNamesTheKey) {
  EXPECT_NE(error_of([] { (void)build_model(Scene::load("", {"mesh.h_mm=4", "mesh.fabric_model=shell"})); })
                .find("mesh.fabric_model"),
            std::string::npos);
  const std::string not_linear = error_of([] {
    (void)build_model(Scene::load("", {"mesh.h_mm=4", "mesh.fabric_model=membrane", "materials.fabric.model=yeoh"}));
  });
  EXPECT_NE(not_linear.find("materials.fabric.model"), std::string::npos) << not_linear;
  EXPECT_NE(not_linear.find("linear_elastic"), std::string::npos) << not_linear;
  const std::string bad_nu = error_of([] {
    (void)build_model(Scene::load("", {"mesh.h_mm=4", "mesh.fabric_model=membrane", "materials.fabric.nu=0.7"}));
  });
  EXPECT_NE(bad_nu.find("materials.fabric"), std::string::npos) << bad_nu;
}

}  // namespace
}  // namespace pneufem
