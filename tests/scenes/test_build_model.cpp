// A deck through the scene (scenes/build_model.cpp): its pressure faces as the cavity when it names
// none, and the MODULI= of its viscoelastic materials reaching the scene's keys.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "damage/viscoelastic.h"
#include "scenes/build_model.h"
#include "tests/scenes/inp/deck_files.h"

namespace pneufem {
namespace {

using namespace pneufem::test;

// A deck whose chambers are marked only by their pressure load (*DLOAD Pn, no CAVITY surface) and a
// scene leaving mesh.cavity_surface at its default: the loaded faces are the cavity, with a note.
TEST_F(InpFiles, WithoutACavitySurfaceTheDecksPressureFacesAreTheCavity) {
  Mesh mesh = build_mesh(Scene::load("", {"geometry.chambers=2", "mesh.h_mm=6.0"}));
  const std::vector<FaceRef> cavity = mesh.surfaces.at("CAVITY");
  mesh.surfaces.erase("CAVITY");
  std::ostringstream os;
  write_inp_mesh(os, mesh, 1e-3);
  os << "*STEP, NLGEOM\n*STATIC\n*DLOAD\n";
  for (const FaceRef& f : cavity) os << mesh.element_ids[f.element] << ", P" << f.local_face + 1 << ", 0.045\n";
  os << "*END STEP\n";
  const std::string path = write("dload_only.inp", os.str());
  const auto bm = build_model(Scene::load("", {"mesh.source=\"inp\"", "mesh.file=\"" + path + "\"",
                                               "mesh.symmetry_set=\"SYMMETRY\""}));
  EXPECT_EQ(bm->model.pressure_faces, cavity);
  EXPECT_EQ(count_containing(bm->warnings, "mesh.cavity_surface: the deck has no surface 'CAVITY'; the faces of its pressure load (" +
                                               std::to_string(cavity.size()) + " *DLOAD/*DSLOAD P faces) are the cavity"), 1);
}

// MODULI= of *HYPERELASTIC / *VISCOELASTIC (Abaqus: whether the hyperelastic constants are the
// instantaneous or the long-term response of a viscoelastic material) is read with its *MATERIAL and
// reaches materials.<m>.viscoelastic.moduli: by the material's name, else the one value of the deck;
// a scene's own key wins (with a note); an unknown value is an error naming file and line.
TEST_F(InpFiles, ModuliOfAViscoelasticMaterialReachTheScene) {
  std::ifstream in(data_path("tet4_two.inp"));
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string two = buffer.str();
  const std::string materials =
      "*MATERIAL, NAME=Silicone\n"
      "*HYPERELASTIC, YEOH, MODULI=LONG TERM\n"
      "0.019, 0.0009, -4.75e-6, 0.5, 0.0, 0.0\n"
      "*VISCOELASTIC, TIME=PRONY\n"
      "0.3, 0.0, 2.0\n"
      "*MATERIAL, NAME=Gel\n"
      "*HYPERELASTIC, NEO HOOKE\n"
      "0.01, 0.5\n"
      "*VISCOELASTIC, TIME=PRONY, moduli=instantaneous\n"
      "0.2, 0.0, 1.0\n";
  const InpDeck d = read_inp(write("m.inp", two + materials), 1e-2);
  const int first = static_cast<int>(std::count(two.begin(), two.end(), '\n')) + 2;  // *HYPERELASTIC's line
  ASSERT_EQ(d.moduli.size(), 2u);
  EXPECT_EQ(d.moduli[0].material, "SILICONE");
  EXPECT_EQ(d.moduli[0].value, "long_term");
  EXPECT_NE(d.moduli[0].where.find("m.inp:" + std::to_string(first)), std::string::npos) << d.moduli[0].where;
  EXPECT_EQ(d.moduli[1].material, "GEL");
  EXPECT_EQ(d.moduli[1].value, "instantaneous");
  EXPECT_EQ(count_containing(d.warnings, "*HYPERELASTIC"), 0);  // a scene's materials pass reads it (materials.h)
  // Abaqus writes "LONG TERM"; an underscore and any case are read alike.
  EXPECT_EQ(read_inp(write("u.inp", two + "*MATERIAL, NAME=A\n*HYPERELASTIC, MODULI=long_term\n0.01, 0, 0.5\n"), 1e-2).moduli.at(0).value,
            "long_term");
  expect_error(two + "*MATERIAL, NAME=A\n*HYPERELASTIC, YEOH, MODULI=RELAXED\n", first,
               {"*HYPERELASTIC, MODULI=RELAXED: unknown value", "use MODULI=INSTANTANEOUS", "or MODULI=LONG TERM"});
  expect_error(two + "*MATERIAL, NAME=A\n*VISCOELASTIC, MODULI=\n", first, {"*VISCOELASTIC, MODULI=: unknown value"});

  // Through a scene: the built-in actuator written as a deck, with the materials appended.
  const std::vector<std::string> base = {"geometry.chambers=2", "mesh.h_mm=6.0"};
  std::ostringstream os;
  write_inp_mesh(os, build_mesh(Scene::load("", base)), 1e-3);
  auto scene = [&](const std::string& deck_materials, std::vector<std::string> extra) {
    std::vector<std::string> o = base;
    o.insert(o.end(), {"mesh.source=\"inp\"", "mesh.file=\"" + write("a.inp", os.str() + deck_materials) + "\"",
                       "mesh.symmetry_set=\"SYMMETRY\""});
    o.insert(o.end(), extra.begin(), extra.end());
    return Scene::load("", o);
  };
  auto moduli = [](const BuiltModel& bm) {
    for (const Part& p : bm.model.parts)
      if (const auto* v = dynamic_cast<const Viscoelastic*>(p.material.get())) return std::string(to_string(v->moduli()));
    return std::string("(not viscoelastic)");
  };
  const std::string on = "materials.silicone.viscoelastic.enabled=true";
  auto bm = build_model(scene(materials, {on}));
  EXPECT_EQ(moduli(*bm), "long_term");  // *MATERIAL, NAME=Silicone is the scene's silicone
  EXPECT_EQ(count_containing(bm->warnings, "materials.silicone from the deck (*MATERIAL Silicone, "), 1);
  EXPECT_EQ(count_containing(bm->warnings, "viscoelastic.gamma, viscoelastic.tau_s, viscoelastic.moduli"), 2);  // and Gel
  bm = build_model(scene(materials, {on, "materials.silicone.viscoelastic.moduli=instantaneous"}));
  EXPECT_EQ(moduli(*bm), "instantaneous");  // the scene's own key wins, with a note
  EXPECT_EQ(count_containing(bm->warnings, "is kept over the deck's MODULI=LONG TERM of *MATERIAL SILICONE"), 1);
  bm = build_model(scene(materials, {}));  // the deck's *VISCOELASTIC switches it on (scenes/deck_materials.h)
  EXPECT_EQ(moduli(*bm), "long_term");
  bm = build_model(scene(materials, {"materials.silicone.viscoelastic.enabled=false"}));  // the scene's key wins
  EXPECT_EQ(moduli(*bm), "(not viscoelastic)");
  EXPECT_EQ(count_containing(bm->warnings, "MODULI="), 0);
  bm = build_model(scene("*MATERIAL, NAME=Ecoflex\n*HYPERELASTIC, YEOH, MODULI=LONG TERM\n0.019, 0, 0, 0.5\n", {on}));
  EXPECT_EQ(moduli(*bm), "long_term");  // no material of the scene's name: the deck's one value
  bm = build_model(scene("", {on}));
  EXPECT_EQ(moduli(*bm), "instantaneous");  // no MODULI= at all: the scene's default, as Abaqus's
  try {
    build_model(scene("*MATERIAL, NAME=A\n*HYPERELASTIC, MODULI=LONG TERM\n0.01, 0, 0.5\n*MATERIAL, NAME=B\n"
                      "*HYPERELASTIC, MODULI=INSTANTANEOUS\n0.01, 0, 0.5\n",
                      {on}));
    ADD_FAILURE() << "no error for MODULI= that differ";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("materials.silicone.viscoelastic.moduli"), std::string::npos) << what;
    EXPECT_NE(what.find("the deck's MODULI= differ (MODULI=LONG TERM of *MATERIAL A at "), std::string::npos) << what;
    EXPECT_NE(what.find("MODULI=INSTANTANEOUS of *MATERIAL B at "), std::string::npos) << what;
    EXPECT_NE(what.find("none belongs to a *MATERIAL named 'silicone'"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace pneufem
