// pneufem diagnose on recordings with a hidden effect. The datasets in tests/data/hidden were made
// by `pneufem synth` (scripts/make_hidden_datasets.sh): the FULL FEM of a small pneu-net with the
// effect switched on, driven by a simulated controller (overshoot), sampled at 200 Hz / 30 fps
// with sensor noise, tracking noise (0.05 deg) and outlier frames. Diagnose does not know the
// truth; it calibrates every candidate with the reduced path model and must
//   * rank the hidden effect first and call it the missing effect (none for the control data),
//   * bring the error down to near the noise floor,
//   * recover constants near the truth.
#include <algorithm>
#include <fstream>
#include <functional>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iterator>
#include <map>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "analysis/measurements.h"
#include "app/diagnose/command.h"
#include "app/diagnose/effect_catalog.h"
#include "app/simulate/drive.h"
#include "app/synth/command.h"
#include "core/errors.h"
#include "scenes/build_model.h"
#include "scenes/inp/deck.h"
#include "scenes/scene.h"
#include "tests/app/recording_helpers.h"

namespace fs = std::filesystem;

namespace pneufem {
namespace {

// The scene the datasets were generated with (scripts/make_hidden_datasets.sh), effects off.
const std::vector<std::string> kScene = {"geometry.chambers=5", "mesh.h_mm=6.0",  "load.max_kPa=30.0",
                                         "load.step_kPa=10.0",  "load.hold_s=4.0", "load.trials=3"};

// The actuator's elastic FEM work (path trace, static curves) is shared by the tests on kScene
// through one cache directory (app/simulate/result_cache.h): keyed by this test program's own bytes, so a
// rebuilt program never reads an old entry; results are bit-identical to computing them
// (DiagnoseCache.ReRunGivesTheIdenticalDiagnosisFromTheCache).
std::string shared_cache() { return (fs::temp_directory_path() / "pneufem_diagnose_cache").string(); }

std::string data(const std::string& name) { return std::string(PNEUFEM_TEST_DATA_DIR) + "/hidden/" + name + ".csv"; }

/// Options for a diagnosis of the hidden-effect dataset `name` on kScene: output in a fresh
/// <tmp>/pneufem_diag_<out>, the shared cache, at most `max_effects` rounds over `candidates`
/// (empty = the whole catalog).
DiagnoseOptions hidden_options(const std::string& name, const std::string& out, int max_effects,
                               std::vector<std::string> candidates = {}) {
  DiagnoseOptions o;
  o.data_path = data(name);
  o.out_dir = (fs::temp_directory_path() / ("pneufem_diag_" + out)).string();
  fs::remove_all(o.out_dir);
  o.max_effects = max_effects;
  o.candidates = std::move(candidates);
  o.cache_dir = shared_cache();
  return o;
}

DiagnosisResult diagnose(const std::string& name, int refine = 0) {
  // One round: one hidden effect (round 2 is exercised in GravityIsKeptUnderHistoryEffects and
  // ForwardSelectionStopsAtTheNoiseFloor).
  DiagnoseOptions o = hidden_options(name, name, 1);
  o.refine = refine;
  const DiagnosisResult r = run_diagnosis(Scene::load("", kScene), o);
  std::printf("%s: baseline %.4f, floor %.4f, final %.4f (FEM %.4f); ranking:", name.c_str(), r.baseline_nrmse,
              r.noise_floor_nrmse, r.final_nrmse, r.verified_fitted_nrmse);
  for (const CandidateResult& c : r.candidates) {
    std::printf(" %s %.4f (dAIC %.0f%s)", c.effect.c_str(), c.nrmse, c.delta_aic, c.significant ? ", sig" : "");
    for (std::size_t i = 0; i < c.params.size(); ++i) std::printf(" %s=%.4g", c.param_names[i].c_str(), c.params[i]);
    std::printf(";");
  }
  std::printf("\n");
  EXPECT_TRUE(fs::exists(fs::path(o.out_dir) / "diagnosis.json"));
  EXPECT_TRUE(fs::exists(fs::path(o.out_dir) / "fitted.toml"));
  return r;
}

/// Noise-free data from the scene's own FEM with the silicone 20 % softer, rig-sampled, written
/// to <tmp>/<name>/data.csv (the directory is returned, emptied first).
fs::path softer_silicone_recording(const Scene& scene, const std::string& name) {
  Recording rec = test::rig_sampled(build_model(scene)->load, "fem");
  const DriveResult truth = simulate_recording(scene.with({"materials.silicone.stiffness_scale=0.8"}), rec, DriveOptions{});
  rec.trials[0].angle_deg.value = truth.trials[0].angle_deg.value;
  const fs::path dir = fs::temp_directory_path() / name;
  fs::remove_all(dir);
  fs::create_directories(dir);
  write_measurements_csv((dir / "data.csv").string(), rec);
  return dir;
}

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

double param(const DiagnosisResult& r, const std::string& name) {
  const CandidateResult& c = r.candidates.front();
  for (std::size_t i = 0; i < c.param_names.size(); ++i)
    if (c.param_names[i] == name) return c.params[i];
  ADD_FAILURE() << "no parameter " << name;
  return NAN;
}

TEST(EffectiveSampleSize, WhiteAndCorrelatedResiduals) {
  std::mt19937_64 rng(3);
  std::normal_distribution<double> n01;
  const int n = 20000;
  std::vector<double> white(n), ar(n);
  std::vector<int> seg(n, 0);
  double x = 0.0;
  const double rho = 0.9;
  for (int i = 0; i < n; ++i) {
    white[i] = n01(rng);
    x = rho * x + std::sqrt(1 - rho * rho) * n01(rng);
    ar[i] = x;
  }
  // White: rho_hat ~ N(0, 1/n) -> n_eff within a few % of n. AR(1) 0.9: n (0.1 / 1.9) = 1053;
  // rho_hat has sd ~ sqrt((1 - rho^2)/n) = 0.003 -> n_eff within ~10 %.
  EXPECT_GT(effective_sample_size(white, seg), 0.95 * n);
  EXPECT_NEAR(effective_sample_size(ar, seg), n * 0.1 / 1.9, 0.1 * n * 0.1 / 1.9);
}

// --fem-calibrate on a small elastic case it can afford in CI: data made by the FEM itself with the
// silicone 20 % softer (no noise), the stiffness candidate only. The reduced model misjudges a
// uniform softening by ~1 % of the angle (test_path_model), which biases its scale (measured 0.779,
// 2.6 % off). Calibrating on the FEM from there (12 runs: golden section on a +-1/6 cell of the
// log-scale range [0.5, 2], bracket 0.333 * 0.618^10 * 0.6 decades = 0.38 %) must bring the scale
// within 0.5 % of the truth, closer than the reduced model, and the FEM error near zero (noise-free
// data; 0.5 % of stiffness is ~0.3 % of the angle range).
// A calibrated constant within 1 % (of the calibration coordinate, log here) of a bound is flagged;
// inside the range it is not; the rig angle's ends are real rigs, never flagged, and so is the
// lag's tau2 = 0 (the first-order lag, reduces_at_lo), though its upper end is.
TEST(Diagnose, ConstantsAtTheEdgeOfTheirRangeAreFlagged) {
  const CandidateEffect& m = candidate_effect("mullins");  // r in [1.1, 20], m in [1e-3, 0.1], both log
  EXPECT_EQ(params_at_bounds(m, {1.1, 0.02}), std::vector<std::string>{"r"});
  EXPECT_EQ(params_at_bounds(m, {1.1 * std::pow(20.0 / 1.1, 0.02), 0.1}), std::vector<std::string>{"m_MPa"});
  EXPECT_EQ(params_at_bounds(m, {3.0, 0.01}), std::vector<std::string>{});
  EXPECT_EQ(params_at_bounds(candidate_effect("fatigue"), {0.02, 1e5}), std::vector<std::string>{"tau_s"});
  EXPECT_EQ(params_at_bounds(candidate_effect("gravity"), {180.0}), std::vector<std::string>{});
  EXPECT_EQ(params_at_bounds(candidate_effect("gravity"), {0.0}), std::vector<std::string>{});
  EXPECT_EQ(params_at_bounds(candidate_effect("pressure_lag"), {0.4, 0.0}), std::vector<std::string>{});
  EXPECT_EQ(params_at_bounds(candidate_effect("pressure_lag"), {0.4, 1.0}), std::vector<std::string>{"tau2_s"});
}

// The static discrepancy (fit_static_discrepancy) on a synthetic staircase: three trials of four
// holds, the model angle flat within a hold. A residual that is a smooth function of the model
// angle (a cubic, as a mesh or stiffness misfit leaves) is removed to round-off; creep inside the
// holds (the measured angle rising while the model's stays put), softening of the later trials and
// a lag after each step are not: at one model angle they take different values.
TEST(StaticDiscrepancy, RemovesAStaticMisfitAndKeepsHistoryEffects) {
  std::vector<ComparedFrame> frames;
  const int trials = 3, holds = 4, per_hold = 50;
  for (int k = 0; k < trials; ++k)
    for (int h = 0; h < holds; ++h)
      for (int i = 0; i < per_hold; ++i) {
        ComparedFrame f;
        f.trial_index = k;
        f.t_s = 4.0 * h + 4.0 * i / per_hold;
        f.model_deg = 10.0 * h;
        f.measured_deg = f.model_deg;
        frames.push_back(f);
      }
  auto with_residual = [&](const std::function<double(const ComparedFrame&, int)>& extra) {
    std::vector<ComparedFrame> out = frames;
    for (std::size_t j = 0; j < out.size(); ++j) out[j].measured_deg -= extra(out[j], static_cast<int>(j % per_hold));
    return out;
  };
  auto rss = [](const std::vector<ComparedFrame>& fs) {
    double s = 0.0;
    for (const ComparedFrame& f : fs) s += (f.model_deg - f.measured_deg) * (f.model_deg - f.measured_deg);
    return s;
  };
  // Static: 0.5 + 0.04 theta - 1e-3 theta^2 + 2e-5 theta^3 deg. Four distinct angles and four
  // coefficients: the fit is exact, and the residual ~1e-13 deg^2 (round-off of ~600 terms).
  const auto stat = with_residual([](const ComparedFrame& f, int) {
    const double a = f.model_deg;
    return 0.5 + 0.04 * a - 1e-3 * a * a + 2e-5 * a * a * a;
  });
  const StaticFit s = fit_static_discrepancy(stat);
  EXPECT_GT(rss(stat), 10.0);
  EXPECT_LT(s.rss_deg2, 1e-18 * 600 + 1e-12);
  EXPECT_NEAR(s.coefficients_deg[0], 0.5, 1e-9);  // x = theta / 30: a0 = 0.5, a1 = 0.04 * 30
  EXPECT_NEAR(s.coefficients_deg[1], 1.2, 1e-9);
  EXPECT_EQ(s.residual_deg.size(), stat.size());
  // History: creep of 0.5 deg over every hold but the first (a ramp, mean 0.25), softening of the
  // later trials (+0.3 deg at every loaded hold of trials 2-3), a lag (1 deg decaying within 0.4 s
  // of each step). The best static fit can only take their mean at each angle: what is left is
  // their variance about it. Exactly for the creep ramp (uniform on [0, 0.5] within every loaded
  // hold: variance 0.5^2/12 per frame, 450 frames = 9.375 deg^2); for the softening 0.3^2 x 2/9 per
  // frame of the 450 loaded frames (two trials of three shifted) = 9.0 deg^2.
  const auto creep = with_residual([&](const ComparedFrame& f, int i) { return f.model_deg > 0 ? -0.5 * i / (per_hold - 1.0) : 0.0; });
  EXPECT_NEAR(fit_static_discrepancy(creep).rss_deg2, 450 * 0.25 / 12.0 * (per_hold + 1.0) / (per_hold - 1.0), 1e-6);
  const auto soft = with_residual([](const ComparedFrame& f, int) { return f.trial_index > 0 && f.model_deg > 0 ? -0.3 : 0.0; });
  EXPECT_NEAR(fit_static_discrepancy(soft).rss_deg2, 450 * 0.09 * 2.0 / 9.0, 1e-9);
  const auto lag = with_residual([](const ComparedFrame& f, int i) { return f.model_deg > 0 ? std::exp(-i / 5.0) : 0.0; });
  // A decaying transient is mostly kept: the fit takes its mean over each hold (n mean^2 = 0.61 of
  // sum e^(-2i/5) = 3.03 deg^2 per hold), 80 % is left.
  EXPECT_NEAR(fit_static_discrepancy(lag).rss_deg2 / rss(lag), 0.80, 0.01);
  // A flat model (every frame at one angle) leaves the powers dependent: the rank-revealing fit
  // takes the mean and nothing blows up.
  std::vector<ComparedFrame> flat = frames;
  for (std::size_t j = 0; j < flat.size(); ++j) flat[j].model_deg = 5.0, flat[j].measured_deg = 5.0 - (j % 2 ? 1.0 : 0.0);
  const StaticFit f = fit_static_discrepancy(flat);
  EXPECT_NEAR(f.rss_deg2, flat.size() * 0.25, 1e-9);
  for (double c : f.coefficients_deg) EXPECT_TRUE(std::isfinite(c));
}

/// The FEM stages' case: a 3-chamber actuator, one trial to 20 kPa, noise-free data from its FEM with
/// the silicone 20 % softer (in `dir`); the options calibrate the stiffness alone.
Scene fem_stage_scene() {
  return Scene::load("", {"geometry.chambers=3", "mesh.h_mm=6", "load.max_kPa=20", "load.step_kPa=10", "load.hold_s=3",
                          "load.ramp_s=0.5", "load.trials=1", "output.vtu=\"none\""});
}
DiagnoseOptions stiffness_only(const fs::path& dir) {
  DiagnoseOptions o;
  o.data_path = (dir / "data.csv").string();
  o.out_dir = (dir / "out").string();
  o.candidates = {"stiffness"};
  o.max_effects = 1;
  return o;
}

TEST(DiagnoseFem, CalibratesOnTheFemFromTheReducedModelStart) {
  const Scene scene = fem_stage_scene();
  const fs::path dir = softer_silicone_recording(scene, "pneufem_diag_femcal");
  DiagnoseOptions o = stiffness_only(dir);
  o.fem_calibration_runs = 12;
  const DiagnosisResult r = run_diagnosis(scene, o);
  ASSERT_EQ(r.selected, std::vector<std::string>{"stiffness"});
  ASSERT_EQ(r.refined_params.size(), 1u);
  const double rom_scale = r.candidates.front().params[0], fem_scale = r.refined_params[0][0];
  std::printf("scale: reduced model %.5f, FEM-calibrated %.5f (truth 0.8); FEM NRMSE %.5f\n", rom_scale, fem_scale,
              r.verified_fitted_nrmse);
  EXPECT_NEAR(fem_scale, 0.8, 0.005 * 0.8);
  EXPECT_LE(std::abs(fem_scale - 0.8), std::abs(rom_scale - 0.8));
  EXPECT_GE(r.verified_fitted_nrmse, 0.0);
  EXPECT_LT(r.verified_fitted_nrmse, 0.005);
  fs::remove_all(dir);
}

// --cache: a second run on the same actuator reads the elastic path and the static FEM curves (gravity
// needs them) from the cache and gives the identical diagnosis, to the bit: the cache stores exact
// doubles and everything else is recomputed from them.
TEST(DiagnoseCache, ReRunGivesTheIdenticalDiagnosisFromTheCache) {
  const Scene scene = fem_stage_scene();
  const fs::path dir = softer_silicone_recording(scene, "pneufem_diag_cache");
  DiagnoseOptions o = stiffness_only(dir);
  o.candidates = {"stiffness", "gravity", "viscoelastic"};
  o.max_evaluations = 15;  // identity is the point here, not the fit
  o.cache_dir = (dir / "cache").string();
  const DiagnosisResult first = run_diagnosis(scene, o);
  const std::string json1 = read_text(dir / "out" / "diagnosis.json");
  o.out_dir = (dir / "out2").string();
  const DiagnosisResult second = run_diagnosis(scene, o);
  const std::string json2 = read_text(dir / "out2" / "diagnosis.json");
  EXPECT_NE(json1.find("\"status\": \"ok\""), std::string::npos);  // a diagnosis that did not fail says so
  EXPECT_NE(json1.find("\"elastic_path_source\": \"computed\""), std::string::npos);
  EXPECT_NE(json2.find("\"elastic_path_source\": \"cache "), std::string::npos);
  int curves = 0;
  for (const auto& e : fs::directory_iterator(dir / "cache")) curves += e.path().filename().string().starts_with("curve_");
  EXPECT_GE(curves, 5);  // the gravity candidate's rig-angle node sweeps at least
  ASSERT_EQ(first.candidates.size(), second.candidates.size());
  for (std::size_t i = 0; i < first.candidates.size(); ++i) {
    EXPECT_EQ(first.candidates[i].effect, second.candidates[i].effect);
    EXPECT_EQ(first.candidates[i].params, second.candidates[i].params) << first.candidates[i].effect;
    EXPECT_EQ(first.candidates[i].rss_deg2, second.candidates[i].rss_deg2) << first.candidates[i].effect;
  }
  EXPECT_EQ(first.baseline_nrmse, second.baseline_nrmse);
  EXPECT_EQ(first.final_nrmse, second.final_nrmse);
  EXPECT_EQ(read_text(dir / "out" / "diagnosis.csv"), read_text(dir / "out2" / "diagnosis.csv"));
  fs::remove_all(dir);
}

// --refine 1: one space-mapping step (the FEM at the reduced model's constants gives a correction,
// the constants are re-calibrated on the corrected reduced model, the FEM runs them too). Same case
// as above: the reduced model's scale is 0.8 % off the truth (0.8062); a space-mapping step on a
// smooth one-parameter problem removes most of that, as the correction changes little with the
// scale (measured 0.8010: a sixth of the error left; asserted: under a quarter). Before 2026-11-26
// the re-calibrated constants were never run by the FEM and --refine 1 returned the reduced
// model's own. The verified NRMSE is that of the last FEM run (not repeated; measured 0.0012).
TEST(DiagnoseFem, OneRefinementMovesTheConstantsToTheFems) {
  const Scene scene = fem_stage_scene();
  const fs::path dir = softer_silicone_recording(scene, "pneufem_diag_refine");
  DiagnoseOptions o = stiffness_only(dir);
  o.refine = 1;
  o.refine_model = DiagnoseOptions::RefineModel::Full;
  const DiagnosisResult r = run_diagnosis(scene, o);
  ASSERT_EQ(r.refined_params.size(), 1u);
  const double rom_scale = r.candidates.front().params[0], refined = r.refined_params[0][0];
  std::printf("scale: reduced model %.5f, refined %.5f (truth 0.8); FEM NRMSE %.5f\n", rom_scale, refined,
              r.verified_fitted_nrmse);
  EXPECT_GT(std::abs(rom_scale - 0.8), 0.004 * 0.8);  // the case needs a biased reduced model
  EXPECT_LT(std::abs(refined - 0.8), 0.25 * std::abs(rom_scale - 0.8));
  EXPECT_GE(r.verified_fitted_nrmse, 0.0);
  EXPECT_LT(r.verified_fitted_nrmse, 0.01);
  fs::remove_all(dir);
}

// --calibration-h: calibrate on a coarser built-in mesh, driven through the pressure map that makes
// its elastic path the scene mesh's (app/diagnose/evaluator.h, PathModelEvaluator). Case: a 3-chamber actuator
// whose h = 8 mesh is 19 % stiffer in angle than its h = 3 mesh, data from the h = 3 FEM with the
// silicone 20 % softer (noise-free). Measured: scene mesh baseline 0.1696 and scale 0.8037; calibration
// mesh 0.1696 and 0.8123; the raw h = 8 mesh 0.2275 and 0.7346 (before the reduced model sampled
// every quadrature point of its elements, 2026-11-26: 0.794, 0.785, 0.696). So: the baseline within
// 1 % (the map is exact for the elastic baseline up to interpolation; raw differs by 34 %), the scale
// within 3 % of the truth (the reduced model's own ~1 % plus the map's neglect of how the mesh error
// changes with the scale; raw is 8 % off) and the same ranking of all six candidates, except
// between candidates whose errors on the scene mesh are within 2 % of each other (a tie at the
// reduced model's accuracy). fitted.toml keeps the scene's mesh.
TEST(CalibrationMesh, GivesTheSceneMeshsBaselineRankingAndConstants) {
  const Scene scene = Scene::load("", {"geometry.chambers=3", "mesh.h_mm=3", "load.max_kPa=20", "load.step_kPa=10",
                                       "load.hold_s=3", "load.ramp_s=0.5", "load.trials=1", "output.vtu=\"none\""});
  const fs::path dir = softer_silicone_recording(scene, "pneufem_diag_calmesh");
  auto run = [&](const Scene& s, double cal_h, const std::vector<std::string>& cands, const std::string& out) {
    DiagnoseOptions o;
    o.data_path = (dir / "data.csv").string();
    o.out_dir = (dir / out).string();
    o.candidates = cands;
    o.max_effects = 1;
    o.calibration_h_mm = cal_h;
    const DiagnosisResult r = run_diagnosis(s, o);
    std::printf("%s: baseline %.4f;", out.c_str(), r.baseline_nrmse);
    for (const CandidateResult& c : r.candidates) std::printf(" %s %.4f%s", c.effect.c_str(), c.nrmse, c.significant ? " (sig)" : "");
    std::printf("; %.1f s\n", r.wall_s);
    return r;
  };
  const DiagnosisResult fine = run(scene, 0.0, {}, "scene_mesh");
  const DiagnosisResult cal = run(scene, 8.0, {}, "calibration_mesh");
  const DiagnosisResult raw = run(scene.with({"mesh.h_mm=8"}), 0.0, {"stiffness"}, "raw_coarse");

  std::printf("stiffness scale: scene mesh %.4f, calibration mesh %.4f, raw coarse mesh %.4f (truth 0.8)\n",
              fine.candidates.front().params[0], cal.candidates.front().params[0], raw.candidates.front().params[0]);
  EXPECT_NEAR(cal.baseline_nrmse, fine.baseline_nrmse, 0.01 * fine.baseline_nrmse);
  EXPECT_GT(std::abs(raw.baseline_nrmse - fine.baseline_nrmse), 0.1 * fine.baseline_nrmse);  // the case is a real test
  ASSERT_EQ(cal.selected, std::vector<std::string>{"stiffness"});
  ASSERT_EQ(fine.selected, std::vector<std::string>{"stiffness"});
  EXPECT_NEAR(cal.candidates.front().params[0], 0.8, 0.03 * 0.8);
  EXPECT_GT(std::abs(raw.candidates.front().params[0] - 0.8), 0.05);

  ASSERT_EQ(cal.candidates.size(), fine.candidates.size());
  std::map<std::string, std::size_t> rank;
  std::map<std::string, bool> significant;
  for (std::size_t i = 0; i < cal.candidates.size(); ++i) {
    rank[cal.candidates[i].effect] = i;
    significant[cal.candidates[i].effect] = cal.candidates[i].significant;
  }
  for (std::size_t i = 0; i < fine.candidates.size(); ++i) {
    const CandidateResult& a = fine.candidates[i];
    ASSERT_TRUE(rank.count(a.effect)) << a.effect;
    EXPECT_EQ(significant[a.effect], a.significant) << a.effect;
    for (std::size_t j = i + 1; j < fine.candidates.size(); ++j) {
      const CandidateResult& b = fine.candidates[j];
      if (b.nrmse > 1.02 * a.nrmse) {
        EXPECT_LT(rank[a.effect], rank[b.effect]) << a.effect << " before " << b.effect;
      }
    }
  }
  EXPECT_EQ(Scene::load((dir / "calibration_mesh" / "fitted.toml").string(), {}).number("mesh.h_mm"), 3.0);
  fs::remove_all(dir);
}

TEST(CalibrationMesh, NeedsTheBuiltInMesher) {
  const fs::path dir = fs::temp_directory_path() / "pneufem_diag_calmesh_inp";
  fs::remove_all(dir);
  DiagnoseOptions o;
  o.data_path = data("none");
  o.out_dir = dir.string();
  o.calibration_h_mm = 8.0;
  const Scene deck = Scene::load("", {"mesh.source=\"inp\"", "mesh.file=\"" PNEUFEM_TEST_DATA_DIR "/inp/tet10_two.inp\""});
  try {
    run_diagnosis(deck, o);
    ADD_FAILURE() << "expected an InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("--calibration-h needs the built-in mesher"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(dir / "diagnosis.json"));
}

// Without --calibration-h, a large built-in mesh is calibrated on a coarser one (the default
// actuator: 108 852 dof at h = 2 -> 6 mm) and a small one on itself; a value given is kept (0 = the
// scene's mesh); a note says which. The threshold (50k dof) sits between the 3-chamber actuator at
// h = 2 (27k) and the default one (109k).
TEST(CalibrationMesh, ChosenForLargeBuiltInMeshesUnlessGiven) {
  std::vector<std::string> notes;
  const Scene def = Scene::load("", {});
  EXPECT_EQ(resolve_calibration_h(def, -1.0, notes), 6.0);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("108852 dof: the candidates are calibrated on the built-in mesher at h = 6 mm"), std::string::npos)
      << notes[0];
  notes.clear();
  EXPECT_EQ(resolve_calibration_h(def, 0.0, notes), 0.0);
  EXPECT_EQ(resolve_calibration_h(def, 4.0, notes), 4.0);
  EXPECT_EQ(resolve_calibration_h(Scene::load("", {"geometry.chambers=3", "mesh.h_mm=2"}), -1.0, notes), 0.0);
  EXPECT_EQ(resolve_calibration_h(def.with({"mesh.h_mm=6"}), -1.0, notes), 0.0);
  EXPECT_TRUE(notes.empty());
}

// Issue 30 item 3: a diagnosis that fails late keeps what it had done. Before, a failure after
// hours of fitting left an empty --out (everything is written at the end). Here a failure injected
// after round 1 (DiagnoseOptions::fail_after_round, as any late exception would) must leave round
// 1's candidates, its selection, the history (baseline and the model after round 1), fitted.toml of
// the effect selected so far and a diagnosis.json and report.md that say it failed and why.
TEST(Diagnose, ALateFailureWritesTheRoundsDoneAndSaysItFailed) {
  DiagnoseOptions o = hidden_options("stiffness", "failed_late", 2, {"stiffness", "viscoelastic"});
  o.fail_after_round = 1;
  std::string error;
  try {
    run_diagnosis(Scene::load("", kScene), o);
  } catch (const std::exception& e) {
    error = e.what();
  }
  ASSERT_NE(error.find("injected failure after round 1"), std::string::npos) << error;
  const fs::path out(o.out_dir);
  const std::string json = read_text(out / "diagnosis.json");
  EXPECT_NE(json.find("\"status\": \"failed: diagnose: injected failure after round 1"), std::string::npos) << json;
  EXPECT_NE(json.find("\"selected\": [\"stiffness\"]"), std::string::npos) << json;
  EXPECT_NE(json.find("\"effect\": \"viscoelastic\""), std::string::npos) << json;  // round 1's other candidate
  EXPECT_EQ(json.find("\"round\": 2"), std::string::npos) << json;
  const std::string history = read_text(out / "history.jsonl");
  EXPECT_NE(history.find("diagnose baseline"), std::string::npos) << history;
  EXPECT_NE(history.find("diagnose + stiffness"), std::string::npos) << history;
  EXPECT_EQ(read_text(out / "report.md").rfind("> **This diagnosis failed** after 1 selected effect(s)", 0), 0u);
  EXPECT_EQ(read_text(out / "fitted.toml").rfind("# pneufem diagnose FAILED (diagnose: injected failure", 0), 0u);
  EXPECT_TRUE(fs::exists(out / "diagnosis.csv"));
  EXPECT_TRUE(fs::exists(out / "calibration.csv"));
}

TEST(HiddenEffect, NoneGivesNoMissingEffect) {
  const DiagnosisResult r = diagnose("none");
  EXPECT_EQ(r.missing_effect, "");
  EXPECT_TRUE(r.selected.empty());
}

// Tolerances on the recovered constants: the reduced model reproduces uniform softening and
// viscoelasticity within ~1 % of the angle (test_path_model), so stiffness, viscoelastic and lag
// constants come back within ~10-30 % (the noise and the controller overshoot limit them too).
TEST(HiddenEffect, Stiffness) {
  const DiagnosisResult r = diagnose("stiffness");
  EXPECT_EQ(r.missing_effect, "stiffness");
  EXPECT_LT(r.final_nrmse, 1.5 * r.noise_floor_nrmse + 0.005);
  EXPECT_NEAR(param(r, "scale"), candidate_effect("stiffness").params[0].truth, 0.05);
}

TEST(HiddenEffect, Viscoelastic) {
  const DiagnosisResult r = diagnose("viscoelastic");
  EXPECT_EQ(r.missing_effect, "viscoelastic");
  // Measured: final 0.023 with a floor of 0.013. The remainder is the reduced model's own error
  // for creep under the overshooting inlet (~1 % of the angle range), hence 2x floor + 0.005.
  EXPECT_LT(r.final_nrmse, 2.0 * r.noise_floor_nrmse + 0.005);
  const CandidateEffect& c = candidate_effect("viscoelastic");
  // gamma and tau trade off (a larger, slower term looks alike over 4 s holds): gamma within 50 %,
  // tau within 30 % (measured 0.60 vs 0.5 and 3.28 s vs 4 s; 0.68 and 3.4 s before the reduced
  // model's path became a spline, 2026-11-26).
  EXPECT_NEAR(param(r, c.params[0].name), c.params[0].truth, 0.5 * c.params[0].truth);
  EXPECT_NEAR(param(r, c.params[1].name), c.params[1].truth, 0.3 * c.params[1].truth);
}

TEST(HiddenEffect, PressureLag) {
  const DiagnosisResult r = diagnose("pressure_lag");
  EXPECT_EQ(r.missing_effect, "pressure_lag");
  EXPECT_LT(r.final_nrmse, 1.5 * r.noise_floor_nrmse + 0.005);
  const CandidateEffect& c = candidate_effect("pressure_lag");
  EXPECT_NEAR(param(r, c.params[0].name), c.params[0].truth, 0.2 * c.params[0].truth);
}

// A recording whose angle is counted the other way (the bend's sign reversed) is a convention, not
// a missing effect: diagnose says so and stops before fitting any candidate to it.
TEST(Diagnose, ARecordingInTheOppositeSignConventionStopsWithTheFix) {
  Recording rec = read_measurements_csv(data("none"));
  for (TrialRecording& t : rec.trials)
    for (double& v : t.angle_deg.value) v = -v;
  const fs::path dir = fs::temp_directory_path() / "pneufem_diag_negated";
  fs::remove_all(dir);
  fs::create_directories(dir);
  write_measurements_csv((dir / "data.csv").string(), rec);
  DiagnoseOptions o;
  o.data_path = (dir / "data.csv").string();
  o.out_dir = (dir / "out").string();
  o.cache_dir = shared_cache();
  try {
    run_diagnosis(Scene::load("", kScene), o);
    ADD_FAILURE() << "diagnose ran on negated angles";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("runs opposite to the model's"), std::string::npos) << what;
    EXPECT_NE(what.find("negate angle_deg. diagnose stops here"), std::string::npos) << what;
  }
  EXPECT_FALSE(fs::exists(dir / "out" / "diagnosis.json"));
  fs::remove_all(dir);
}

TEST(HiddenEffect, Gravity) {
  const DiagnosisResult r = diagnose("gravity");
  EXPECT_EQ(r.missing_effect, "gravity");
  EXPECT_LT(r.final_nrmse, 1.5 * r.noise_floor_nrmse + 0.005);
  const CandidateEffect& c = candidate_effect("gravity");
  EXPECT_NEAR(param(r, c.params[0].name), c.params[0].truth, 20.0);
  // The rig angle is calibrated on FEM curves interpolated over the angle (five sweeps); the
  // reported RSS is the FEM sweep's at the calibrated angle. At the optimum the residual is the
  // noise, so an interpolation error that mattered would show as a gap between the two; 2 % of the
  // RSS is an angle error below 0.15 x the noise's rms (sqrt(0.02)), invisible in the ranking.
  const CandidateResult& g = r.candidates.front();
  double best = INFINITY;
  for (const CalibrationPoint& p : g.trace) best = std::min(best, p.rss_deg2);
  std::printf("gravity: interpolated RSS %.6g, FEM RSS %.6g deg^2\n", best, g.rss_deg2);
  EXPECT_NEAR(best, g.rss_deg2, 0.02 * g.rss_deg2);
}

// Round 2 on top of gravity with a history effect: the reduced model cannot carry gravity, so it
// adds the elastic FEM's gravity offset. Without it (before 2026-11-23) round-2 viscoelastic lost
// the gravity and scored like the baseline (NRMSE 0.1365 vs 0.0108). A calibrated viscoelastic
// term can only help or do nothing on gravity-only data, so round 2 must stay within the noise of
// round 1: 10 % of the NRMSE (the offset superposition neglects the creep's change of the sag).
// A deck of the hidden-effect actuator turned about a skew axis, with no angle keys (the frame comes
// from the mesh): hidden gravity at the rig angle 90 deg (horizontal, fabric side down, in the
// actuator's frame) is found with its angle. The gravity candidate sets the rig angle in that frame;
// a vector in the built-in actuator's coordinates would pull the tilted deck sideways. Measured
// with all candidates and three trials: 89.1 deg at the noise floor; here one trial, two candidates
// (the test's budget); 5 deg is ~3x the spread of the calibrated angle under the tracking noise.
TEST(HiddenEffect, GravityOnATiltedDeckIsFoundInTheActuatorsFrame) {
  const fs::path dir = fs::temp_directory_path() / "pneufem_diag_tilted";
  fs::remove_all(dir);
  fs::create_directories(dir);
  Mesh mesh = build_mesh(Scene::load("", {"geometry.chambers=5", "mesh.h_mm=6.0", "mesh.half=false"}));
  const Eigen::Matrix3d R = Eigen::AngleAxisd(1.1, Eigen::Vector3d(0.3, -0.5, 0.8).normalized()).toRotationMatrix();
  for (Eigen::Vector3d& x : mesh.X) x = R * x;
  {
    std::ofstream deck(dir / "tilted.inp");
    write_inp_mesh(deck, mesh, 1e-3);
  }
  const std::vector<std::string> scene = {"mesh.source=\"inp\"", "mesh.file=\"" + (dir / "tilted.inp").string() + "\"",
                                          "load.max_kPa=30.0", "load.step_kPa=10.0", "load.hold_s=4.0", "load.trials=1"};
  SynthOptions so;
  so.sets = scene;
  so.hidden = {"gravity"};
  so.out_csv = (dir / "data.csv").string();
  so.seed = 7;
  so.pressure_rate_Hz = 200.0;
  so.angle_noise_deg = 0.05;
  run_synth(so);
  DiagnoseOptions o;
  o.data_path = so.out_csv;
  o.out_dir = (dir / "diagnosis").string();
  o.candidates = {"stiffness", "gravity"};
  o.max_effects = 1;
  const DiagnosisResult r = run_diagnosis(Scene::load("", scene), o);
  EXPECT_EQ(r.missing_effect, "gravity");
  EXPECT_NEAR(param(r, "rig_angle_deg"), 90.0, 5.0);
  EXPECT_LT(r.final_nrmse, 1.5 * r.noise_floor_nrmse + 0.005);
  EXPECT_GT(r.baseline_nrmse, 5.0 * r.final_nrmse);  // the weight matters on this actuator: a real test
}

TEST(HiddenEffect, GravityIsKeptUnderHistoryEffects) {
  DiagnoseOptions o = hidden_options("gravity", "gravity_visco", 2, {"gravity", "viscoelastic"});
  o.stop_at_noise_floor = false;  // round 1 reaches the floor; this test is about round 2
  const DiagnosisResult r = run_diagnosis(Scene::load("", kScene), o);
  ASSERT_EQ(r.missing_effect, "gravity");
  double g1 = NAN, v2 = NAN;
  for (const CandidateResult& c : r.candidates) {
    if (c.round == 1 && c.effect == "gravity") g1 = c.nrmse;
    if (c.round == 2 && c.effect == "viscoelastic") v2 = c.nrmse;
  }
  std::printf("round 1 gravity NRMSE %.4f, round 2 viscoelastic on top %.4f\n", g1, v2);
  EXPECT_LT(v2, 1.1 * g1);
}

// The forward selection stops once round 1 has brought the residual within min_gain_of_floor
// (10 %) of the noise floor: a second effect could then pass the gain test only by fitting below
// the floor. Hidden stiffness is explained to 0.0159 against a floor of 0.0156 (measured), so round
// 2 is skipped and says why; hidden creep leaves 0.0232 against 0.0128 with the reduced model, so
// round 2 still runs there.
TEST(HiddenEffect, ForwardSelectionStopsAtTheNoiseFloor) {
  auto run = [](const std::string& name, std::vector<std::string> cands) {
    return run_diagnosis(Scene::load("", kScene), hidden_options(name, "stop_" + name, 2, std::move(cands)));
  };
  auto rounds = [](const DiagnosisResult& r) {
    int m = 0;
    for (const CandidateResult& c : r.candidates) m = std::max(m, c.round);
    return m;
  };
  const DiagnosisResult s = run("stiffness", {"stiffness", "pressure_lag"});
  ASSERT_EQ(s.missing_effect, "stiffness");
  ASSERT_LT(s.final_nrmse, 1.1 * s.noise_floor_nrmse);  // the premise of the stop
  EXPECT_EQ(rounds(s), 1);
  EXPECT_NE(s.stopped.find("noise floor"), std::string::npos) << s.stopped;
  std::ifstream js(fs::temp_directory_path() / "pneufem_diag_stop_stiffness" / "diagnosis.json");
  const std::string json((std::istreambuf_iterator<char>(js)), std::istreambuf_iterator<char>());
  EXPECT_NE(json.find("\"stopped\": \"after round 1"), std::string::npos);
  const DiagnosisResult v = run("viscoelastic", {"viscoelastic", "pressure_lag", "mullins", "gravity"});
  ASSERT_EQ(v.missing_effect, "viscoelastic");
  ASSERT_GE(v.final_nrmse, 1.1 * v.noise_floor_nrmse);
  EXPECT_EQ(rounds(v), 2);
  EXPECT_TRUE(v.stopped.empty()) << v.stopped;
  // Round 2 and its stand-ins. What is left after viscoelastic (0.0232 vs a floor of 0.0128) is
  // the reduced model's small error for creep, ~3/4 of it static. Gravity passes the raw tests on
  // it (measured: delta AIC -209, removes 51 % of the excess) but removes nothing beyond a static
  // misfit, and Mullins, calibrated beyond it, too little (0.0160 -> 0.0155): neither is added.
  // Before the static test both were significant, and Mullins was selected (at r = 1.1, its bound).
  EXPECT_EQ(v.selected, std::vector<std::string>{"viscoelastic"});
  EXPECT_EQ(v.missing_history_effect, "viscoelastic");
  EXPECT_EQ(s.missing_history_effect, "");  // stiffness is not a history effect
  for (const CandidateResult& c : v.candidates) {
    if (c.round != 2) continue;
    EXPECT_FALSE(c.significant) << c.effect << ": " << c.why;
    if (c.effect == "gravity") {
      EXPECT_LE(c.delta_aic, -10.0);
      EXPECT_GE(c.removed, 0.25);
      EXPECT_FALSE(c.beyond_static);
      EXPECT_NE(c.why.find("Not selected: after the first effect"), std::string::npos) << c.why;
    }
  }
  EXPECT_GT(v.static_share, 0.5);
  EXPECT_LT(v.final_nrmse_beyond_static, v.final_nrmse);
  EXPECT_NE(v.static_note.find("gravity (NRMSE"), std::string::npos) << v.static_note;
  // ... and diagnosis.json carries them (README schema).
  std::ifstream vj(fs::temp_directory_path() / "pneufem_diag_stop_viscoelastic" / "diagnosis.json");
  const std::string vjson((std::istreambuf_iterator<char>(vj)), std::istreambuf_iterator<char>());
  EXPECT_NE(vjson.find("\"static_remainder\": {"), std::string::npos);
  EXPECT_NE(vjson.find("\"share_of_excess\": "), std::string::npos);
  EXPECT_NE(vjson.find("\"beyond_static\": false"), std::string::npos);
  EXPECT_NE(vjson.find("\"nrmse_beyond_static\": "), std::string::npos);
  EXPECT_NE(vjson.find("\"missing_history_effect\": \"viscoelastic\""), std::string::npos);
}

// --trust-elastic-model restores the raw tests from round 2 on: on the same data gravity, which
// passes them, is then added (the option is for a model whose elastic response is known).
TEST(HiddenEffect, TrustingTheElasticModelLetsAStaticEffectFollow) {
  DiagnoseOptions o = hidden_options("viscoelastic", "trust", 2, {"viscoelastic", "gravity"});
  o.trust_elastic_model = true;
  const DiagnosisResult r = run_diagnosis(Scene::load("", kScene), o);
  EXPECT_EQ(r.selected, (std::vector<std::string>{"viscoelastic", "gravity"}));
}

TEST(HiddenEffect, Mullins) {
  const DiagnosisResult r = diagnose("mullins");
  EXPECT_EQ(r.missing_effect, "mullins");
  // Measured final 0.0102 vs floor 0.0095 (r 2.86 vs 3, m 0.0043 vs 0.001 MPa): the reduced model's
  // shape error for damage localised in the walls (test_path_model) biases the constants, and r
  // and m trade off (a smaller r with a larger m softens alike), so r within 1.0 and m to an order
  // of magnitude; --refine corrects them with the FEM (too costly for CI; BENCHMARKS.md).
  EXPECT_LT(r.final_nrmse, 1.5 * r.noise_floor_nrmse + 0.005);
  EXPECT_NEAR(param(r, "r"), 3.0, 1.0);
  EXPECT_NEAR(std::log10(param(r, "m_MPa")), std::log10(0.001), 1.0);
}

// The refinement with the reduced-order model (--refine 2, the reduced model by default) on the
// hidden Mullins recording: the path model's constants (measured r 2.81, m 0.0048 MPa) fit it with
// the path model, but the full FEM - the model that made the recording - at those constants is far
// off (measured NRMSE 0.0455 at a floor of 0.0095): the path model misjudges damage localised in the
// walls. Two refinements on the reduced model with softened equilibria (solver.reduced_softened_levels
// = 6: right on this h = 6 mesh, off by default because of the default h = 2 mesh, docs/theory.md)
// move them to where the FEM fits (measured 0.0130, r 2.46, m 0.0020 MPa, with the offline part built
// for the protocol's peak, 33 kPa; 0.0106 with it built for this recording's 32.6 kPa: near the limit
// point the reduced model's error depends on where its path is sampled, bench/results/rom_h2_story/
// near_limit.md; the truth's own FEM NRMSE is 0.0098; with the default basis 0.0190). r and m trade off along a valley the
// three trials do not close (HiddenEffect.Mullins), so the constants themselves are not asserted;
// the FEM's fit is, by the FEM itself (an independent run, not the reduced model): under 1.5x the
// floor (the reduced model's 0.1-0.3 deg error on this case, of the order of the noise, and the
// 0.0106-0.0130 spread above) and under half the path constants' error.
TEST(DiagnoseRefinement, TheReducedModelMovesMullinsConstantsToWhereTheFemFits) {
  DiagnoseOptions o = hidden_options("mullins", "refine_mullins", 1, {"mullins"});
  o.refine = 2;
  const Scene scene = Scene::load("", kScene).with({"solver.reduced_softened_levels=6"});
  const DiagnosisResult r = run_diagnosis(scene, o);
  ASSERT_EQ(r.selected, std::vector<std::string>{"mullins"});
  EXPECT_EQ(r.refined_model, "reduced");
  ASSERT_EQ(r.refined_params.size(), 1u);
  ASSERT_EQ(r.refined_nrmse_per_trial.size(), 3u);
  const Recording rec = read_measurements_csv(data("mullins"));
  auto fem_nrmse = [&](const std::vector<double>& v) {
    const CandidateEffect& c = candidate_effect("mullins");
    std::vector<Series> model;
    for (TrialTrace& t : simulate_recording(scene.with(c.sets(scene, v)), rec, DriveOptions{}).trials)
      model.push_back(std::move(t.angle_deg));
    return compare_recording(rec, model).nrmse;
  };
  const double path = fem_nrmse(r.candidates.front().params), refined = fem_nrmse(r.refined_params[0]);
  std::printf("full FEM NRMSE: path-model constants %.4f, refined %.4f (r %.3f, m %.4g MPa); floor %.4f\n", path, refined,
              r.refined_params[0][0], r.refined_params[0][1], r.noise_floor_nrmse);
  EXPECT_LT(refined, 1.5 * r.noise_floor_nrmse);
  EXPECT_LT(refined, 0.5 * path);
  // The report and history carry the refined model's error per trial.
  std::ifstream hist(fs::path(o.out_dir) / "history.jsonl");
  const std::string h((std::istreambuf_iterator<char>(hist)), std::istreambuf_iterator<char>());
  EXPECT_NE(h.find("diagnose, refined (reduced-order model)"), std::string::npos) << h;
}

// Fatigue (W_th = 8 kPa, tau = 200 s, energy driver) softens the interior walls over the trials.
// Like Mullins it is damage localised in the walls, which the reduced model overestimates ~2x
// (test_path_model); here that leaves more of the error (measured final 0.0154, floor 0.0084),
// hence 2x the floor + 0.005. The two constants trade off (a lower threshold with a slower rate
// looks alike over three trials): along that valley the reduced model's RSS is 12.0 deg^2 at the
// fit (W_th 4.2 kPa, tau 953 s), 13.7 at the truth and 11.8 at W_th's lower bound with tau 2 200 s,
// so where the calibration stops along it is set by the reduced model's own error, not by the
// data. What the data do fix is the valley: the reported trade-off ranges (RSS within 25 %;
// measured W_th 3.0-9.7 kPa, tau 100-2 424 s) must hold the truth, and must exclude most of the
// catalog's box (tau up to 1e5 s, W_th up to 0.1 MPa), or they would prove nothing.
// Re-measured with fatigue_saturating in the catalog (2026-11-29, branch diag2; the law at n = 6,
// effect_catalog.cpp): fatigue first, 0.0418 -> 0.0157 at a 0.0084 floor, W_th 3.0 kPa (the valley's
// flat end, its lower bound, now flagged as such), tau 2 721 s, ranges W_th 3.0-11.0 kPa, tau
// 100-2 721 s (the truth inside); fatigue_saturating second, 0.0180 (W_th 3.0 kPa, tau 1 614 s): on
// this n = 1 truth the non-saturating form is named, as it must be. 82 s of one core at load 5.
TEST(HiddenEffect, Fatigue) {
  const DiagnosisResult r = diagnose("fatigue");
  EXPECT_EQ(r.missing_effect, "fatigue");
  EXPECT_LT(r.final_nrmse, 2.0 * r.noise_floor_nrmse + 0.005);
  EXPECT_LT(r.final_nrmse, 0.5 * r.baseline_nrmse);
  EXPECT_NEAR(std::log10(param(r, "W_th_MPa")), std::log10(0.008), std::log10(3.0));
  const auto c = std::find_if(r.candidates.begin(), r.candidates.end(),
                              [](const CandidateResult& x) { return x.effect == "fatigue" && x.round == 1; });
  ASSERT_NE(c, r.candidates.end());
  ASSERT_EQ(c->trade_lo.size(), 2u);
  EXPECT_LE(c->trade_lo[0], 0.008);
  EXPECT_GE(c->trade_hi[0], 0.008);
  EXPECT_LE(c->trade_lo[1], 200.0);
  EXPECT_GE(c->trade_hi[1], 200.0);
  EXPECT_LT(c->trade_hi[0], 0.03);
  EXPECT_LT(c->trade_hi[1], 1e4);
  EXPECT_NE(c->why.find("They trade off"), std::string::npos) << c->why;
}

// Two hidden effects at once, as in the paper's recordings: creep in every hold (viscoelastic,
// gamma 0.5, tau 4 s) and fatigue growing over the trials (W_th 4 kPa, tau 200 s: with the Prony
// term this actuator is stiffer and its walls store less energy, and at the fatigue dataset's 8 kPa
// the fatigue moved the angle by < 0.07 deg in three trials, the tracking noise; at 4 kPa by
// 0.77 deg in trial 3). Round 1 must name the creep (it explains most: measured NRMSE 0.154 ->
// 0.040), round 2 the fatigue beyond it (-> 0.0167 at a 0.0107 floor), not Mullins, the other wall
// damage, which stops growing after the first peak. Candidates: these three and the static stand-in;
// gravity and lag are not in question here and cost half the run. Bounds: the final error as in
// HiddenEffect.Fatigue (2x the floor + 0.005: the reduced model's wall-damage error); the fatigue
// threshold within 2x of the truth (measured 4.05 kPa; 5.24 kPa, tau 136 s, re-measured 2026-11-29
// on branch diag2, final 0.0163 at a 0.0107 floor, 212 s at load 5); its tau is not asserted, it trades off
// with the threshold (HiddenEffect.Fatigue).
TEST(HiddenEffect, CreepAndFatigueTogetherAreBothFound) {
  const DiagnosisResult r = run_diagnosis(
      Scene::load("", kScene),
      hidden_options("viscoelastic_fatigue", "visco_fatigue", 2, {"stiffness", "viscoelastic", "mullins", "fatigue"}));
  std::printf("baseline %.4f, floor %.4f, final %.4f; selected:", r.baseline_nrmse, r.noise_floor_nrmse, r.final_nrmse);
  for (const std::string& s : r.selected) std::printf(" %s", s.c_str());
  std::printf("\n");
  ASSERT_EQ(r.selected, (std::vector<std::string>{"viscoelastic", "fatigue"}));
  EXPECT_EQ(r.missing_effect, "viscoelastic");
  EXPECT_LT(r.final_nrmse, 2.0 * r.noise_floor_nrmse + 0.005);
  EXPECT_GT(r.baseline_nrmse, 5.0 * r.final_nrmse);
  const auto f = std::find_if(r.candidates.begin(), r.candidates.end(),
                              [](const CandidateResult& c) { return c.effect == "fatigue" && c.round == 2; });
  ASSERT_NE(f, r.candidates.end());
  std::printf("fatigue: W_th %.4g MPa, tau %.4g s (truth 0.004, 200)\n", f->params[0], f->params[1]);
  // Round 2's reasons read the residual the creep left, not the baseline's: the growth over the
  // trials they quote is another. Before the fix (2026-11-29) round 2's fatigue quoted the
  // baseline's "the error falls from trial 1 to the last trial (rms 0.80 -> 0.62 deg)"; now it
  // quotes what the creep left, "the error grows from trial 1 to the last trial (rms 0.13 -> 0.26
  // deg)", the fatigue's signature (the numbers are printed, the difference asserted).
  const auto f1 = std::find_if(r.candidates.begin(), r.candidates.end(),
                               [](const CandidateResult& c) { return c.effect == "fatigue" && c.round == 1; });
  ASSERT_NE(f1, r.candidates.end());
  const auto growth = [](const std::string& why) {
    const std::size_t a = why.find("Residual signature: "), b = why.find(" deg)", a);
    return a == std::string::npos || b == std::string::npos ? std::string() : why.substr(a, b - a);
  };
  std::printf("round 1: %s\nround 2: %s\n", growth(f1->why).c_str(), growth(f->why).c_str());
  EXPECT_FALSE(growth(f->why).empty());
  EXPECT_NE(growth(f1->why), growth(f->why));
  EXPECT_NEAR(std::log10(f->params[0]), std::log10(0.004), std::log10(2.0));
  // Issue 35 item 3: after each round, the joint intervals of every constant selected so far (the
  // fit within 25 % of its RSS, the other constants re-adjusting). Each holds its value and has a
  // width; diagnosis.json and report.md carry them. They are intervals of the path model's
  // constants: measured here, the truth lies outside three of the four (gamma 0.57-0.72 vs 0.5,
  // tau 2.6-3.7 s vs 4, W_th 0.0045-0.0060 vs 0.004 MPa; fatigue's tau 100-207 s holds 200), the
  // path model's bias against the FEM that made the recording (docs/theory.md, "Uncertainty of
  // the constants"), so the truth is printed, not asserted.
  ASSERT_EQ(r.intervals.size(), 2u);
  EXPECT_EQ(r.intervals[0].constants.size(), 2u);
  const RoundIntervals& last = r.intervals.back();
  ASSERT_TRUE(last.computed);
  ASSERT_EQ(last.constants.size(), 4u);
  const std::map<std::string, double> truth = {
      {"viscoelastic.gamma", 0.5}, {"viscoelastic.tau_s", 4.0}, {"fatigue.W_th_MPa", 0.004}, {"fatigue.tau_s", 200.0}};
  for (const ConstantInterval& c : last.constants) {
    const std::string key = c.effect + "." + c.name;
    std::printf("interval %s: %.4g (%.4g to %.4g)%s, truth %.4g\n", key.c_str(), c.value, c.lo, c.hi,
                c.identified ? "" : " not identified", truth.at(key));
    EXPECT_LE(c.lo, c.value) << key;
    EXPECT_GE(c.hi, c.value) << key;
    EXPECT_GT(c.hi, c.lo) << key;
  }
  const std::string json = read_text(fs::temp_directory_path() / "pneufem_diag_visco_fatigue" / "diagnosis.json");
  EXPECT_NE(json.find("\"intervals\""), std::string::npos);
  EXPECT_NE(json.find("\"identified\""), std::string::npos);
  EXPECT_NE(read_text(fs::temp_directory_path() / "pneufem_diag_visco_fatigue" / "report.md").find("Joint intervals"), std::string::npos);
}

// The swap of forms after a round (try_other_forms, bench/notes/2026-11-29-diag4.md), end to end.
// The recording hides fatigue WITHOUT saturation (n = 1, W_th 8 kPa, tau 200 s) beside a small
// instantaneous creep (gamma 0.1, tau 2 s). Alone in round 1 the saturating form fits best: its fast
// early damage (tau from 10 s, the knee at tau/(5 g)) stands in for the creep's rise within the first
// holds. Once the creep is in the model (round 2) the joint re-fit prefers n = 1, the form the
// recording was made with, and the fatigue's form is swapped: a greedy selection alone would keep
// fatigue_saturating. Measured (2026-11-29, branch diag4): baseline 0.1126 (floor 0.0063); round 1
// fatigue_saturating 0.0271, fatigue 0.0325, creep 0.0378; after round 1 fatigue in its place 93.5
// against 65.1 deg^2 (kept); round 2 the creep (0.0209); then "round 2: fatigue replaced
// fatigue_saturating", RSS 38.64 -> 20.91 deg^2 (NRMSE 0.0154); fatigue W_th 7.9 kPa, tau 34 s,
// creep gamma 0.054, tau 1.7 s. 93 s CPU of one thread with the elastic path traced (an empty
// cache; 79 s with it cached). Without the swap, form_changes is empty and fatigue_saturating stays
// selected.
TEST(HiddenEffect, AFormPreferredInRoundOneIsSwappedWhenALaterEffectJoins) {
  DiagnoseOptions o = hidden_options("viscoelastic_instantaneous_fatigue", "form_swap", 2,
                                     {"viscoelastic_instantaneous", "fatigue", "fatigue_saturating"});
  o.intervals = false;  // not under test here (DiagnoseIntervals, CreepAndFatigueTogetherAreBothFound)
  const DiagnosisResult r = run_diagnosis(Scene::load("", kScene), o);
  std::printf("baseline %.4f, floor %.4f, final %.4f; selected:", r.baseline_nrmse, r.noise_floor_nrmse, r.final_nrmse);
  for (const std::string& s : r.selected) std::printf(" %s", s.c_str());
  std::printf("\n");
  for (const std::string& f : r.form_changes) std::printf("form changed: %s\n", f.c_str());
  const auto in_round = [&](int round, const std::string& name) {
    const auto c = std::find_if(r.candidates.begin(), r.candidates.end(),
                                [&](const CandidateResult& x) { return x.round == round && x.effect == name; });
    EXPECT_NE(c, r.candidates.end()) << name << " in round " << round;
    return c == r.candidates.end() ? CandidateResult{} : *c;
  };
  // Round 1 preferred the saturating form (the candidates of a round are ranked, the best first) ...
  ASSERT_FALSE(r.candidates.empty());
  EXPECT_EQ(r.candidates.front().round, 1);
  EXPECT_EQ(r.candidates.front().effect, "fatigue_saturating");
  EXPECT_TRUE(r.candidates.front().significant);
  EXPECT_LT(in_round(1, "fatigue_saturating").nrmse, in_round(1, "fatigue").nrmse);
  // ... round 2 added the creep, and its joint re-fit preferred n = 1: the form was swapped, in the
  // result, in diagnosis.json and in report.md.
  EXPECT_TRUE(in_round(2, "viscoelastic_instantaneous").significant);
  ASSERT_EQ(r.selected, (std::vector<std::string>{"fatigue", "viscoelastic_instantaneous"}));
  EXPECT_EQ(r.missing_effect, "fatigue");
  ASSERT_EQ(r.form_changes.size(), 1u);
  const std::string change = "round 2: fatigue replaced fatigue_saturating";
  EXPECT_EQ(r.form_changes[0].rfind(change, 0), 0u) << r.form_changes[0];
  const fs::path out = fs::temp_directory_path() / "pneufem_diag_form_swap";
  EXPECT_NE(read_text(out / "diagnosis.json").find("\"form_changes\": [\"" + change), std::string::npos);
  EXPECT_NE(read_text(out / "report.md").find("Form changed: " + change), std::string::npos);
  // The swap lowered the error of the model round 2 had selected (measured 0.0209 -> 0.0154).
  EXPECT_LT(r.final_nrmse, in_round(2, "viscoelastic_instantaneous").nrmse);
}

// A later round's joint re-fit that moves an earlier constant outside the interval it had is
// said in words (DiagnosisResult::interval_notes); inside it, nothing is said.
TEST(DiagnoseIntervals, AConstantMovedOutsideItsIntervalIsNamed) {
  RoundIntervals one;
  one.round = 1, one.computed = true, one.rss_tol = 0.25;
  one.constants = {{"fatigue", "W_th_MPa", 0.0061, 0.004, 0.009, true}, {"fatigue", "tau_s", 3.0e4, 1.0e4, 5.0e4, true}};
  RoundIntervals two = one;
  two.round = 2;
  two.constants[0].value = 0.041;  // outside 0.004 ... 0.009
  two.constants[1].value = 2.0e4;  // inside
  two.constants.push_back({"viscoelastic", "gamma", 0.3, 0.2, 0.4, true});
  const std::vector<std::string> notes = moved_outside_intervals(one, two);
  ASSERT_EQ(notes.size(), 1u);
  EXPECT_NE(notes[0].find("round 2 moved fatigue.W_th_MPa from 0.0061 to 0.041, outside its interval after round 1 (0.004 to 0.009)"),
            std::string::npos)
      << notes[0];
  one.computed = false;  // no interval, no claim
  EXPECT_TRUE(moved_outside_intervals(one, two).empty());
}

}  // namespace
}  // namespace pneufem
