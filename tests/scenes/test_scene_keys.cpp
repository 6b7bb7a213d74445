// scenes/scene_keys.h: the key checks that the readers behind build_model share - unknown keys of a
// table, a string key's allowed values, a number that must be > 0, and a deck's node set named by a
// key - each with the message a user reads (the key, and what is allowed or available).
#include "scenes/scene_keys.h"

#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "engine/mesh.h"
#include "scenes/scene.h"
#include "tests/support/input_error.h"

namespace pneufem {
namespace {

using pneufem::test::error_of;

bool has(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

TEST(SceneKeys, RequireKeysNamesTheUnknownKeyAndTheAllowedOnes) {
  const Scene s = Scene::load("");
  const std::vector<std::string> keys = s.table_keys("angle");
  ASSERT_GE(keys.size(), 2u);
  const std::set<std::string> all(keys.begin(), keys.end());
  EXPECT_EQ(error_of([&] { detail::require_keys(s, "angle", all, "the angle"); }), "(no error)");
  std::set<std::string> fewer = all;
  const std::string dropped = *fewer.begin();
  fewer.erase(fewer.begin());
  const std::string e = error_of([&] { detail::require_keys(s, "angle", fewer, "the angle"); });
  EXPECT_TRUE(has(e, "angle." + dropped)) << e;
  EXPECT_TRUE(has(e, "unknown key for the angle; allowed: " + *fewer.begin())) << e;
}

TEST(SceneKeys, ChoiceReturnsTheValueOfTheNameOrListsTheNames) {
  enum class Method { Newton, Relaxation, Other };
  const Scene s = Scene::load("");
  const auto pick = [](const Scene& sc) {
    return detail::choice<Method>(sc, "solver.method",
                                  {{"newton", Method::Newton}, {"relaxation", Method::Relaxation}, {"x", Method::Other}});
  };
  EXPECT_EQ(pick(s.with({"solver.method=\"relaxation\""})), Method::Relaxation);
  EXPECT_EQ(pick(s.with({"solver.method=\"newton\""})), Method::Newton);
  const std::string e = error_of([&] { pick(s.with({"solver.method=\"newtn\""})); });
  EXPECT_TRUE(has(e, "solver.method")) << e;
  EXPECT_TRUE(has(e, "must be \"newton\", \"relaxation\" or \"x\", got \"newtn\"")) << e;
  EXPECT_TRUE(has(e, "--set")) << e;  // where the key was set
}

TEST(SceneKeys, PositiveRejectsZeroAndNegative) {
  // A key with a declared range (scenes/key_limits.h) is refused by that range as it is read, before
  // positive() sees it; so the check is exercised on a number of a user's material table that no range
  // covers (build_model rejects such a key as unknown later; positive() does not know that).
  const auto scene_with = [](const std::string& v) {
    return Scene::load("", {"materials.gel={model=\"yeoh\", C10_MPa=0.02, K_over_mu=50.0, density_kg_m3=1000.0, "
                            "size=" + v + "}"});
  };
  EXPECT_EQ(detail::positive(scene_with("2.5"), "materials.gel.size"), 2.5);
  for (const char* v : {"0.0", "-1.0"}) {
    const std::string e = error_of([&] { detail::positive(scene_with(v), "materials.gel.size"); });
    EXPECT_TRUE(has(e, "materials.gel.size")) << e;
    EXPECT_TRUE(has(e, "must be > 0")) << e;
  }
}

TEST(SceneKeys, NodeSetAsWrittenOrUpperCasedOrAnError) {
  const Scene s = Scene::load("");
  Mesh m;
  m.node_sets["FIXED"] = {0, 1, 2};
  m.node_sets["Tip"] = {7};
  m.node_sets["EMPTY"] = {};
  EXPECT_EQ(detail::node_set(s.with({"mesh.fixed_set=\"fixed\""}), m, "mesh.fixed_set"), (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(detail::node_set(s.with({"mesh.fixed_set=\"Tip\""}), m, "mesh.fixed_set"), (std::vector<int>{7}));
  std::string e = error_of([&] { detail::node_set(s.with({"mesh.fixed_set=\"empty\""}), m, "mesh.fixed_set"); });
  EXPECT_TRUE(has(e, "node set 'empty' is empty")) << e;
  e = error_of([&] { detail::node_set(s.with({"mesh.fixed_set=\"CLAMP\""}), m, "mesh.fixed_set"); });
  EXPECT_TRUE(has(e, "node set 'CLAMP' not found in the mesh; available: EMPTY, FIXED, Tip")) << e;
}

TEST(SceneKeys, NodeSetNamedByTwoInstancesMustBeQualified) {
  // An Abaqus/CAE deck stores an instance's set as "INSTANCE.NAME": a bare name two instances define
  // is ambiguous, and the message names both qualified names.
  const Scene s = Scene::load("");
  Mesh m;
  m.node_sets["A-1.BASE"] = {0};
  m.node_sets["B-1.BASE"] = {1};
  const std::string e = error_of([&] { detail::node_set(s.with({"mesh.fixed_set=\"base\""}), m, "mesh.fixed_set"); });
  EXPECT_TRUE(has(e, "is defined by 2 instances of the deck")) << e;
  EXPECT_TRUE(has(e, "A-1.BASE")) << e;
  EXPECT_TRUE(has(e, "B-1.BASE")) << e;
}

}  // namespace
}  // namespace pneufem
