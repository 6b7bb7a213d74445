// app/fit_material/deck_test_data.h: test data read from an Abaqus deck (*UNIAXIAL / *BIAXIAL /
// *PLANAR TEST DATA): Treloar's data from a deck fit as from CSV, and the deck's errors.
#include "app/fit_material/deck_test_data.h"

#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "app/fit_material/command.h"
#include "fit/inelastic.h"
#include "tests/app/cli_helpers.h"
#include "tests/app/fit_material/fit_material_helpers.h"
#include "tests/support/input_error.h"

namespace pneufem {
namespace {

using fit::TestMode;
using test::error_of;
using namespace test::fit_material;

/// Treloar's three tests as an Abaqus deck: *HYPERELASTIC, OGDEN, N=3, TEST DATA INPUT and the test data
/// blocks (nominal stress, nominal strain; mm-N-MPa), after a material without test data.
std::string treloar_deck() {
  std::string deck = "** Treloar 1944 as Abaqus test data\n*MATERIAL, NAME=STEEL\n*ELASTIC\n210000., 0.3\n"
                     "*MATERIAL, NAME=Treloar\n*HYPERELASTIC, OGDEN, N=3, TEST DATA INPUT\n";
  for (const auto& [kw, file] : std::vector<std::pair<std::string, std::string>>{
           {"UNIAXIAL", "uniaxial"}, {"BIAXIAL", "equibiaxial"}, {"PLANAR", "pureshear"}}) {
    deck += "*" + kw + " TEST DATA\n";
    std::ifstream in(kData + "/treloar1944/treloar_" + file + ".dat");
    for (double l, P; in >> l >> P;) deck += std::to_string(P) + ", " + std::to_string(l - 1.0) + "\n";
  }
  return write_temp("treloar.inp", deck);
}

// The same fit from a deck as from the CSV files: the law from the *HYPERELASTIC line, the same
// points (to the 6 decimals std::to_string wrote: constants within 1e-4 relative of the CSV fit).
TEST(DeckTestData, TreloarFromAnAbaqusDeckFitsAsFromCsv) {
  FitMaterialOptions o;
  o.data = {"deck:" + treloar_deck()};
  o.out_dir = test::fresh_dir("fit_deck").string();
  const FitMaterialResult deck = run_fit_material(o);
  EXPECT_EQ(deck.model, "ogden3");
  ASSERT_EQ(deck.tests.size(), 3u);
  EXPECT_EQ(deck.tests[1].mode, TestMode::biaxial);
  EXPECT_EQ(deck.tests[0].points.size(), 25u);
  o.data = {treloar_csv("uniaxial"), "biaxial:" + treloar_csv("equibiaxial"), treloar_csv("pureshear")};
  o.model = "ogden3";
  const FitMaterialResult csv = run_fit_material(o);
  ASSERT_EQ(deck.fit.constants.c.size(), csv.fit.constants.c.size());
  for (std::size_t i = 0; i < csv.fit.constants.c.size(); ++i) {
    EXPECT_NEAR(deck.fit.constants.c[i], csv.fit.constants.c[i], 1e-4 * csv.fit.constants.c[i]);
    EXPECT_NEAR(deck.fit.constants.alpha[i], csv.fit.constants.alpha[i], 1e-4 * std::abs(csv.fit.constants.alpha[i]));
  }
}

TEST(DeckTestData, Errors) {
  const auto deck = [&](const std::string& name, const std::string& text) { return write_temp(name, text); };
  const std::string arruda = deck("ab.inp", "*MATERIAL, NAME=R\n*HYPERELASTIC, ARRUDA-BOYCE, TEST DATA INPUT\n");
  std::string e = error_of([&] { read_deck_test_data(arruda, "mm"); });
  EXPECT_NE(e.find("ab.inp:2: *HYPERELASTIC, ARRUDA-BOYCE: pneufem has no such law"), std::string::npos) << e;
  const std::string outside = deck("out.inp", "*MATERIAL, NAME=R\n*HYPERELASTIC, YEOH\n0.1, 0, 0, 0\n*UNIAXIAL TEST DATA\n0.1, 0.2\n");
  e = error_of([&] { read_deck_test_data(outside, "mm"); });
  EXPECT_NE(e.find("out.inp:4: *UNIAXIAL TEST DATA outside a *HYPERELASTIC, TEST DATA INPUT"), std::string::npos) << e;
  const std::string bad = deck("bad.inp", "*MATERIAL, NAME=R\n*HYPERELASTIC, TEST DATA INPUT\n*UNIAXIAL TEST DATA\n0.1, x\n");
  e = error_of([&] { read_deck_test_data(bad, "mm"); });
  EXPECT_NE(e.find("bad.inp:4: field 2 (nominal strain) is not a number; a test data line is 'nominal stress, nominal strain'"),
            std::string::npos) << e;
  const std::string two = deck("two.inp", "*MATERIAL, NAME=A\n*HYPERELASTIC, YEOH, TEST DATA INPUT\n*UNIAXIAL TEST DATA\n"
                                          "0.1, 0.2\n0.2, 0.5\n0.3,1\n*MATERIAL, NAME=B\n*HYPERELASTIC, TEST DATA INPUT\n"
                                          "*PLANAR TEST DATA\n0.1, 0.2\n0.2, 0.5\n");
  FitMaterialOptions o;
  o.out_dir = test::fresh_dir("fit_deck_errors").string();
  o.data = {"deck:" + two};
  e = error_of([&] { run_fit_material(o); });
  EXPECT_NE(e.find("several materials have test data (A, B); choose one with --deck-material NAME"), std::string::npos) << e;
  o.deck_material = "B";
  // no law on the line: Abaqus's default POLYNOMIAL, N=1 (Mooney-Rivlin), whose C10 and C01 a planar
  // test alone cannot separate (P = 2 (l - l^-3)(C10 + C01))
  e = error_of([&] { run_fit_material(o); });
  EXPECT_NE(e.find("two.inp:9 (*MATERIAL B) (2 points) do not determine the 2 constants of mooney_rivlin"),
            std::string::npos) << e;
  o.model = "neo_hookean";
  o.model_given = true;
  const FitMaterialResult r = run_fit_material(o);
  EXPECT_EQ(r.model, "neo_hookean");
  EXPECT_EQ(r.tests[0].mode, TestMode::planar);
  EXPECT_NEAR(r.tests[0].points[1].P_Pa, 0.2e6, 1e-6);  // MPa with --deck-length-unit mm
}

}  // namespace
}  // namespace pneufem
