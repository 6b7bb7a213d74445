// Abaqus materials from decks (scenes/inp/materials.h) and as a layer of the scene
// (scenes/deck_materials.h): each keyword to its constants against hand-computed values, the Ogden
// convention against the analytic uniaxial stress, the scene's keys over the deck's, and the errors
// (file:line and the keyword).
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

namespace pneufem {
namespace {

namespace fs = std::filesystem;

class DeckMaterials : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("pneufem_deck_materials_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string write(const std::string& name, const std::string& text) const {
    const fs::path p = dir_ / name;
    std::ofstream(p) << text;
    return p.string();
  }
  /// A scene reading the deck `text` (written as `name`), with `sets`.
  Scene scene(const std::string& name, const std::string& text, std::vector<std::string> sets = {}) const {
    sets.insert(sets.begin(), {"mesh.source=\"inp\"", "mesh.file=\"" + write(name, text) + "\""});
    return Scene::load("", sets);
  }
  std::string error_of(const std::string& name, const std::string& text) const {
    try {
      (void)read_inp_materials(write(name, text), "mm");
    } catch (const InputError& e) {
      return e.what();
    }
    return "(no error)";
  }
  fs::path dir_;
};

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

/// The error of `text` as a scene's deck, from loading the scene.
std::string scene_error(const std::function<Scene()>& load) {
  try {
    (void)load();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
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
  // Through a scene: a name that cannot be a scene table.
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
