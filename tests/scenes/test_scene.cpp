// Scene files: defaults, merging, overrides, and the errors a user sees for bad input.
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "core/errors.h"
#include "scenes/build_model.h"
#include "scenes/scene.h"
#include "tests/support/input_error.h"

namespace pneufem {
namespace {

namespace fs = std::filesystem;

std::string write_temp(const std::string& name, const std::string& text) {
  const fs::path dir = fs::temp_directory_path() / "pneufem_test_scene";
  fs::create_directories(dir);
  const fs::path p = dir / name;
  std::ofstream(p) << text;
  return p.string();
}

using pneufem::test::error_of;

// scenes/examples/small_actuator.toml, the tutorial's scene (docs/user_guide.md), is the scene the
// recordings of tests/data/hidden were made with (scripts/make_hidden_datasets.sh): every --set of a
// recording's command line has the example's value, so the tutorial compares like with like.
TEST(ExampleScenes, SmallActuatorIsTheSceneOfTheHiddenEffectRecordings) {
  const std::string root = std::string(PNEUFEM_TEST_DATA_DIR) + "/../..";
  const Scene example = Scene::load(root + "/scenes/examples/small_actuator.toml");
  for (const char* name : {"none", "viscoelastic"}) {
    std::ifstream in(std::string(PNEUFEM_TEST_DATA_DIR) + "/hidden/" + name + ".truth.json");
    std::stringstream text;
    text << in.rdbuf();
    const std::string json = text.str();
    const std::string field = "\"command_line\": \"";
    const std::size_t at = json.find(field);
    ASSERT_NE(at, std::string::npos) << name;
    const std::size_t begin = at + field.size();
    std::istringstream words(json.substr(begin, json.find('"', begin) - begin));
    int sets = 0;
    for (std::string w, previous; words >> w; previous = w) {
      if (previous != "--set") continue;
      const std::string key = w.substr(0, w.find('=')), value = w.substr(w.find('=') + 1);
      EXPECT_EQ(example.number(key), std::stod(value)) << name << ": " << key;
      ++sets;
    }
    EXPECT_EQ(sets, 6) << name;  // chambers, h_mm, max_kPa, step_kPa, hold_s, trials
  }
  // Everything else is the default scene's.
  EXPECT_EQ(example.string("materials.silicone.model"), Scene::load("").string("materials.silicone.model"));
}

TEST(Scene, DefaultsAreTheEngineIssueActuator) {
  const Scene s = Scene::load("");
  EXPECT_DOUBLE_EQ(s.number("geometry.width_mm"), 22.0);
  EXPECT_EQ(s.integer("geometry.chambers"), 15);
  EXPECT_DOUBLE_EQ(s.number("materials.silicone.C10_MPa"), 0.019);
  EXPECT_DOUBLE_EQ(s.number("materials.silicone.C30_MPa"), -4.75e-6);
  EXPECT_DOUBLE_EQ(s.number("materials.silicone.K_over_mu"), 100.0);
  EXPECT_DOUBLE_EQ(s.number("materials.fabric.E_MPa"), 6500.0);
  EXPECT_EQ(s.string("load.protocol"), "staircase");
  EXPECT_EQ(s.array_size("parts"), 2);
  EXPECT_EQ(s.origin("geometry.width_mm"), "default scene");
}

TEST(Scene, FileMergesOverDefaultsAndRecordsOrigins) {
  const std::string p = write_temp("merge.toml", "[load]\ntrials = 3\n\n[materials.silicone]\nC10_MPa = 0.02\n");
  const Scene s = Scene::load(p);
  EXPECT_EQ(s.integer("load.trials"), 3);
  EXPECT_DOUBLE_EQ(s.number("materials.silicone.C10_MPa"), 0.02);
  EXPECT_DOUBLE_EQ(s.number("materials.silicone.C20_MPa"), 9.0e-4);  // kept from the defaults
  EXPECT_EQ(s.origin("load.trials"), p + ":2");
  // The resolved scene re-loads to the same configuration.
  const std::string resolved = write_temp("resolved.toml", s.to_toml());
  EXPECT_EQ(Scene::load(resolved).to_toml(), s.to_toml());
}

TEST(Scene, OverridesParseTomlValuesAndBareWords) {
  const Scene s = Scene::load("", {"load.trials=10", "solver.method=relaxation", "gravity.g_m_s2=[0, 0, -9.81]"});
  EXPECT_EQ(s.integer("load.trials"), 10);
  EXPECT_EQ(s.string("solver.method"), "relaxation");
  EXPECT_DOUBLE_EQ(s.vec3("gravity.g_m_s2").z(), -9.81);
  EXPECT_EQ(s.origin("load.trials"), "--set load.trials");
}

TEST(Scene, ChangingAMaterialModelDropsTheOldConstants) {
  const Scene s = Scene::load("", {"materials.silicone={model=\"neo_hookean\", C10_MPa=0.02, K_over_mu=100.0, "
                                   "density_kg_m3=1070.0}"});
  EXPECT_FALSE(s.has("materials.silicone.C20_MPa"));
  EXPECT_NO_THROW(make_material(s, "silicone"));
}

// model_toml: the key of the caches of the ideal model and of diagnose's elastic curves. The constants
// of a switched-off effect do not change the model, so they must not change the key; anything else must.
TEST(Scene, ModelTomlIgnoresOnlyTheTablesSwitchedOff) {
  const Scene base = Scene::load("", {});
  const std::string tau = "materials.silicone.fatigue.tau_s=";
  EXPECT_EQ(base.with({tau + "123.0"}).model_toml(), base.model_toml());            // fatigue is off
  EXPECT_NE(base.with({tau + "123.0"}).to_toml(), base.to_toml());                  // (the full text differs)
  EXPECT_EQ(base.model_toml().find("[materials.silicone.fatigue]"), std::string::npos);
  const Scene on = base.with({"materials.silicone.fatigue.enabled=true"});
  EXPECT_NE(on.model_toml(), base.model_toml());
  EXPECT_NE(on.with({tau + "123.0"}).model_toml(), on.model_toml());                 // now it counts
  EXPECT_NE(base.with({"materials.silicone.C10_MPa=0.02"}).model_toml(), base.model_toml());
  EXPECT_NE(base.model_toml().find("[materials.silicone]"), std::string::npos);     // the rest stays
}

TEST(SceneErrors, UnknownKeyNamesFileLineAndSuggestion) {
  const std::string p = write_temp("typo.toml", "# comment\n[solver]\nmetod = \"newton\"\n");
  const std::string msg = error_of([&] { Scene::load(p); });
  EXPECT_NE(msg.find(p + ":3"), std::string::npos) << msg;
  EXPECT_NE(msg.find("solver.metod"), std::string::npos) << msg;
  EXPECT_NE(msg.find("did you mean 'solver.method'"), std::string::npos) << msg;
}

TEST(SceneErrors, TomlSyntaxErrorNamesLine) {
  const std::string p = write_temp("syntax.toml", "[load]\ntrials = = 3\n");
  const std::string msg = error_of([&] { Scene::load(p); });
  EXPECT_NE(msg.find(p + ":2"), std::string::npos) << msg;
  // What to do, too (the fuzz corpus's syntax errors named the place but gave no advice).
  EXPECT_NE(msg.find(" (TOML syntax error); fix the text there: one key = value per line"), std::string::npos) << msg;
}

TEST(SceneErrors, WrongTypeNamesKeyAndOrigin) {
  const std::string p = write_temp("type.toml", "[load]\ntrials = \"ten\"\n");
  const Scene s = Scene::load(p);
  const std::string msg = error_of([&] { s.integer("load.trials"); });
  EXPECT_NE(msg.find(p + ":2"), std::string::npos) << msg;
  EXPECT_NE(msg.find("load.trials"), std::string::npos) << msg;
  EXPECT_NE(msg.find("integer"), std::string::npos) << msg;
}

TEST(SceneErrors, UnknownOverrideKeyAndMalformedOverride) {
  EXPECT_NE(error_of([] { Scene::load("", {"load.trails=3"}); }).find("did you mean 'load.trials'"), std::string::npos);
  EXPECT_NE(error_of([] { Scene::load("", {"load.trials"}); }).find("key=value"), std::string::npos);
}

TEST(SceneErrors, BadMaterialConstantNamesTheMaterial) {
  const Scene s = Scene::load("", {"materials.silicone.C10_MPa=-0.01"});
  const std::string msg = error_of([&] { make_material(s, "silicone"); });
  EXPECT_NE(msg.find("materials.silicone"), std::string::npos) << msg;
  EXPECT_NE(msg.find("C10"), std::string::npos) << msg;
  EXPECT_NE(msg.find("--set"), std::string::npos) << msg;
}

TEST(SceneErrors, UnknownMaterialKeyAndModel) {
  const Scene s1 = Scene::load("", {"materials.silicone.C40_MPa=1.0"});
  EXPECT_NE(error_of([&] { make_material(s1, "silicone"); }).find("allowed"), std::string::npos);
  const Scene s2 = Scene::load("", {"materials.silicone.model=\"gent\""});
  EXPECT_NE(error_of([&] { make_material(s2, "silicone"); }).find("unknown material model"), std::string::npos);
}

// Issue 30 item 5: a part's unknown material model is named as such; it used to be reported as a
// missing density (the part read the density before building the material, and a table whose model
// changes starts empty).
TEST(SceneErrors, UnknownMaterialModelOfAPartIsNotReportedAsAMissingDensity) {
  const std::string msg = error_of([] { build_model(Scene::load("", {"materials.silicone.model=\"gent\"", "mesh.h_mm=8.0"})); });
  EXPECT_NE(msg.find("unknown material model \"gent\""), std::string::npos) << msg;
  EXPECT_EQ(msg.find("density"), std::string::npos) << msg;
}

TEST(SceneErrors, MissingSetInPartsIsReported) {
  const Scene s = Scene::load("", {"parts=[{elset=\"SILICONE\", material=\"silicone\"}, {elset=\"CLOTH\", material=\"fabric\"}]",
                                   "mesh.h_mm=4.0"});
  const std::string msg = error_of([&] { build_model(s); });
  EXPECT_NE(msg.find("CLOTH"), std::string::npos) << msg;
  EXPECT_NE(msg.find("not found"), std::string::npos) << msg;
}

TEST(SceneErrors, ElementWithoutPartIsReported) {
  const Scene s = Scene::load("", {"parts=[{elset=\"SILICONE\", material=\"silicone\"}]", "mesh.h_mm=4.0"});
  const std::string msg = error_of([&] { build_model(s); });
  EXPECT_NE(msg.find("belongs to no part"), std::string::npos) << msg;
}

TEST(SceneErrors, SolverCountsOutOfRangeNameTheKey) {
  const std::string m1 = error_of([] { build_model(Scene::load("", {"solver.stiff_relaxation_steps=-1", "mesh.h_mm=8.0"})); });
  EXPECT_NE(m1.find("solver.stiff_relaxation_steps"), std::string::npos) << m1;
  EXPECT_NE(m1.find(">= 0"), std::string::npos) << m1;
  const std::string m2 = error_of([] { build_model(Scene::load("", {"solver.max_iterations=0", "mesh.h_mm=8.0"})); });
  EXPECT_NE(m2.find("solver.max_iterations"), std::string::npos) << m2;
}

TEST(SceneBuild, DefaultModelHasCavityTipFixedAndSymmetry) {
  const Scene s = Scene::load("", {"mesh.h_mm=4.0"});
  const auto bm = build_model(s);
  EXPECT_GT(bm->model.pressure_faces.size(), 0u);
  EXPECT_GT(bm->model.angle.tip_nodes.size(), 3u);
  EXPECT_EQ(bm->model.angle.mirror_axis, 0);
  EXPECT_EQ(bm->load.trials.size(), 1u);
  EXPECT_EQ(bm->load.trials[0].step_level_Pa.size(), 10u);  // 0, 5, ..., 45 kPa
  EXPECT_DOUBLE_EQ(bm->load.trials[0].duration(), 160.0);
}

}  // namespace
}  // namespace pneufem
