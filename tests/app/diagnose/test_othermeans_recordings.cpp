// pneufem diagnose on recordings made by OTHER MEANS than pneufem's laws (issue 35, items 4 and 5):
// tests/data/othermeans/make_recordings.py starts from the small actuator's elastic angle-pressure
// curve (scenes/examples/small_actuator.toml, a static `pneufem simulate` sweep, or another mesh's
// or geometry's) and applies the hidden effects at the STRUCTURE level, in forms that are not
// pneufem's constitutive laws: creep as Fung's quasi-linear viscoelasticity of the angle with a
// stretched-exponential or power-law creep function (the elastic curve is the instantaneous
// response), fatigue as a compliance growing as a power or a logarithm of a load-weighted cycle
// count, Mullins as a softer reload below the previous peak pressure, a first- or second-order
// (under-damped) lag of the chamber pressure behind the inlet sensor; a regulator with overshoot,
// 100-500 Hz pressure, 30 fps angles with noise and outlier frames; 3 to 10 trials of different
// peaks, steps and holds (README.md beside the recordings lists each one).
//
// Each diagnosis runs the whole catalog. Asserted, as the issue asks: every hidden effect is named
// (creep in either moduli convention), nothing else is, and the error after the selection is at
// most 0.4x the baseline's; the recordings with a static misfit only name nothing.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "app/diagnose/command.h"
#include "scenes/scene.h"

namespace fs = std::filesystem;

namespace pneufem {
namespace {

// The actuator the recordings belong to (scenes/examples/small_actuator.toml). The recordings
// carry their own pressure, which drives the model; the scene's [load] only sets the elastic
// path's reach, which diagnose extends to the recording's peak.
const std::vector<std::string> kScene = {"geometry.chambers=5", "mesh.h_mm=6.0",  "load.max_kPa=30.0",
                                         "load.step_kPa=10.0",  "load.hold_s=4.0", "load.trials=3"};

DiagnosisResult diagnose(const std::string& name) {
  DiagnoseOptions o;
  o.data_path = std::string(PNEUFEM_TEST_DATA_DIR) + "/othermeans/" + name + ".csv";
  o.out_dir = (fs::temp_directory_path() / ("pneufem_diag_othermeans_" + name)).string();
  fs::remove_all(o.out_dir);
  o.cache_dir = (fs::temp_directory_path() / "pneufem_diagnose_cache").string();  // shared elastic work
  const auto t0 = std::chrono::steady_clock::now();
  const DiagnosisResult r = run_diagnosis(Scene::load("", kScene), o);
  std::printf("%s: baseline %.4f, floor %.4f, final %.4f (%.2fx); selected:", name.c_str(), r.baseline_nrmse,
              r.noise_floor_nrmse, r.final_nrmse, r.final_nrmse / r.baseline_nrmse);
  for (const std::string& s : r.selected) std::printf(" %s", s.c_str());
  std::printf("; %.1f s\n", std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  for (const CandidateResult& c : r.candidates) {
    std::printf("  round %d %-27s NRMSE %.4f beyond static %.4f dAIC %8.1f%s", c.round, c.effect.c_str(), c.nrmse,
                c.nrmse_beyond_static, c.delta_aic, c.significant ? " sig" : "");
    for (std::size_t i = 0; i < c.params.size(); ++i) std::printf(" %s=%.4g", c.param_names[i].c_str(), c.params[i]);
    std::printf("\n");
  }
  return r;
}

/// The catalog's names for a hidden effect of the generator.
std::set<std::string> names_of(const std::string& hidden) {
  if (hidden == "creep") return {"viscoelastic", "viscoelastic_instantaneous"};
  if (hidden == "lag") return {"pressure_lag"};
  return {hidden};
}

/// Every hidden effect named, nothing else, and the error after the selection <= 0.4x the baseline.
void expect_found(const DiagnosisResult& r, const std::vector<std::string>& hidden) {
  std::set<std::string> allowed;
  for (const std::string& h : hidden) {
    const std::set<std::string> names = names_of(h);
    allowed.insert(names.begin(), names.end());
    EXPECT_TRUE(std::any_of(r.selected.begin(), r.selected.end(), [&](const std::string& s) { return names.count(s) > 0; }))
        << "hidden " << h << " not named";
  }
  for (const std::string& s : r.selected) EXPECT_TRUE(allowed.count(s) > 0) << "spurious: " << s;
  EXPECT_LE(r.final_nrmse, 0.4 * r.baseline_nrmse);
}


// Item 5: one hidden effect each.
TEST(OtherMeansRecording, StretchedExponentialCreepIsNamed) { expect_found(diagnose("creep_kww"), {"creep"}); }
TEST(OtherMeansRecording, PowerLawCreepIsNamed) { expect_found(diagnose("creep_powerlaw"), {"creep"}); }
TEST(OtherMeansRecording, PowerLawFatigueOverTenTrialsIsNamed) { expect_found(diagnose("fatigue_powerlaw"), {"fatigue"}); }
TEST(OtherMeansRecording, LogarithmicFatigueIsNamed) { expect_found(diagnose("fatigue_log"), {"fatigue"}); }
TEST(OtherMeansRecording, SofterReloadBelowThePeakIsMullins) { expect_found(diagnose("mullins_reload"), {"mullins"}); }
TEST(OtherMeansRecording, FirstOrderLagIsNamed) { expect_found(diagnose("lag_first_order"), {"lag"}); }
TEST(OtherMeansRecording, UnderDampedSecondOrderLagIsNamed) { expect_found(diagnose("lag_second_order"), {"lag"}); }

// Item 5: two and three effects together.
TEST(OtherMeansRecording, CreepAndFatigueOverTenTrialsAreBothNamed) {
  expect_found(diagnose("creep_fatigue"), {"creep", "fatigue"});
}
TEST(OtherMeansRecording, MullinsAndLagAreBothNamed) { expect_found(diagnose("mullins_lag"), {"mullins", "lag"}); }
TEST(OtherMeansRecording, CreepFatigueAndLagAreAllNamed) {
  expect_found(diagnose("creep_fatigue_lag"), {"creep", "fatigue", "lag"});
}

// Item 4: a static misfit only names nothing.
TEST(OtherMeansNull, TwoPercentSofterSiliconeNamesNothing) {
  EXPECT_TRUE(diagnose("null_stiffness_2pc").selected.empty());
}
TEST(OtherMeansNull, ThreePercentStifferSiliconeNamesNothing) {
  EXPECT_TRUE(diagnose("null_stiffness_3pc_stiffer").selected.empty());
}
TEST(OtherMeansNull, ThickerInteriorWallsNameNothing) { EXPECT_TRUE(diagnose("null_geometry_wall").selected.empty()); }
TEST(OtherMeansNull, AnotherMeshsCurveNamesNoHistoryEffect) {
  const DiagnosisResult r = diagnose("null_mesh_h4");
  EXPECT_TRUE(r.missing_history_effect.empty()) << r.missing_history_effect;
}

}  // namespace
}  // namespace pneufem
