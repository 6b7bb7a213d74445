// A deck written by `pneufem mesh --out x.inp` re-imports to the identical scene (issue 32 item 3):
// a scene with mesh.source = "inp" on it and no materials or parts of its own builds the same
// materials (every law and effect the deck can carry) and bends the same, to the last digit.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "core/errors.h"
#include "scenes/build_model.h"
#include "scenes/calculix_deck.h"
#include "scenes/inp/deck.h"
#include "scenes/inp/materials.h"
#include "scenes/scene.h"
#include "tests/app/cli_helpers.h"

namespace pneufem {
namespace {

namespace fs = std::filesystem;

// Short protocol on a 2-chamber actuator: two levels, rate effects on (seconds).
const char* kCommon =
    "[load]\nmax_kPa = 10.0\nstep_kPa = 5.0\nhold_s = 2.0\nramp_s = 0.5\nmark_s = 1.0\ntrials = 1\n"
    "[output]\nvtu = \"none\"\n";

// Every law constant and effect the deck carries, none of them the default scene's.
const char* kMaterials =
    "[materials.silicone]\nmodel = \"ogden\"\nmu_MPa = [0.03, 0.0008]\nalpha = [2.2, -1.5]\nK_over_mu = 80.0\n"
    "density_kg_m3 = 1100.0\n"
    "[materials.silicone.mullins]\nenabled = true\nr = 4.0\nm_MPa = 0.02\nbeta = 0.1\n"
    "[materials.silicone.viscoelastic]\nenabled = true\ngamma = [0.2, 0.1]\ntau_s = [0.5, 3.0]\nmoduli = \"long_term\"\n"
    "[materials.fabric]\nmodel = \"linear_elastic\"\nE_MPa = 5000.0\nnu = 0.3\ndensity_kg_m3 = 1200.0\n";

/// Stresses of `m` along a short loading history (three steps of growing stretch with time), every
/// component, so that two materials can be compared to the bit.
std::vector<double> responses(const Material& m) {
  std::vector<double> out;
  std::vector<double> state(static_cast<std::size_t>(m.state_size())), next(state.size());
  if (!state.empty()) m.init_state(state);
  double t = 0.0;
  for (double l : {1.2, 1.6, 1.4}) {
    Mat3 F = Mat3::Identity();
    F(0, 0) = l;
    F(1, 1) = 1.0 / std::sqrt(l);
    F(0, 2) = 0.1 * l;
    t += 0.7;
    std::vector<PointResponse> r(1);
    m.evaluate(std::span<const Mat3>(&F, 1), TimeStep{t, 0.7}, state, next, r, false);
    for (int i = 0; i < 9; ++i) out.push_back(r[0].P()(i));
    state = next;
  }
  return out;
}

TEST(DeckRoundTrip, AnExportedDeckReimportsToTheSameScene) {
  const fs::path d = test::fresh_dir("deck_round_trip");
  fs::create_directories(d);
  std::ofstream(d / "original.toml") << "[geometry]\nchambers = 2\n[mesh]\nh_mm = 6.0\n" << kCommon << kMaterials;
  test::CliResult r = test::run_cli("mesh " + (d / "original.toml").string() + " --out " + (d / "x.inp").string());
  ASSERT_EQ(r.code, 0) << r.out;
  // The deck scene: its mesh keys and the protocol, no materials and no parts.
  std::ofstream(d / "deck.toml") << "[mesh]\nsource = \"inp\"\nfile = \"x.inp\"\nsymmetry_set = \"SYMMETRY\"\n"
                                 << "[angle]\nfixed_normal = [0.0, -1.0, 0.0]\nbend_direction = [0.0, 0.0, -1.0]\n"
                                 << kCommon;

  // The resolved materials: the same keys, and the same stresses along a history to the bit.
  const Scene a = Scene::load((d / "original.toml").string()), b = Scene::load((d / "deck.toml").string());
  EXPECT_EQ(b.numbers("materials.silicone.mu_MPa"), a.numbers("materials.silicone.mu_MPa"));
  EXPECT_EQ(b.numbers("materials.silicone.alpha"), a.numbers("materials.silicone.alpha"));
  EXPECT_EQ(b.number("materials.silicone.K_over_mu"), 80.0);  // not 79.99999999999999: D1 read back exactly
  EXPECT_EQ(b.number("materials.silicone.density_kg_m3"), 1100.0);
  EXPECT_EQ(b.numbers("materials.silicone.viscoelastic.gamma"), a.numbers("materials.silicone.viscoelastic.gamma"));
  EXPECT_EQ(b.string("materials.silicone.viscoelastic.moduli"), "long_term");
  EXPECT_EQ(b.number("materials.fabric.density_kg_m3"), 1200.0);
  const auto ma = build_model(a), mb = build_model(b);
  ASSERT_EQ(ma->model.parts.size(), mb->model.parts.size());
  for (std::size_t i = 0; i < ma->model.parts.size(); ++i) {
    const Part &pa = ma->model.parts[i], &pb = mb->model.parts[i];
    EXPECT_EQ(pa.name, pb.name);
    EXPECT_EQ(pa.density_kg_m3, pb.density_kg_m3) << pa.name;
    EXPECT_EQ(pa.material->name(), pb.material->name()) << pa.name;
    EXPECT_EQ(responses(*pa.material), responses(*pb.material)) << pa.name;
  }
  EXPECT_EQ(ma->model.element_part, mb->model.element_part);

  // Both simulated: the same angles, to the last digit.
  r = test::run_cli("simulate " + (d / "original.toml").string() + " --out " + (d / "a").string() + " --threads 2");
  ASSERT_EQ(r.code, 0) << r.out;
  r = test::run_cli("simulate " + (d / "deck.toml").string() + " --out " + (d / "b").string() + " --threads 2");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("note: materials.silicone from the deck (*MATERIAL SILICONE, "), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("note: parts from the deck's *SOLID SECTION lines: SILICONE -> silicone"), std::string::npos) << r.out;
  const std::string angles = test::slurp(d / "a" / "angles.csv");
  EXPECT_GT(std::count(angles.begin(), angles.end(), '\n'), 3);
  EXPECT_EQ(test::slurp(d / "b" / "angles.csv"), angles);
  // summary.json records the notes.
  EXPECT_NE(test::slurp(d / "b" / "summary.json").find("materials.fabric from the deck (*MATERIAL FABRIC, "), std::string::npos);
  fs::remove_all(d);
}

// What the export writes besides: a material's stiffness_scale times its constants (K/mu unchanged, so
// D1 follows mu0), fatigue named in a note (Abaqus has no keyword for it), a region's scale refused.
TEST(DeckRoundTrip, TheExportScalesConstantsNamesWhatItCannotWriteAndRefusesRegionScales) {
  const std::vector<std::string> small = {"geometry.chambers=2", "mesh.h_mm=6.0"};
  std::vector<std::string> sets = small;
  sets.insert(sets.end(), {"materials.silicone.stiffness_scale=0.5", "materials.silicone.fatigue.enabled=true"});
  const Scene s = Scene::load("", sets);
  std::vector<std::string> notes;
  const std::string deck = calculix_deck(s, *build_model(s), &notes);
  const std::string yeoh = "*HYPERELASTIC, YEOH\n" + inp_real_text(0.5 * 0.019) + ", " + inp_real_text(0.5 * 9.0e-4) + ", " +
                           inp_real_text(0.5 * -4.75e-6) + ", " + inp_real_text(abaqus_d1(100.0, 2 * (0.5 * 0.019))) + ", 0, 0\n";
  EXPECT_NE(deck.find(yeoh), std::string::npos) << deck.substr(deck.find("*MATERIAL"), 300);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("materials.silicone.fatigue is not written to the deck"), std::string::npos) << notes[0];
  EXPECT_NE(deck.find("** pneufem: materials.silicone.fatigue is not written"), std::string::npos);
  std::vector<std::string> region = small;
  region.push_back("regions.roof.stiffness_scale=0.8");
  const Scene r = Scene::load("", region);
  try {
    (void)calculix_deck(r, *build_model(r));
    ADD_FAILURE() << "no error for a region's scale";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("key 'regions.roof.stiffness_scale': the CalculiX export writes one material per"),
              std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace pneufem
