// A deck's materials as a layer of the scene (scenes/deck_materials.h): the deck's materials and
// sections become the scene's (Ogden constants in Abaqus's convention against the analytic uniaxial
// stress), the scene's keys win over the deck's, the deck's line in errors and notes, and a material
// given as test data needing the fitted block. The reader of *MATERIAL is tests/scenes/inp/test_materials.cpp.
#include "scenes/deck_materials.h"

#include <cmath>
#include <span>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/errors.h"
#include "damage/mullins.h"
#include "scenes/build_model.h"
#include "scenes/scene.h"
#include "tests/scenes/inp/material_decks.h"

namespace pneufem {
namespace {

using test::DeckMaterials;
using test::scene_error;

/// Nominal uniaxial stress of an incompressible Ogden solid at stretch lambda (lateral lambda^-1/2):
/// Abaqus's convention W = sum 2 mu_i/alpha_i^2 (...) gives T = sum 2 mu_i/alpha_i (l^(a-1) - l^(-a/2-1)).
double abaqus_ogden_uniaxial(const std::vector<double>& mu, const std::vector<double>& alpha, double l) {
  double T = 0.0;
  for (std::size_t i = 0; i < mu.size(); ++i)
    T += 2.0 * mu[i] / alpha[i] * (std::pow(l, alpha[i] - 1.0) - std::pow(l, -alpha[i] / 2.0 - 1.0));
  return T;
}

/// The same in Ogden's 1972 convention W = sum mu_p/alpha_p (...): T = sum mu_p (l^(a-1) - l^(-a/2-1)).
double ogden1972_uniaxial(const std::vector<double>& mu_p, const std::vector<double>& alpha, double l) {
  double T = 0.0;
  for (std::size_t i = 0; i < mu_p.size(); ++i)
    T += mu_p[i] * (std::pow(l, alpha[i] - 1.0) - std::pow(l, -alpha[i] / 2.0 - 1.0));
  return T;
}

/// The material's nominal uniaxial stress at an isochoric stretch l (J = 1, so U'(J) = 0): P11 less the
/// lateral stress carried over, T = P11 - P22 lambda2/lambda1 (the incompressible solid's pressure
/// makes the lateral faces free).
double material_uniaxial(const Material& m, double l) {
  Mat3 F = Mat3::Zero();
  F(0, 0) = l;
  F(1, 1) = F(2, 2) = 1.0 / std::sqrt(l);
  std::vector<PointResponse> out(1);
  std::vector<double> s0(static_cast<std::size_t>(m.state_size())), s1(s0.size());
  if (!s0.empty()) m.init_state(s0);
  m.evaluate(std::span<const Mat3>(&F, 1), TimeStep{}, s0, s1, out, false);
  const Mat3 P = out[0].P();
  return P(0, 0) - P(1, 1) * F(1, 1) / F(0, 0);
}

// Abaqus's Ogden mu_i are pneufem's (materials/ogden.h): read from a deck, the law's uniaxial stress is
// Abaqus's analytic one, and Ogden 1972's with mu_p = 2 mu_i / alpha_i. Reading the deck's mu_i as
// 1972's mu_p (the convention of some texts) would be off by alpha_i/2: 1.25 and -1 here.
TEST_F(DeckMaterials, OgdenConstantsAreAbaqusConvention) {
  const std::vector<double> mu = {0.02, 0.001}, alpha = {2.5, -2.0};  // MPa; stable: mu_i > 0
  const Scene s = scene("og.inp", "*MATERIAL, NAME=Rubber\n*HYPERELASTIC, OGDEN, N=2\n0.02, 2.5, 0.001, -2., 0.02, 0.\n");
  EXPECT_EQ(s.string("materials.rubber.model"), "ogden");
  EXPECT_EQ(s.numbers("materials.rubber.mu_MPa"), mu);
  EXPECT_EQ(s.numbers("materials.rubber.alpha"), alpha);
  // K0 = 2/D1 = 100 MPa over mu0 = 0.021 MPa.
  EXPECT_NEAR(s.number("materials.rubber.K_over_mu"), 100.0 / 0.021, 1e-12 * 100.0 / 0.021);
  const MaterialPtr m = make_material(s, "rubber");
  EXPECT_NEAR(m->initial_bulk_modulus(), 100e6, 1e-6);  // Pa; 1e-14 relative
  const std::vector<double> mu_p = {2 * mu[0] / alpha[0], 2 * mu[1] / alpha[1]};
  for (double l : {0.7, 1.3, 2.0, 3.5}) {
    const double T = material_uniaxial(*m, l);
    // 1e-12 relative: the law evaluates spectrally (an SVD of F) in Pa; the formulas are exact.
    EXPECT_NEAR(T, 1e6 * abaqus_ogden_uniaxial(mu, alpha, l), 1e-12 * std::abs(T)) << l;
    EXPECT_NEAR(T, 1e6 * ogden1972_uniaxial(mu_p, alpha, l), 1e-12 * std::abs(T)) << l;
    EXPECT_GT(std::abs(T - 1e6 * ogden1972_uniaxial(mu, alpha, l)), 0.05 * std::abs(T)) << l;  // the other reading
  }
}

// The deck's materials and sections become the scene's, each key's origin the deck's line; the
// scene's keys win key by key, a scene's [[parts]] win as a whole; notes say which came from where.
TEST_F(DeckMaterials, SceneKeysOverrideTheDeck) {
  const std::string deck =
      "*MATERIAL, NAME=Gel\n*HYPERELASTIC, NEO HOOKE\n0.01, 0.2\n*DENSITY\n1.1e-9\n*MULLINS EFFECT\n4, 0.03, 0.2\n"
      "*MATERIAL, NAME=Silicone\n*HYPERELASTIC, MOONEY-RIVLIN\n0.01, 0.002, 0.2\n"
      "*SOLID SECTION, ELSET=BODY, MATERIAL=GEL\n";
  Scene s = scene("d.inp", deck);
  EXPECT_EQ(s.string("materials.gel.model"), "neo_hookean");
  EXPECT_EQ(s.number("materials.gel.C10_MPa"), 0.01);
  EXPECT_EQ(s.number("materials.gel.K_over_mu"), 500.0);  // 2/0.2 = 10 MPa over 0.02
  EXPECT_EQ(s.number("materials.gel.density_kg_m3"), 1100.0);
  EXPECT_TRUE(s.boolean("materials.gel.mullins.enabled"));
  EXPECT_EQ(s.number("materials.gel.mullins.r"), 4.0);
  EXPECT_EQ(s.origin("materials.gel.mullins.r"), (dir_ / "d.inp").string() + ":6");
  EXPECT_EQ(s.array_size("parts"), 1);  // the deck's section replaces the default scene's parts
  EXPECT_EQ(s.string("parts[0].elset"), "BODY");
  EXPECT_EQ(s.string("parts[0].material"), "gel");
  // The default scene's silicone (Yeoh) is replaced by the deck's law, not mixed with it.
  EXPECT_EQ(s.string("materials.silicone.model"), "mooney_rivlin");
  EXPECT_FALSE(s.has("materials.silicone.C20_MPa"));
  EXPECT_NO_THROW((void)make_material(s, "silicone"));
  const MaterialPtr gel = make_material(s, "gel");
  EXPECT_NE(dynamic_cast<const Mullins*>(gel.get()), nullptr);

  // A scene file's key and an override win over the deck's; the rest stays the deck's.
  const std::string file = write("s.toml", "[mesh]\nsource = \"inp\"\nfile = \"d.inp\"\n[materials.gel]\nC10_MPa = 0.012\n"
                                           "[[parts]]\nelset = \"BODY\"\nmaterial = \"silicone\"\n");
  s = Scene::load(file, {"materials.gel.mullins.r=2.5"});
  EXPECT_EQ(s.number("materials.gel.C10_MPa"), 0.012);
  EXPECT_EQ(s.number("materials.gel.mullins.r"), 2.5);
  EXPECT_EQ(s.number("materials.gel.mullins.m_MPa"), 0.03);
  EXPECT_EQ(s.number("materials.gel.density_kg_m3"), 1100.0);
  EXPECT_EQ(s.string("parts[0].material"), "silicone");
  auto note = [&](const std::string& what) {
    for (const std::string& n : s.notes())
      if (n.find(what) != std::string::npos) return n;
    return "(no note with '" + what + "' in " + std::to_string(s.notes().size()) + " notes)";
  };
  EXPECT_NE(note("materials.gel from the deck").find("model, K_over_mu, density_kg_m3, mullins.enabled, mullins.m_MPa, "
                                                     "mullins.beta; the scene's own: C10_MPa (" + file + ":5), mullins.r "
                                                     "(--set materials.gel.mullins.r); used by no part"),
            std::string::npos)
      << note("materials.gel");
  EXPECT_NE(note("*SOLID SECTION").find("the deck's *SOLID SECTION lines are not used: the scene sets [[parts]] (" + file),
            std::string::npos)
      << note("*SOLID SECTION");
  // A different law in the scene replaces the deck's table, as a scene file's does the default's.
  s = Scene::load(file, {"materials.gel={model=\"yeoh\", C10_MPa=0.02, K_over_mu=50.0, density_kg_m3=1000.0}"});
  EXPECT_EQ(s.string("materials.gel.model"), "yeoh");
  EXPECT_FALSE(s.has("materials.gel.mullins"));
  EXPECT_NO_THROW((void)make_material(s, "gel"));
}

// A deck's own value that a material refuses is reported at the deck's line; Abaqus's D1 = 0
// (incompressible) takes the default scene's K0/mu0 with a note.
TEST_F(DeckMaterials, ErrorsNameTheDeckLineAndIncompressibleIsNoted) {
  Scene s = scene("r.inp", "*MATERIAL, NAME=Gel\n*HYPERELASTIC, NEO HOOKE\n0.01, 0.\n*MULLINS EFFECT\n0.5, 0.03, 0.2\n");
  try {
    (void)make_material(s, "gel");
    ADD_FAILURE() << "no error for r = 0.5";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find((dir_ / "r.inp").string() + ":4: key 'materials.gel.mullins'"), std::string::npos)
        << e.what();
  }
  EXPECT_EQ(s.number("materials.gel.K_over_mu"), 100.0);
  bool noted = false;
  for (const std::string& n : s.notes())
    noted |= n.find("materials.gel.K_over_mu = 100: the deck's D1 = 0 (" + (dir_ / "r.inp").string() + ":2) is "
                    "incompressible in Abaqus") != std::string::npos;
  EXPECT_TRUE(noted);
}

// A deck material's name that cannot be a scene table is an error naming the deck's line.
TEST_F(DeckMaterials, ANameThatCannotBeASceneTableIsAnError) {
  const std::string e = scene_error([&] { return scene("n.inp", "*MATERIAL, NAME=\"my gel\"\n*ELASTIC\n1., 0.3\n"); });
  EXPECT_NE(e.find("n.inp:1: *MATERIAL, NAME=my gel: the name cannot be a scene table"), std::string::npos) << e;
}

// *HYPERELASTIC, TEST DATA INPUT: the constants are not fitted while a scene loads; a part using the
// material needs the scene's law, else the error says how to get it with fit-material. The scene's law
// (fit-material's block) makes it run.
TEST_F(DeckMaterials, TestDataInputNeedsTheFittedBlock) {
  const std::string deck = "*MATERIAL, NAME=Lab\n*HYPERELASTIC, YEOH, TEST DATA INPUT\n*UNIAXIAL TEST DATA\n0.05, 0.2\n"
                           "0.1, 0.5\n*DENSITY\n1.05e-9\n*SOLID SECTION, ELSET=BODY, MATERIAL=Lab\n";
  const std::string e = scene_error([&] { return scene("t.inp", deck); });
  EXPECT_NE(e.find("t.inp:2: *MATERIAL Lab has *HYPERELASTIC, TEST DATA INPUT, and the scene's parts use it"), std::string::npos) << e;
  EXPECT_NE(e.find("run `pneufem fit-material deck:" + (dir_ / "t.inp").string() + " --deck-material Lab --name lab --out DIR`"),
            std::string::npos)
      << e;
  const Scene s = scene("t.inp", deck, {"materials.lab.model=\"yeoh\"", "materials.lab.C10_MPa=0.02",
                                         "materials.lab.K_over_mu=100.0"});
  EXPECT_EQ(s.number("materials.lab.density_kg_m3"), 1050.0);  // still the deck's
  EXPECT_NO_THROW((void)make_material(s, "lab"));
  // Used by no part: a note, no error.
  EXPECT_NO_THROW((void)scene("u.inp", deck, {"parts=[{elset=\"BODY\", material=\"silicone\"}]"}));
}

}  // namespace
}  // namespace pneufem
