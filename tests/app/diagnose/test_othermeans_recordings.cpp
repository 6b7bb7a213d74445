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
// (creep in either moduli convention, fatigue with or without saturation), nothing else is, and the
// error after the selection is at most 0.4x the baseline's; the recordings with a static misfit only
// name nothing.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <limits>
#include <set>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "app/diagnose/command.h"
#include "scenes/scene.h"
#include "tests/app/diagnose/run_and_print.h"

namespace fs = std::filesystem;

namespace pneufem {
namespace {

// The actuator the recordings belong to (scenes/examples/small_actuator.toml). The recordings
// carry their own pressure, which drives the model; the scene's [load] only sets the elastic
// path's reach, which diagnose extends to the recording's peak.
const std::vector<std::string> kScene = {"geometry.chambers=5", "mesh.h_mm=6.0",  "load.max_kPa=30.0",
                                         "load.step_kPa=10.0",  "load.hold_s=4.0", "load.trials=3"};

DiagnosisResult diagnose(const std::string& name, std::vector<std::string> candidates = {}, int max_effects = 4,
                         const std::function<void(DiagnoseOptions&)>& adjust = {}) {
  DiagnoseOptions o;
  o.candidates = std::move(candidates);
  o.max_effects = max_effects;
  o.data_path = std::string(PNEUFEM_TEST_DATA_DIR) + "/othermeans/" + name + ".csv";
  o.out_dir = (fs::temp_directory_path() / ("pneufem_diag_othermeans_" + name)).string();
  fs::remove_all(o.out_dir);
  o.cache_dir = (fs::temp_directory_path() / "pneufem_diagnose_cache").string();  // shared elastic work
  if (adjust) adjust(o);
  return test::run_and_print_diagnosis(name, kScene, o);
}

/// The catalog's names for a hidden effect of the generator.
std::set<std::string> names_of(const std::string& hidden) {
  if (hidden == "creep") return {"viscoelastic", "viscoelastic_instantaneous", "viscoelastic_broad"};  // one or three terms
  if (hidden == "lag") return {"pressure_lag"};
  if (hidden == "fatigue") return {"fatigue", "fatigue_saturating", "fatigue_uniform"};  // any of its three forms
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


// ---- Item 4: a static misfit only (CI: the stiffness candidate alone, the one a static misfit is taken for).
//
// A 2 % softer and a 3 % stiffer silicone pass all three fit tests as `stiffness`, with the truth's
// constants (measured: NRMSE 0.0246 -> 0.0052 at a 0.0053 floor, delta AIC -6387, scale 0.980 for
// the truth's 1/1.02 = 0.980; 0.0345 -> 0.0228 at a 0.0232 floor, scale 1.031 for 1/0.97 = 1.031):
// real, well-fitted changes, but ones an elastic model is expected to be off by. They are rejected by
// their size (min_static_change: they move the angle by < 5 % of the range, RMS), which is what this
// test checks; before min_static_change both were named. Walls 0.2 mm thicker (a 0.3-0.7 % angle
// change) fail the gain test already (0.0105 -> 0.0103). 34 s of one core (with the elastic path).
TEST(OtherMeansNull, SmallStaticMisfitsNameNothing) {
  for (const std::string name : {"null_stiffness_3pc_stiffer", "null_stiffness_2pc", "null_geometry_wall"}) {
    const DiagnosisResult r = diagnose(name, {"stiffness"}, 1);
    EXPECT_TRUE(r.selected.empty()) << name << ": " << r.missing_effect;
    ASSERT_EQ(r.candidates.size(), 1u);
    EXPECT_GE(r.candidates[0].static_change_nrmse, 0.0);
    EXPECT_LT(r.candidates[0].static_change_nrmse, 0.05) << name;
    // A static misfit grows nothing over the trials: the growth split is not significant (measured
    // 0.4, 1.3, 1.1 standard errors), so the growth round has nothing to act on.
    EXPECT_FALSE(r.baseline_growth.significant) << name << ": " << r.baseline_growth.difference_deg << " +- "
                                                << r.baseline_growth.difference_se_deg;
    EXPECT_TRUE(r.growth_note.empty()) << name << ": " << r.growth_note;
  }
}

// The same 2 % softer silicone against instantaneous creep, which can stand in for it: a Prony term
// at its smallest gamma and tau relaxes within 0.2 s of every step, a uniformly softer silicone. With
// the whole catalog (2026-11-29, before the fix) viscoelastic_instantaneous was named, at gamma 0.021
// and tau 0.2 s (both at their lower bounds), NRMSE 0.0246 -> 0.0063 raw but 0.0052 -> 0.0063 beyond
// a static misfit, after stiffness had been rejected by its size; 963 s. A history effect that
// explains nothing beyond a static misfit and fits no better than the static effect rejected by its
// size stands in for that misfit (reject_static_stand_ins).
TEST(OtherMeansNull, CreepThatOnlyStandsInForAStaticMisfitIsNotNamed) {
  const DiagnosisResult r = diagnose("null_stiffness_2pc", {"stiffness", "viscoelastic_instantaneous"}, 1);
  EXPECT_TRUE(r.selected.empty()) << r.missing_effect;
  const auto creep = std::find_if(r.candidates.begin(), r.candidates.end(),
                                  [](const CandidateResult& c) { return c.effect == "viscoelastic_instantaneous"; });
  ASSERT_NE(creep, r.candidates.end());
  EXPECT_FALSE(creep->beyond_static);
  EXPECT_GE(creep->nrmse, r.candidates.front().nrmse);  // stiffness, rejected by its size, fits as well or better
  EXPECT_NE(creep->why.find("stands in for that small static misfit"), std::string::npos) << creep->why;
}

// A 15 % larger angle (the h = 4 mesh's curve, diagnosed on h = 6) is no longer within an elastic
// model's accuracy: stiffness is named (measured: scale 0.905, NRMSE 0.1045 -> 0.0151, 0.0081 beyond
// a static misfit at a 0.0080 floor: what is left is the curve's shape, static) and the note says the
// rest is static. The null of the issue ("another mesh's curve: nothing named") holds for a mesh as
// close as the walls above; for this one the model IS off, and saying so is the finding.
TEST(OtherMeansNull, AnotherMeshsCurveIsNamedAsStiffnessWithTheRestStatic) {
  const DiagnosisResult r = diagnose("null_mesh_h4", {"stiffness"}, 1);
  ASSERT_EQ(r.selected, std::vector<std::string>{"stiffness"});
  EXPECT_GT(r.candidates[0].static_change_nrmse, 0.05);
  EXPECT_GT(r.static_share, 0.9);
  // Ten trials of another mesh's curve: no growth over the trials, before or after (measured -0.01 +-
  // 0.01 deg, 0.7 and 0.6 standard errors).
  EXPECT_FALSE(r.baseline_growth.significant) << r.baseline_growth.difference_deg << " +- " << r.baseline_growth.difference_se_deg;
  EXPECT_FALSE(r.final_growth.significant) << r.final_growth.difference_deg << " +- " << r.final_growth.difference_se_deg;
}

// ---- The growth round (issue 35 item 2; app/diagnose/command.cpp, growth_round). The whole-RSS tests
// are made unpassable here (min_removed 0.999: no effect removes 99.9 % of the error above the floor),
// so only the growth round can name anything: on the logarithmic fatigue (eight trials; the baseline's
// top holds grow +0.20 deg against the rests' +0.05, top minus rest 11.9 standard errors) it must name
// fatigue_uniform, leave no significant split and lower the error; with --no-growth-round nothing is
// named; and on another mesh's curve (ten trials, no growth: 0.7 standard errors) it must not run.
TEST(OtherMeansRecording, TheGrowthRoundNamesAFatigueOnItsGrowthAlone) {
  const auto strict = [](DiagnoseOptions& o) { o.min_removed = 0.999, o.intervals = false; };
  const DiagnosisResult r = diagnose("fatigue_log", {"fatigue_uniform"}, 1, strict);
  ASSERT_EQ(r.selected, std::vector<std::string>{"fatigue_uniform"});
  EXPECT_TRUE(r.baseline_growth.significant);
  EXPECT_GT(r.baseline_growth.difference_deg, 0.0);
  EXPECT_FALSE(r.final_growth.significant) << r.final_growth.difference_deg << " +- " << r.final_growth.difference_se_deg;
  EXPECT_LT(r.final_nrmse, r.baseline_nrmse);
  ASSERT_EQ(r.candidates.size(), 2u);  // round 1's, not significant, and the growth round's
  EXPECT_FALSE(r.candidates[0].significant);
  EXPECT_NE(r.candidates[1].why.find("tried in the growth round"), std::string::npos) << r.candidates[1].why;
  const DiagnosisResult off = diagnose("fatigue_log", {"fatigue_uniform"}, 1, [&](DiagnoseOptions& o) {
    strict(o);
    o.growth_round = false;
  });
  EXPECT_TRUE(off.selected.empty());
  const DiagnosisResult null = diagnose("null_mesh_h4", {"fatigue_uniform"}, 1, strict);
  EXPECT_TRUE(null.selected.empty());
  EXPECT_EQ(null.candidates.size(), 1u);  // round 1 only: no growth round
}

// ---- Item 5 in CI: the first-order lag against the candidates that could stand in for it (a static
// misfit, creep in a hold, softening). Measured: pressure_lag named alone, NRMSE 0.1046 -> 0.0080
// (0.08x) at a 0.0082 floor, tau 0.396 s for the truth's 0.4 s (the regulator's overshoot is in the
// recorded inlet pressure, so the lag is seen behind it) and tau2 = 0 (first order: the candidate's
// second constant, free in [0, 1] s, stays at 0); round 2 skipped at the noise floor. 30 s of one
// core; 17 s on two threads with the two-constant lag (2026-11-27).
TEST(OtherMeansRecording, FirstOrderLagIsNamedWithItsTimeConstant) {
  const DiagnosisResult r = diagnose("lag_first_order", {"stiffness", "pressure_lag", "viscoelastic_instantaneous", "mullins"});
  expect_found(r, {"lag"});
  ASSERT_FALSE(r.candidates.empty());
  ASSERT_EQ(r.candidates.front().effect, "pressure_lag");
  EXPECT_NEAR(r.candidates.front().params.at(0), 0.4, 0.02);  // 5 %: the CalculiX recording's tolerance
  EXPECT_LE(r.candidates.front().params.at(1), 0.05);          // tau2: first order (measured 0)
}

// ---- Item 5: the whole catalog, as a user runs it. Too slow for CI on one core (a whole-catalog
// diagnosis of a 3-10 trial recording with two rounds: 3.5-15 min of one core, measured on a shared
// machine), except the second-order lag (one round, 100 s on two threads); run the others with
// --gtest_also_run_disabled_tests. Each comment gives what was measured (the CLI,
// `pneufem diagnose scenes/examples/small_actuator.toml --data tests/data/othermeans/NAME.csv`, the
// same run_diagnosis with the same defaults).

// Measured: viscoelastic_instantaneous alone, NRMSE 0.1162 -> 0.0192 (0.17x) at a 0.0075 floor; gamma
// 0.19, tau 3.8 s for a KWW creep g 0.35, tau 1.5 s, beta 0.6 (different laws: no like-for-like
// constants). Round 2 named nothing (Mullins and gravity passed raw tests only, not beyond the static
// misfit). 210 s of one core (with main's max_effects 2). Passes with the broad creep in the catalog
// (2026-11-29, 971 s of one thread at load 6; bench/notes/2026-11-29-diag3.md): the one-term creep named
// alone, 0.1162 -> 0.0192 (0.17x), the broad creep second in round 1 (0.0251, gamma 0.21, tau 2.0 s)
// and not swapped in; round 2 nothing (Mullins 0.0179, gravity 0.0185 not beyond the static misfit).
TEST(OtherMeansRecording, DISABLED_StretchedExponentialCreepIsNamed) { expect_found(diagnose("creep_kww"), {"creep"}); }
// Measured: viscoelastic_instantaneous alone, 0.1049 -> 0.0250 (0.24x), floor 0.0042; 319 s. Passes
// with the broad creep in the catalog (2026-11-29, 1 264 s of one thread at load 6): the same selection;
// the broad creep 0.0306 in round 1 (0.0149 beyond a static misfit against the one-term's 0.0157), with
// tau at its 30 s bound, and not swapped in; round 2 nothing (gravity 0.0230, stiffness 0.0243).
TEST(OtherMeansRecording, DISABLED_PowerLawCreepIsNamed) { expect_found(diagnose("creep_powerlaw"), {"creep"}); }
// Measured with the candidates stiffness, fatigue_saturating, fatigue_uniform (max 2; 2026-11-29,
// bench/notes/2026-11-29-diag6.md, 104 s CPU): fatigue_uniform named alone, 0.0386 -> 0.0165 at a 0.0129
// floor, 0.43x: FAILS the 0.4x bound by 0.03x (fatigue_saturating 0.0174, 0.45x, equally good); round 2
// stiffness dAIC +1.4. What is left is flat over the trials (0.09-0.13 deg), 19 % of it static.
TEST(OtherMeansRecording, DISABLED_PowerLawFatigueOverTenTrialsIsNamed) {
  expect_found(diagnose("fatigue_powerlaw"), {"fatigue"});
}
// Fatigue growing as the logarithm of a load-weighted cycle count (a third of it in trial 1), against
// fatigue in both forms and the static stand-in (what took part of it before). Before
// fatigue_saturating (2026-11-29) this FAILED the 0.4x bound only: fatigue (n = 1) named alone,
// NRMSE 0.0374 -> 0.0162 = 0.43x at a 0.0133 floor, because that law cannot slow down
// (bench/notes/2026-11-29-fatigue-saturation.md). Measured since (bench/notes/2026-11-29-diag2.md),
// with the candidates stiffness, fatigue, fatigue_saturating, viscoelastic_instantaneous, mullins
// (max 2): fatigue_saturating named alone, 0.0374 -> 0.0148 = 0.396x (W_th 6.1 kPa, tau 54 s), fatigue
// 0.0162 reported as equally good (RSS within 25 %: the recording, 1.1x the floor after either, does
// not tell the two forms apart by the tests' standard), round 2 nothing (stiffness 0.0148 fails the
// gain test; Mullins and creep at bounds); 190 s of one core at load 5. Here with three candidates:
// the 0.4x bound is the target (this effect is small: its baseline is 2.8x the floor).
TEST(OtherMeansRecording, LogarithmicFatigueIsNamedAsSaturatingFatigue) {
  const DiagnosisResult r = diagnose("fatigue_log", {"stiffness", "fatigue", "fatigue_saturating"}, 2);
  expect_found(r, {"fatigue"});
  ASSERT_EQ(r.selected, std::vector<std::string>{"fatigue_saturating"});
  const auto first = [&](const std::string& name) {
    const auto c = std::find_if(r.candidates.begin(), r.candidates.end(),
                                [&](const CandidateResult& x) { return x.effect == name && x.round == 1; });
    EXPECT_NE(c, r.candidates.end()) << name;
    return c == r.candidates.end() ? std::numeric_limits<double>::infinity() : c->nrmse;
  };
  EXPECT_LT(first("fatigue_saturating"), first("fatigue"));  // the law that slows down fits better
}
// The uniform form of fatigue (damage/fatigue_uniform.h: the whole loaded silicone softens with a
// load-weighted count, where the two threshold forms damage its most strained points) beside the
// saturating one, with every round run (no stop at the noise floor). Measured (2026-11-29, bench/notes/
// 2026-11-29-diag6.md, the CLI with stiffness too, max 2): fatigue_uniform 0.0374 -> 0.0146 (0.39x) at a
// 0.0133 floor (a 0.101, t0 30 s), fatigue_saturating 0.0148 reported as equally good; 66 s CPU.
// Asserted: one fatigue is named and the other form is not stacked on it in round 2 (it is a form of
// the same effect: tried in its place, try_other_forms; before diag6 a form in another scene table
// would have been calibrated on top of it), and the error is within the 0.4x.
TEST(OtherMeansRecording, LogarithmicFatigueIsNamedOnceInOneOfItsForms) {
  DiagnoseOptions o;
  o.candidates = {"fatigue_saturating", "fatigue_uniform"};
  o.max_effects = 2;
  o.stop_at_noise_floor = false;
  o.data_path = std::string(PNEUFEM_TEST_DATA_DIR) + "/othermeans/fatigue_log.csv";
  o.out_dir = (fs::temp_directory_path() / "pneufem_diag_othermeans_fatigue_log_forms").string();
  fs::remove_all(o.out_dir);
  o.cache_dir = (fs::temp_directory_path() / "pneufem_diagnose_cache").string();
  const DiagnosisResult r = test::run_and_print_diagnosis("fatigue_log (forms)", kScene, o);
  expect_found(r, {"fatigue"});
  EXPECT_EQ(r.selected.size(), 1u);
  for (const CandidateResult& c : r.candidates) EXPECT_EQ(c.round, 1) << c.effect << " tried in round " << c.round;
}
// The whole catalog (measured with five candidates above).
TEST(OtherMeansRecording, DISABLED_LogarithmicFatigueIsNamed) { expect_found(diagnose("fatigue_log"), {"fatigue"}); }
// Measured with the candidates stiffness, mullins, viscoelastic_instantaneous, fatigue (max 2):
// mullins alone, NRMSE 0.0353 -> 0.0087 (0.25x) at a 0.0077 floor (r 1.1, its bound: the reload
// softening of this recording is larger at low pressure than Ogden-Roxburgh's with any r); creep
// and fatigue also passed round 1 but with constants at their bounds, and nothing passed round 2.
// 73 s of one core.
TEST(OtherMeansRecording, DISABLED_SofterReloadBelowThePeakIsMullins) {
  expect_found(diagnose("mullins_reload"), {"mullins"});
}
// The CI test FirstOrderLagIsNamedWithItsTimeConstant runs this recording on four candidates.
// Measured with the whole catalog and the two-constant lag (2026-11-27): pressure_lag alone, NRMSE
// 0.1046 -> 0.0080 (0.08x) at a 0.0082 floor, tau 0.396 s, tau2 0; round 2 skipped at the noise
// floor. 75 s on two threads.
TEST(OtherMeansRecording, DISABLED_FirstOrderLagIsNamed) { expect_found(diagnose("lag_first_order"), {"lag"}); }
// In CI (the whole catalog, 100 s on two threads): the second-order lag. Named as pressure_lag with
// tau2 > tau/2 (under-damped), its natural frequency 1/(2 pi tau2) and damping tau/(2 tau2) those of
// the truth's chamber (f_n 0.6 Hz, zeta 0.45). Measured (2026-11-27): pressure_lag named alone, NRMSE
// 0.0939 -> 0.0091 (0.10x) at a 0.0092 floor, tau 0.2378 s, tau2 0.2632 s: f_n 0.605 Hz, zeta 0.452
// (truth tau 0.2387 s, tau2 0.2653 s); round 2 skipped at the noise floor. With the first-order lag
// of the catalog before it (tau 0.35 s) the error left was 0.0386, 0.41x: an under-damped chamber
// overshoots each step, which no first-order filter of the inlet can.
TEST(OtherMeansRecording, UnderDampedSecondOrderLagIsNamedWithItsFrequencyAndDamping) {
  const DiagnosisResult r = diagnose("lag_second_order");
  expect_found(r, {"lag"});
  ASSERT_FALSE(r.candidates.empty());
  const CandidateResult& c = r.candidates.front();
  ASSERT_EQ(c.effect, "pressure_lag");
  ASSERT_EQ(c.params.size(), 2u);
  const double tau = c.params[0], tau2 = c.params[1];
  EXPECT_NEAR(1.0 / (2.0 * M_PI * tau2), 0.6, 0.03);  // 5 %, as the first-order lag's tau
  EXPECT_NEAR(tau / (2.0 * tau2), 0.45, 0.045);       // 10 %: noise and the regulator seen through the lag
  EXPECT_NE(c.why.find("under-damped"), std::string::npos) << c.why;  // and the diagnosis says so
}
// Incomplete measurement (whole catalog, max_effects 4; over 75 min of wall time on a shared machine,
// not finished by the deadline): creep was selected in round 1 in the instantaneous convention
// (round 2's long-term candidate was refused as switching it), most likely fatigue in round 2 (the
// lowest error beyond a static misfit: 37 deg^2 against Mullins' 53), and round 3 selected a third
// effect, since round 4 ran: spurious unless it was neither Mullins, stiffness, lag nor gravity.
// Measured with the candidates one-term and broad creep, fatigue_uniform (max 3; 2026-11-30,
// bench/notes/2026-11-30-diag8.md, 332 s CPU): the broad creep alone, 0.1422 -> 0.0188; its residual's
// top holds grow +0.27 +- 0.02 deg beyond the rests (12.1 standard errors), and the growth round's
// fatigue_uniform takes that to +0.09 only with a = 0.5, its bound, and NRMSE 0.0202: not named. FAILS.
TEST(OtherMeansRecording, DISABLED_CreepAndFatigueOverTenTrialsAreBothNamed) {
  expect_found(diagnose("creep_fatigue"), {"creep", "fatigue"});
}
// Measured with the candidates stiffness, mullins, pressure_lag, viscoelastic_instantaneous (max 3):
// the lag in round 1 (NRMSE 0.0953 -> 0.0350), Mullins in round 2 (-> 0.0164 at a 0.0160 floor,
// 0.17x; r 1.71, m 0.044 MPa), the lag re-fitted jointly to tau 0.351 s (truth 0.35 s); round 3
// skipped at the noise floor. 115 s of one core. Measured again with the whole catalog and the
// two-constant lag (2026-11-27): the lag in round 1 (0.0953 -> 0.0339, tau 0.325 s, tau2 0.128 s:
// over-damped, taking part of the softening), Mullins in round 2 (-> 0.0163 at a 0.0160 floor,
// 0.17x; r 1.48, m 0.052 MPa) with the lag re-fitted jointly to tau 0.352 s, tau2 0: first order, as
// the truth. 296 s on two threads.
TEST(OtherMeansRecording, DISABLED_MullinsAndLagAreBothNamed) { expect_found(diagnose("mullins_lag"), {"mullins", "lag"}); }
// FAILS (measured 2026-11-27, whole catalog, max_effects 4): creep (viscoelastic_instantaneous) in
// round 1 (NRMSE 0.1534 -> 0.0771, floor 0.0059), the lag in round 2 (-> 0.0136, tau 0.31 s for the
// truth's 0.3; creep re-fitted jointly to gamma 0.35, tau 10.5 s), and round 3 names nothing: fatigue
// takes 0.0136 -> 0.0135 (delta AIC -0.5). Final 0.09x the baseline, nothing spurious, fatigue not
// found. The power-law creep of this recording (n 0.35) never recovers between trials, so it too
// drifts upward over the six trials; the long Prony term (tau 10.5 s, re-fitted in round 2) takes
// that drift, and the log-law fatigue's own growth (D 0.02 -> 0.05) is left below the tests. 813 s
// of one core. Measured again with the two-constant lag (2026-11-27): the same selection and
// errors (0.1534 -> 0.0771 -> 0.0136, 0.09x; fatigue in round 3 0.0136 -> 0.0135, delta AIC 0.8);
// the lag first order as the truth's (tau 0.311 s, tau2 0; re-fitted in round 3 to 0.310 s, 0);
// in round 1, alone under the creep, it had fitted tau 0.18 s, tau2 0.25 s. 927 s on two threads
// of a shared machine. Still FAILS: fatigue not found. Measured again with fatigue_saturating
// (2026-11-29, candidates stiffness, creep, lag and both fatigue forms, 941 s of one thread): the same
// rounds; round 3 fatigue 0.0136 -> 0.0135 (dAIC +0.8), fatigue_saturating 0.0136 (+1.5). The cause
// (bench/notes/2026-11-29-diag2.md): the same recording made without the fatigue leaves 0.0214 after
// creep and lag (gamma 0.26, tau 10.1 s; its error growing over the trials), this one 0.0136 (gamma
// 0.35, tau 10.6 s; none): the one-term creep, re-fitted, takes the fatigue's growth, and nothing is
// left for fatigue. A creep law that can follow a power-law creep is the fix, not looser tests.
// Since (2026-11-29, bench/notes/2026-11-29-diag3.md): the broad-spectrum creep viscoelastic_broad
// and the swap of forms after a round (try_other_forms). With the candidates stiffness, both
// instantaneous creeps, lag and both fatigues (max 4): round 1 one-term creep (RSS 655 deg^2; broad
// 680), round 2 the lag, then the broad creep replaced the one-term one (RSS 20.56 -> 20.1 deg^2 with
// the lag), and in round 3 fatigue's calibration beyond a static misfit reached 12.0 deg^2 (fatigue_saturating
// 12.0) against the model's raw 20.1 (its own RSS beyond a static misfit, which the tests compare, was
// not printed). The run did not reach round 3's tests: in a joint re-fit the process grew inside
// apply_pressure_lag (the chamber's pressure history; cause not verified, the note's section E) and was
// killed at 12 GB (another run by the OOM killer at 24 GB). Not run with the whole catalog (over 40 min).
// Re-run with the lag's breakpoints bounded (2026-11-29, bench/notes/2026-11-29-diag4.md; the same six
// candidates, 1 150 s CPU of one thread, 110 MB peak): the same rounds 1-2 and the same swap, and round
// 3 names nothing: fatigue 0.0135 (dAIC +3.9; 0.0105 beyond a static misfit against the model's 0.0104),
// fatigue_saturating the same, stiffness 0.0135. Final broad creep + lag, 0.1534 -> 0.0135 (0.09x).
// Still FAILS (fatigue not named), and the whole catalog costs ~1.5-2x that run: stays disabled.
// Why (bench/notes/2026-11-29-diag5.md): the generator's fatigue adds 0.27 -> 0.89 deg at the top
// holds over the six trials (tests/data/othermeans/components.py), and after rounds 1-2 the residual
// per trial is flat (0.08-0.12 deg): the broad creep took that growth with its slow end (re-fitted
// beside the lag to gamma 1.02, tau 25.9 s: a term of 259 s carrying 54 % of gamma, on a 72 s
// recording whose rests last 3 s, i.e. a softening growing with the time under load, as a damage).
// A second start of round 3's joint re-fit from the fatigue's round-1 constants (its frozen
// calibration ends where it does nothing) ended worse (29.1 against 20.2 deg^2) and was not kept.
// Measured with broad creep, lag, fatigue_saturating and stiffness (max 3): 917 s CPU, 111 MB.
// With fatigue_uniform (the whole silicone's compliance growing with a load-weighted count, the
// generator's kind of fatigue; bench/notes/2026-11-29-diag6.md): broad creep, lag, fatigue_uniform (max
// 3, 544 s CPU) give the same rounds and round 3 fatigue_uniform dAIC +3.9 at no damage (the creep's
// 259 s term again). With the creep's slowest term bounded by the recording (an experiment, not
// committed) the growth stays in the residual, and round 3's fatigue_uniform, re-fitted jointly on the
// raw RSS, ends at no damage and worse (0.0198 -> 0.0221). Still FAILS.
// Where the growth is (2026-11-29, bench/notes/2026-11-30-diag7.md; the growth split over trials 2-6 of
// measured - model at the top holds / at rest): the data +0.73 / +0.52 deg; after the broad creep and
// the lag -0.19 / -0.00 (the creep's slow terms grow the top ~2x the rests and take the fatigue's
// top-only growth); with the one-term creep instead (candidates viscoelastic_instantaneous, lag,
// fatigue_uniform) the same 0.0136 and +0.20 / +0.06 left, a fatigue's signature that the whole-RSS
// tests do not see (round 3 fatigue_uniform dAIC +1.7). Still FAILS; the lead is a test on the split.
// With that test (2026-11-30, bench/notes/2026-11-30-diag8.md): the split after creep and lag is +0.13
// +- 0.02 deg, 7.0 standard errors, and the growth round names fatigue_uniform (n_eff log RSS + z^2:
// -35.0; split left +0.07 +- 0.02, not significant): creep + lag + fatigue_uniform, 0.1534 -> 0.0137
// (0.089x), with the candidates one-term creep, lag, fatigue_uniform (692 s CPU) and with the broad
// creep too (the swap of forms counts the broad creep's negative split and keeps the one-term one;
// 962 s CPU). Not yet run with the whole catalog: stays disabled until it is.
TEST(OtherMeansRecording, DISABLED_CreepFatigueAndLagAreAllNamed) {
  expect_found(diagnose("creep_fatigue_lag"), {"creep", "fatigue", "lag"});
}
// Measured with the whole catalog (2026-11-29, one thread of a machine at load 8): null_geometry_wall
// names nothing (baseline 0.0105 at a 0.0098 floor; stiffness the best, 0.0103, dAIC -63, fails the
// gain test; every history candidate ends with a constant at a bound), 442 s. null_stiffness_2pc
// named viscoelastic_instantaneous (a stand-in: CreepThatOnlyStandsInForAStaticMisfitIsNotNamed
// above); after that fix nothing (creep 0.0063 and fatigue 0.0136 rejected as stand-ins for
// stiffness's 0.0052, which its size rejects), 213 s. null_stiffness_3pc_stiffer, after the fix,
// round 1: nothing (long-term creep 0.0245, dAIC -957, tau at its bound, rejected as a stand-in for
// stiffness's 0.0228), 279 s. null_mesh_h4 was not measured in time (the CI tests above run the stiffness
// candidate; GeneratedNull in test_othermeans_generated.cpp runs four candidates on a null generated
// in the test).
TEST(OtherMeansNull, DISABLED_StaticMisfitsNameNothingWithTheWholeCatalog) {
  for (const std::string name : {"null_stiffness_3pc_stiffer", "null_stiffness_2pc", "null_geometry_wall"})
    EXPECT_TRUE(diagnose(name).selected.empty()) << name;
  EXPECT_TRUE(diagnose("null_mesh_h4").missing_history_effect.empty());
}
}  // namespace
}  // namespace pneufem
