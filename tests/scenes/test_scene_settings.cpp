// scenes/scene_settings.h: the typed settings of a scene, read once from their keys, with the
// scene reader's messages (the key, where it was set, the values allowed).
#include "scenes/scene_settings.h"

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "scenes/build_model.h"
#include "scenes/scene.h"
#include "tests/support/input_error.h"

namespace pneufem {
namespace {

using pneufem::test::error_of;

TEST(SceneSettings, MeshSourceOfTheDefaultSceneAndOfADeck) {
  const Scene base = Scene::load("");
  const MeshSettings m = mesh_settings(base);
  EXPECT_EQ(m.source, MeshSettings::Source::PneuNet);
  EXPECT_EQ(m.h_mm, base.number("mesh.h_mm"));
  EXPECT_EQ(mesh_settings(base.with({"mesh.h_mm=3.5"})).h_mm, 3.5);

  const MeshSettings deck = mesh_settings(base.with({"mesh.source=\"inp\"", "mesh.file=\"actuator.inp\""}));
  EXPECT_EQ(deck.source, MeshSettings::Source::Inp);
  EXPECT_EQ(deck.file, "actuator.inp");
  EXPECT_EQ(deck.h_mm, 0.0);  // a deck is its own mesh
  EXPECT_EQ(mesh_settings(base.with({"mesh.source=\"stl\""})).source, MeshSettings::Source::Stl);
}

// The meshers' keys in SI units, read for the sources that use them; each bad value names its key.
TEST(SceneSettings, MesherKeysAndTheGeometry) {
  const Scene base = Scene::load("", {"mesh.h_mm=4", "mesh.h_z_mm=2.5", "mesh.half=false", "mesh.element=\"tet4\"",
                                      "mesh.fabric_layers=2", "mesh.fabric_model=\"membrane\""});
  const MeshSettings m = mesh_settings(base);
  EXPECT_EQ(m.h_m, 4e-3);
  EXPECT_EQ(m.h_z_m, 2.5e-3);
  EXPECT_FALSE(m.half);
  EXPECT_EQ(m.element, ElementType::Tet4);
  EXPECT_EQ(m.fabric_layers, 2);
  EXPECT_TRUE(m.membrane_fabric);
  const PneuNetParams p = pneunet_settings(base.with({"geometry.chambers=7", "geometry.width_mm=20"}));
  EXPECT_EQ(p.chambers, 7);
  EXPECT_EQ(p.width, 20e-3);
  EXPECT_EQ(p.h, 4e-3);
  EXPECT_EQ(p.h_z, 2.5e-3);
  EXPECT_EQ(p.element, ElementType::Tet4);
  EXPECT_EQ(p.fabric_model, FabricModel::Membrane);
  EXPECT_FALSE(p.half);
  // A deck's unit; the mesher's keys keep their defaults.
  const MeshSettings deck = mesh_settings(base.with({"mesh.source=\"inp\"", "mesh.length_unit=\"m\""}));
  EXPECT_EQ(deck.length_unit_m, 1.0);
  EXPECT_EQ(deck.h_m, 0.0);
  EXPECT_EQ(mesh_settings(Scene::load("")).length_unit_m, 1e-3);
  const Scene d = Scene::load("");
  EXPECT_NE(error_of([&] { mesh_settings(d.with({"mesh.element=\"hex8\""})); })
                .find("key 'mesh.element': must be \"tet10\" or \"tet4\", got \"hex8\""),
            std::string::npos);
  EXPECT_NE(error_of([&] { mesh_settings(d.with({"mesh.h_z_mm=-1"})); }).find("mesh.h_z_mm"), std::string::npos);
  EXPECT_NE(error_of([&] { mesh_settings(d.with({"mesh.fabric_model=\"cloth\""})); })
                .find("must be \"solid\" or \"membrane\", got \"cloth\""),
            std::string::npos);
  EXPECT_NE(error_of([&] { mesh_settings(d.with({"mesh.source=\"inp\"", "mesh.length_unit=\"in\""})); })
                .find("must be \"mm\" or \"m\", got \"in\""),
            std::string::npos);
  EXPECT_NE(error_of([&] { mesh_settings(d.with({"mesh.source=\"stl\"", "mesh.h_mm=0"})); }).find("mesh.h_mm"),
            std::string::npos);
}

// The message build_model gave before the settings were typed: the key, where it was set, the values.
TEST(SceneSettings, UnknownMeshSourceNamesTheKeyAndTheSources) {
  const Scene s = Scene::load("", {"mesh.source=\"gmsh\""});
  const std::string msg = error_of([&] { mesh_settings(s); });
  EXPECT_NE(msg.find("mesh.source"), std::string::npos) << msg;
  EXPECT_NE(msg.find("--set"), std::string::npos) << msg;
  EXPECT_NE(msg.find("must be \"pneunet\", \"inp\" or \"stl\", got \"gmsh\""), std::string::npos) << msg;
  EXPECT_EQ(error_of([&] { build_mesh(s); }), msg);
}

// A scene's text quoted in a message (a key, a string value) may hold a NUL or a terminal escape
// (TOML strings allow \u0000): InputError::what() is a C string that a NUL cut short, before the
// rest of the message; control bytes are now written as \xHH (as the deck and CSV readers do).
TEST(SceneSettings, ControlBytesInKeysAndValuesDoNotCutTheMessageShort) {
  std::string msg = error_of([] { Scene::from_text("\"a\\u0000b\" = 1\n", "s.toml"); });
  EXPECT_EQ(msg.rfind("s.toml:1: key 'a\\x00b': unknown key (`pneufem scene --defaults` lists every key)", 0), 0u)
      << msg;
  msg = error_of([] { mesh_settings(Scene::from_text("[mesh]\nsource = \"gm\\u0000sh\\u001b[2J\"\n", "s.toml")); });
  EXPECT_NE(msg.find("s.toml:2:"), std::string::npos) << msg;
  EXPECT_NE(msg.find("got \"gm\\x00sh\\x1B[2J\""), std::string::npos) << msg;
}

// Found by counting the scene fuzz corpus: a material of the user's own whose table lacks a key
// was reported as "default scene: key 'materials.gel.model': missing" - the wrong place, and no
// advice. The message now names the line of the user's table and what to do.
TEST(SceneSettings, AMissingKeyOfTheUsersOwnTableNamesThatTable) {
  const Scene s = Scene::from_text("[load]\ntrials = 2\n[materials.gel.mullins]\nenabled = true\n", "s.toml");
  const std::string msg = error_of([&] { make_material(s, "gel"); });
  EXPECT_EQ(msg, "s.toml:4: key 'materials.gel.model': missing; add it (`pneufem scene --defaults` lists every key)");
  // A table replaced by a value names the --set that did it.
  EXPECT_EQ(error_of([] { load_settings(Scene::from_text("", "s.toml", {"load=3"})); }).rfind("--set load: key 'load.protocol': missing; add it", 0), 0u);
}

// Found by counting the scene fuzz corpus: load.mark_s outside the hold was refused by the engine
// as "load.mark_s: must lie within the hold, after the ramp" - no file, no line, no values.
TEST(SceneSettings, AMarkOutsideTheHoldNamesWhereAndTheRange) {
  const Scene s = Scene::from_text("[load]\nhold_s = 4.0\nmark_s = 5.0\n", "s.toml");
  EXPECT_EQ(error_of([&] { inlet_load(s); }),
            "s.toml:3: key 'load.mark_s': got 5; the mark must lie within the hold, after the ramp: from load.ramp_s "
            "= 0.5 to load.hold_s = 4 s");
  EXPECT_EQ(error_of([] { inlet_load(Scene::from_text("[load]\nhold_s = 4.0\nramp_s = 4.0\n", "s.toml")); }),
            "s.toml:3: key 'load.ramp_s': got 4; it must be shorter than load.hold_s = 4");
}

TEST(SceneSettings, LoadProtocolAndRest) {
  const Scene base = Scene::load("");
  const LoadSettings l = load_settings(base.with({"load.rest_s=12.5"}));
  EXPECT_EQ(l.protocol, LoadSettings::Protocol::Staircase);
  EXPECT_EQ(l.rest_s, 12.5);
  EXPECT_EQ(inlet_load(base.with({"load.rest_s=12.5"})).rest_between_trials_s, 12.5);
  EXPECT_EQ(load_settings(base.with({"load.protocol=\"csv\""})).protocol, LoadSettings::Protocol::Csv);
  const std::string msg = error_of([&] { load_settings(base.with({"load.protocol=\"ramp\""})); });
  EXPECT_NE(msg.find("load.protocol"), std::string::npos) << msg;
  EXPECT_NE(msg.find("must be \"staircase\" or \"csv\", got \"ramp\""), std::string::npos) << msg;
}

// The staircase's numbers, read once in SI units; inlet_load builds the protocol from them.
TEST(SceneSettings, StaircaseNumbersInSI) {
  const Scene s = Scene::load("", {"load.max_kPa=30", "load.step_kPa=7.5", "load.hold_s=4", "load.ramp_s=0.25",
                                   "load.mark_s=2", "load.trials=3", "load.output_every_s=1", "load.csv=\"p.csv\""});
  const LoadSettings l = load_settings(s);
  EXPECT_EQ(l.max_Pa, 30e3);
  EXPECT_EQ(l.step_Pa, 7.5e3);
  EXPECT_EQ(l.hold_s, 4.0);
  EXPECT_EQ(l.ramp_s, 0.25);
  EXPECT_EQ(l.mark_s, 2.0);
  EXPECT_EQ(l.trials, 3);
  EXPECT_EQ(l.output_every_s, 1.0);
  EXPECT_EQ(l.csv, "p.csv");
  const LoadHistory h = inlet_load(s);
  ASSERT_EQ(h.trials.size(), 3u);
  EXPECT_EQ(h.trials[0].step_level_Pa, (std::vector<double>{0.0, 7.5e3, 15e3, 22.5e3, 30e3}));
  EXPECT_EQ(h.trials[0].mark_s, 2.0);
  EXPECT_EQ(h.trials[0].time_s[2], 4.25);  // the first ramp ends ramp_s after the hold
}

TEST(SceneSettings, SolverAndOutput) {
  const Scene base = Scene::load("");
  const SolverSettings sv = solver_settings(base.with({"solver.model=\"reduced\""}));
  EXPECT_EQ(sv.mode, SolverSettings::Mode::QuasiStatic);
  EXPECT_EQ(sv.model, SolverSettings::Model::Reduced);
  EXPECT_EQ(mode_name(sv.mode), "quasi_static");
  EXPECT_EQ(model_name(sv.model), "reduced");
  EXPECT_EQ(mode_name(SolverSettings::Mode::Explicit), "explicit");
  EXPECT_EQ(model_name(SolverSettings::Model::Full), "full");
  const std::string msg =
      error_of([&] { solver_settings(base.with({"solver.mode=\"explicit\"", "solver.model=\"reduced\""})); });
  EXPECT_NE(msg.find("solver.model"), std::string::npos) << msg;
  EXPECT_NE(msg.find("needs solver.mode = \"quasi_static\""), std::string::npos) << msg;
  EXPECT_EQ(output_settings(base.with({"output.vtu=\"all\""})).vtu, "all");
  EXPECT_NE(error_of([&] { output_settings(base.with({"output.vtu=\"some\""})); }).find("output.vtu"), std::string::npos);
}

}  // namespace
}  // namespace pneufem
