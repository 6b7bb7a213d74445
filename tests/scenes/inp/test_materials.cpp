// Abaqus materials read from decks (scenes/inp/materials.h): each keyword to its constants against
// hand-computed values, a metre deck in pascals, and the errors (file:line and the keyword). The
// materials as a layer of the scene (scenes/deck_materials.h) are tests/scenes/test_deck_materials.cpp;
// both use the fixture of tests/scenes/inp/material_decks.h.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/errors.h"
#include "damage/mullins.h"
#include "damage/viscoelastic.h"
#include "materials/hyperelastic.h"
#include "materials/ogden.h"
#include "materials/scaled.h"
#include "scenes/build_model.h"
#include "scenes/inp/materials.h"
#include "scenes/scene.h"
#include "tests/scenes/inp/material_decks.h"

namespace pneufem {
namespace {

using test::DeckMaterials;

const InpMaterial& named(const InpMaterials& m, const std::string& name) {
  for (const InpMaterial& x : m.materials)
    if (x.name == name) return x;
  throw std::runtime_error("no material " + name);
}

double constant(const InpMaterial& m, const std::string& key) {
  for (const auto& [k, v] : m.constants)
    if (k == key) return v;
  throw std::runtime_error("no constant " + key);
}

// Every keyword to its constants, hand-computed: the numbers of a mm deck are MPa as written; D1 = 2/K0
// with K0/mu0 = 2/(D1 mu0); density tonne/mm^3 x 1e12 = kg/m^3; Prony gamma_i = g_i / (1 - sum g).
TEST_F(DeckMaterials, EachKeywordToItsConstants) {
  const InpMaterials d = read_inp_materials(write("all.inp",
      "*Material, name=Ecoflex\n"
      "*Hyperelastic, Yeoh, moduli=LONG TERM\n"
      "0.019, 9e-4, -4.75e-6, 0.5263157894736842, 0., 0.\n"
      "*Density\n1.07e-09,\n"
      "*Mullins Effect\n3.0, 0.02, 0.1\n"
      "*Viscoelastic, time=PRONY\n0.2, 0., 1.5\n0.1, 0., 10.\n"
      "*MATERIAL, NAME=Neo\n*HYPERELASTIC, NEO HOOKE\n0.0085, 0.1\n"
      "*MATERIAL, NAME=MR\n*HYPERELASTIC, MOONEY-RIVLIN\n0.01, 0.002, 0.2\n"
      "*MATERIAL, NAME=Poly\n*HYPERELASTIC, POLYNOMIAL, N=1\n0.01, 0.002, 0.2\n"
      "*MATERIAL, NAME=Default\n*HYPERELASTIC\n0.01, 0.002, 0.2\n"
      "*MATERIAL, NAME=Red2\n*HYPERELASTIC, REDUCED POLYNOMIAL, N=2\n0.02, 0.001, 0.05, 0.\n"
      "*MATERIAL, NAME=Og3\n*HYPERELASTIC, OGDEN, N=3\n"
      "0.3, 1.3, 0.0012, 5.0, 0.01, -2.0, 0.4, 0.\n0.\n"
      "*MATERIAL, NAME=Fabric\n*ELASTIC, TYPE=ISOTROPIC\n6500., 0.2\n*DENSITY\n1.2e-9\n*CONDUCTIVITY\n0.2\n"
      "*SOLID SECTION, ELSET=Body, MATERIAL=ECOFLEX\n,\n*Solid Section, elset=FABRIC, material=fabric\n"),
      "mm");
  ASSERT_EQ(d.materials.size(), 8u);
  const InpMaterial& e = named(d, "Ecoflex");
  EXPECT_EQ(e.model, "yeoh");
  EXPECT_EQ(constant(e, "C10_MPa"), 0.019);
  EXPECT_EQ(constant(e, "C20_MPa"), 9e-4);
  EXPECT_EQ(constant(e, "C30_MPa"), -4.75e-6);
  EXPECT_EQ(e.mu0_MPa, 2 * 0.019);
  EXPECT_EQ(e.D1_per_MPa, 0.5263157894736842);
  // K0 = 2/D1 = 3.8 MPa = 100 mu0: the shortest decimal, exactly 100.
  EXPECT_EQ(k_over_mu_from_d1(e.D1_per_MPa, e.mu0_MPa), 100.0);
  EXPECT_EQ(density_from_deck(*e.density, "mm"), 1070.0);
  ASSERT_TRUE(e.mullins.has_value());
  EXPECT_EQ(e.mullins->r, 3.0);
  EXPECT_EQ(e.mullins->m_MPa, 0.02);
  EXPECT_EQ(e.mullins->beta, 0.1);
  ASSERT_TRUE(e.prony.has_value());
  EXPECT_EQ(e.prony->g, (std::vector<double>{0.2, 0.1}));
  EXPECT_EQ(e.prony->tau_s, (std::vector<double>{1.5, 10.0}));
  const std::vector<double> gamma = gamma_from_abaqus_g(e.prony->g);
  // gamma = g / (1 - 0.3): 2/7 and 1/7 (to rounding: 1e-15 relative), giving the deck's g exactly back.
  EXPECT_NEAR(gamma[0], 2.0 / 7.0, 1e-15);
  EXPECT_NEAR(gamma[1], 1.0 / 7.0, 1e-15);
  EXPECT_EQ(abaqus_g(gamma), e.prony->g);
  EXPECT_EQ(e.moduli, "long_term");

  const InpMaterial& neo = named(d, "Neo");
  EXPECT_EQ(neo.model, "neo_hookean");
  // K0 = 2/0.1 = 20 MPa, mu0 = 2 * 0.0085 = 0.017 MPa: K0/mu0 = 1176.47... (1e-13: one division's rounding
  // in the shortest-decimal search, which keeps 2/(K/mu mu0) == D1 exactly).
  const double kr = k_over_mu_from_d1(neo.D1_per_MPa, neo.mu0_MPa);
  EXPECT_NEAR(kr, 20.0 / 0.017, 1e-13 * kr);
  // A D1 the writer made from K0/mu0 (abaqus_d1) gives that K0/mu0 back exactly; a hand-written one may
  // lie between two ratios' D1, then within two roundings (4e-16). Exact for a K0/mu0 of at most 15
  // significant digits: the ratios with one D1 span ~2 ulps, so no other decimal that short is among them.
  EXPECT_NEAR(abaqus_d1(kr, neo.mu0_MPa), 0.1, 4e-16 * 0.1);
  for (double mu0 : {0.038, 0.017, 0.0213, 1.0 / 3.0})
    for (double k : {100.0, 47.5, 1000.0, 333.3, 12.3456789012345})
      EXPECT_EQ(k_over_mu_from_d1(abaqus_d1(k, mu0), mu0), k) << k << " " << mu0;
  for (double rho : {1070.0, 1000.0, 1234.5, 998.2071})
    EXPECT_EQ(density_from_deck(deck_density(rho, "mm"), "mm"), rho) << rho;
  for (const std::vector<double>& gm : {std::vector<double>{0.1}, {0.3, 0.05}, {0.5, 0.25, 1.5}})
    EXPECT_EQ(gamma_from_abaqus_g(abaqus_g(gm)), gm);
  for (const char* n : {"MR", "Poly", "Default"}) {  // POLYNOMIAL N=1 and no law named: Mooney-Rivlin
    const InpMaterial& mr = named(d, n);
    EXPECT_EQ(mr.model, "mooney_rivlin") << n;
    EXPECT_EQ(constant(mr, "C10_MPa"), 0.01) << n;
    EXPECT_EQ(constant(mr, "C01_MPa"), 0.002) << n;
    EXPECT_EQ(mr.mu0_MPa, 2 * (0.01 + 0.002)) << n;
    // K0 = 2/0.2 = 10 MPa over mu0 = 0.024 MPa.
    EXPECT_NEAR(k_over_mu_from_d1(mr.D1_per_MPa, mr.mu0_MPa), 10.0 / 0.024, 1e-13 * 10.0 / 0.024) << n;
  }
  const InpMaterial& red = named(d, "Red2");  // C10, C20, D1, D2: Yeoh with C30 = 0
  EXPECT_EQ(red.model, "yeoh");
  EXPECT_EQ(constant(red, "C20_MPa"), 0.001);
  EXPECT_EQ(constant(red, "C30_MPa"), 0.0);
  EXPECT_EQ(red.D1_per_MPa, 0.05);
  const InpMaterial& og = named(d, "Og3");  // 8 values a line: D2, D3 on the lines' ends
  EXPECT_EQ(og.model, "ogden");
  EXPECT_EQ(og.mu_MPa, (std::vector<double>{0.3, 0.0012, 0.01}));
  EXPECT_EQ(og.alpha, (std::vector<double>{1.3, 5.0, -2.0}));
  EXPECT_EQ(og.mu0_MPa, 0.3 + 0.0012 + 0.01);
  EXPECT_EQ(og.D1_per_MPa, 0.4);
  const InpMaterial& fab = named(d, "Fabric");
  EXPECT_EQ(fab.model, "linear_elastic");
  EXPECT_EQ(constant(fab, "E_MPa"), 6500.0);
  EXPECT_EQ(constant(fab, "nu"), 0.2);
  EXPECT_EQ(density_from_deck(*fab.density, "mm"), 1200.0);
  ASSERT_EQ(d.notes.size(), 1u);  // *CONDUCTIVITY: passed over, with a note naming it
  EXPECT_NE(d.notes[0].find("all.inp:35: *CONDUCTIVITY of *MATERIAL Fabric passed over"), std::string::npos) << d.notes[0];
  ASSERT_EQ(d.sections.size(), 2u);
  EXPECT_EQ(d.sections[0].elset, "Body");
  EXPECT_EQ(d.sections[0].material, "ECOFLEX");
  EXPECT_EQ(d.sections[1].material, "fabric");
}

// An m deck's numbers are Pa, kg/m^3: stresses come back in MPa (the shortest decimal whose 1e6
// multiple is the deck's number), D1 in 1/MPa, densities as written.
TEST_F(DeckMaterials, AMetreDeckIsInPascals) {
  const InpMaterials d = read_inp_materials(
      write("m.inp", "*MATERIAL, NAME=A\n*HYPERELASTIC, NEO HOOKE\n8500., 1e-7\n*DENSITY\n1070.\n*MULLINS EFFECT\n2, 2000, 0\n"), "m");
  const InpMaterial& a = d.materials.at(0);
  EXPECT_EQ(constant(a, "C10_MPa") * 1e6, 8500.0);
  EXPECT_NEAR(constant(a, "C10_MPa"), 0.0085, 1e-18);
  EXPECT_NEAR(a.D1_per_MPa, 0.1, 1e-16);  // 1e-7 /Pa = 0.1 /MPa
  EXPECT_EQ(density_from_deck(*a.density, "m"), 1070.0);
  EXPECT_NEAR(a.mullins->m_MPa, 0.002, 1e-18);
}

// Bad material input: a clear error naming the file, the line and the keyword, and what to do.
TEST_F(DeckMaterials, BadMaterialsAreErrorsNamingFileLineAndKeyword) {
  const std::string m = "*MATERIAL, NAME=R\n";
  struct Case {
    std::string text;
    std::vector<std::string> expected;
  };
  const std::vector<Case> cases = {
      {m + "*HYPERELASTIC, ARRUDA-BOYCE\n0.1, 7, 0.1\n",
       {"bad.inp:2: *HYPERELASTIC, ARRUDA-BOYCE: the parameter ARRUDA-BOYCE is not read by pneufem", "fit-material"}},
      {m + "*HYPERELASTIC, YEOH, HYBRID\n0.1, 0, 0, 0.1\n", {"bad.inp:2: *HYPERELASTIC, HYBRID, YEOH: the parameter HYBRID"}},
      {m + "*ELASTIC, TYPE=ORTHOTROPIC\n1, 2, 3, 4, 5, 6, 7, 8\n9\n", {"bad.inp:2: *ELASTIC, TYPE=ORTHOTROPIC: TYPE=ORTHOTROPIC is not isotropic"}},
      {m + "*ELASTIC\n1.0, 0.3\n*PLASTIC\n1.0, 0.\n", {"bad.inp:4: *PLASTIC: pneufem does not model this material behaviour",
                                                      "remove it from *MATERIAL R"}},
      {m + "*HYPERELASTIC, OGDEN, N=4\n", {"bad.inp:2: *HYPERELASTIC, N=4, OGDEN: N=4 is not one pneufem has", "1 to 3 terms"}},
      {m + "*HYPERELASTIC, YEOH\n0.1, 0, 0, 0.1, 0.2, 0.\n", {"bad.inp:2: *HYPERELASTIC, YEOH: D2 = 0.2", "set D2, D3, ... to 0"}},
      {m + "*HYPERELASTIC, NEO HOOKE\n0.1, 0.1, 20.\n", {"bad.inp:3: *HYPERELASTIC, NEO HOOKE: value 3 '20.' is more than its 2",
                                                         "temperature"}},
      {m + "*HYPERELASTIC, NEO HOOKE\n0.1, 0.1\n0.2, 0.1\n", {"bad.inp:4: *HYPERELASTIC, NEO HOOKE: more data lines"}},
      {m + "*HYPERELASTIC, NEO HOOKE\n*DENSITY\n1e-9\n", {"bad.inp:2: *HYPERELASTIC, NEO HOOKE: no data line"}},
      {m + "*HYPERELASTIC, NEO HOOKE\nx, 0.1\n", {"bad.inp:3: *HYPERELASTIC, NEO HOOKE: value 1 'x' is not a number"}},
      {m + "*ELASTIC\n1., 0.3\n*VISCOELASTIC, TIME=RELAXATION TEST DATA\n", {"bad.inp:4: *VISCOELASTIC, TIME=RELAXATION TEST DATA",
                                                                             "fit-material relaxation:FILE"}},
      {m + "*ELASTIC\n1., 0.3\n*VISCOELASTIC, TIME=PRONY\n0.2, 0.1, 1.\n", {"bad.inp:5: *VISCOELASTIC, TIME=PRONY: k_i = 0.1", "set k_i = 0"}},
      {m + "*ELASTIC\n1., 0.3\n*VISCOELASTIC, TIME=PRONY\n0.6, 0., 1.\n0.5, 0., 2.\n", {"bad.inp:6:", "sum to 1.1 >= 1"}},
      {m + "*ELASTIC\n1., 0.3\n*MULLINS EFFECT, TEST DATA INPUT\n", {"bad.inp:4: *MULLINS EFFECT, TEST DATA INPUT: the parameter",
                                                                     "--mullins"}},
      {m + "*ELASTIC\n1., 0.3\n*HYPERELASTIC, NEO HOOKE\n0.1, 0.\n", {"bad.inp:4: *HYPERELASTIC, NEO HOOKE: *MATERIAL R has an elastic law already"}},
      {"*HYPERELASTIC, NEO HOOKE\n0.1, 0.\n", {"bad.inp:1: *HYPERELASTIC: a material option outside a *MATERIAL"}},
      {m + "*DENSITY\n1e-9\n", {"bad.inp:1: *MATERIAL, NAME=R: no elastic law"}},
      {m + "*ELASTIC\n1., 0.3\n*MATERIAL, NAME=r\n", {"bad.inp:4: *MATERIAL, NAME=r: a second material named r (the first at"}},
      {m + "*ELASTIC\n1., 0.3\n*SOLID SECTION, ELSET=B, MATERIAL=Gel\n",
       {"bad.inp:4: *SOLID SECTION, ELSET=B, MATERIAL=Gel: the deck defines no material Gel (it has: R)"}},
      {m + "*ELASTIC\n1., 0.3\n*SOLID SECTION, ELSET=B\n", {"bad.inp:4: *SOLID SECTION, ELSET=B: no MATERIAL="}},
  };
  for (const Case& c : cases) {
    const std::string e = error_of("bad.inp", c.text);
    for (const std::string& x : c.expected) EXPECT_NE(e.find(x), std::string::npos) << c.text << "\n-> " << e;
  }
}

}  // namespace
}  // namespace pneufem
