// `pneufem synth` (app/synth/command.h): the data read back in the canonical format, the step detector finds
// the commanded levels, noise and outliers follow the settings, a seed fixes the file (for any
// thread count), and a hidden pressure lag makes the noise-free angle lag the control's.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <sstream>

#include <gtest/gtest.h>

#include "analysis/measurements.h"
#include "analysis/steps.h"
#include "app/diagnose/effect_catalog.h"
#include "app/synth/command.h"
#include "core/errors.h"
#include "core/json_writer.h"
#include "scenes/build_model.h"
#include "tests/app/cli_helpers.h"
#include "tests/support/input_error.h"

namespace pneufem {
namespace {

namespace fs = std::filesystem;

// 3 chambers at 6 mm, levels 0, 5, 10 kPa held 4 s, 2 trials: ~150 solved states. Linear tets (8x
// cheaper here than tet10, ~1 s per run): they lock, so the angles are small (0.05 deg at 10 kPa),
// but these tests check the data pipeline, not the physics, and compare angles relative to each other.
const std::vector<std::string> kSmall = {"geometry.chambers=3", "mesh.h_mm=6.0", "mesh.element=tet4", "load.max_kPa=10",
                                         "load.step_kPa=5",     "load.hold_s=4", "load.trials=2",
                                         "load.mark_s=2.5"};

fs::path dir() {
  const fs::path d = fs::temp_directory_path() / "pneufem_test_synth";
  fs::create_directories(d);
  return d;
}

using pneufem::test::slurp;

using pneufem::test::error_of;

SynthOptions options(const std::string& name, std::vector<std::string> hidden) {
  SynthOptions o;
  o.sets = kSmall;
  o.hidden = std::move(hidden);
  o.out_csv = (dir() / name).string();
  o.seed = 42;
  return o;
}

// ctest runs every TEST in its own process, so each test makes the runs it needs; the control
// dataset (5 % outliers so their count is measurable on 722 frames) is checked in one test.
TEST(Synth, ControlDatasetReadsBackWithTheCommandedStepsNoiseAndOutliers) {
  SynthOptions o = options("control.csv", {"none"});
  o.outlier_fraction = 0.05;
  o.threads = 1;
  const SynthResult r = run_synth(o);
  const Recording rec = read_measurements_csv((dir() / "control.csv").string());
  ASSERT_EQ(rec.trials.size(), 2u);
  for (const TrialRecording& t : rec.trials) {
    EXPECT_EQ(t.pressure_kPa.t_s.size(), 12u * 400u + 1u);  // 0..12 s at 400 Hz
    EXPECT_EQ(t.angle_deg.t_s.size(), 12u * 30u + 1u);       // 0..12 s at 30 fps
    EXPECT_EQ(t.pressure_kPa.t_s.front(), 0.0);               // time restarts each trial
  }
  EXPECT_EQ(rec.trials[1].angle_deg.value, r.data.trials[1].angle_deg.value);  // bit-for-bit round trip
  EXPECT_TRUE(fs::exists(dir() / "control.truth.csv"));
  const std::string json = slurp(dir() / "control.truth.json");
  for (const char* key : {"\"seed\": 42", "\"hidden\": []", "\"pressure_noise_kPa\": 0.1", "\"scene\"", "\"pneufem_version\""})
    EXPECT_NE(json.find(key), std::string::npos) << key;
  // The step detector finds 0, 5, 10 kPa: its level is a median over half a plateau (~800 samples
  // of 0.1 kPa noise, after the 2 % settling of the overshoot, 1 s): within 0.05 kPa.
  for (const TrialSteps& ts : detect_steps(rec)) {
    ASSERT_EQ(ts.detection.steps.size(), 3u) << "trial " << ts.trial;
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(ts.detection.steps[k].level_kPa, 5.0 * k, 0.05);
    // The second-order rise starts with zero slope, which the detector places slightly late.
    EXPECT_NEAR(ts.detection.steps[1].t_start_s, 4.0, 0.1);
  }
  // Pressure noise: residual of the 400 Hz samples against the closed-form inlet. Sample std of
  // n = 9602 Gaussian values has relative standard error 1/sqrt(2n) = 0.7 %: 4 % is > 5 sigma.
  double ss = 0.0;
  long n = 0;
  for (const TrialRecording& t : r.data.trials)
    for (std::size_t i = 0; i < t.pressure_kPa.t_s.size(); ++i) {
      const double tt = t.pressure_kPa.t_s[i];
      const double p = controller_pressure_kPa({4.0, 8.0}, {5.0, 5.0}, 1.0, 0.65, tt);
      ss += std::pow(t.pressure_kPa.value[i] - p, 2);
      ++n;
    }
  EXPECT_NEAR(std::sqrt(ss / n), 0.1, 0.004);
  // Angle: outliers jump >= 10 deg, the noise is 0.3 deg (a 5 deg cut is 16 sigma): the frames off
  // the truth by > 5 deg are exactly the outliers; the others carry the 0.3 deg noise: their sample
  // std over n ~ 690 frames has relative standard error 1/sqrt(2n) = 2.7 %, so 10 % is 3.7 sigma.
  int outliers = 0;
  double sa = 0.0;
  long na = 0;
  for (std::size_t k = 0; k < r.data.trials.size(); ++k)
    for (std::size_t j = 0; j < r.data.trials[k].angle_deg.value.size(); ++j) {
      const double d = r.data.trials[k].angle_deg.value[j] - r.truth.trials[k].angle_deg.value[j];
      if (std::abs(d) > 5.0) {
        ++outliers;
        EXPECT_LE(std::abs(d), 40.0 + 5 * 0.3);
      } else {
        sa += d * d;
        ++na;
      }
    }
  EXPECT_EQ(outliers, r.outliers);
  // Binomial(722, 0.05): mean 36.1, sd 5.9; 4 sd either side.
  EXPECT_GE(outliers, 13);
  EXPECT_LE(outliers, 60);
  EXPECT_NEAR(std::sqrt(sa / na), 0.3, 0.03);
  // The noise-free angle is a bend (0.05 deg for these locking tets at 10 kPa), not zero.
  EXPECT_GT(r.truth.trials[0].angle_deg.value.back(), 0.02);
}

TEST(Synth, SameSeedSameFileForAnyThreadCount) {
  // A short single-step record keeps the two runs cheap.
  auto run = [](const std::string& name, int threads, std::uint64_t seed) {
    SynthOptions o = options(name, {"stiffness"});
    o.sets.insert(o.sets.end(), {"load.trials=1", "load.max_kPa=5", "load.hold_s=2", "load.mark_s=1"});
    o.threads = threads;
    o.seed = seed;
    o.outlier_fraction = 0.05;
    run_synth(o);
    return slurp(dir() / name) + slurp(dir() / (fs::path(name).stem().string() + ".truth.csv"));
  };
  const std::string one = run("seed_1thread.csv", 1, 7);
  EXPECT_EQ(run("seed_2threads.csv", 2, 7), one);
  EXPECT_NE(run("seed_other.csv", 1, 8), one);
}

// A chamber lagging by tau = 0.5 s: just after each step the angle is behind the control's (the
// chamber has reached 1 - e^-1 of the step 0.5 s after the command), at the end of each hold it has
// caught up (e^-(4 - 0.3)/0.5 = 6e-4 of the step's angle change left).
TEST(Synth, HiddenPressureLagDelaysTheAngle) {
  auto run = [](const std::string& name, const std::string& hidden) {
    SynthOptions o = options(name, {hidden});
    o.sets.push_back("load.trials=1");
    o.threads = 1;
    return run_synth(o);
  };
  const SynthResult c = run("nolag.csv", "none"), lag = run("lag.csv", "pressure_lag");
  EXPECT_NE(slurp(dir() / "lag.truth.json").find("load.pressure_lag_s=0.5"), std::string::npos);
  const Series& a0 = c.truth.trials[0].angle_deg;
  const Series& a1 = lag.truth.trials[0].angle_deg;
  const double step_angle = value_at(a0, 7.9) - value_at(a0, 3.9);
  ASSERT_GT(step_angle, 0.01);  // 0.025 deg per 5 kPa step here
  for (double t_step : {4.0, 8.0}) {
    EXPECT_LT(value_at(a1, t_step + 0.5), value_at(a0, t_step + 0.5) - 0.2 * step_angle) << t_step;
    EXPECT_NEAR(value_at(a1, t_step + 3.9), value_at(a0, t_step + 3.9), 2e-3 * step_angle) << t_step;
  }
}

// truth.json records the constants the simulation used: a --set that overrides a hidden effect's
// scalar constant replaces the catalog's truth, one that overrides a derived key (gravity's angle
// becomes a vector) makes it unknown (null) rather than wrong.
TEST(Synth, TruthRecordsOverriddenConstants) {
  SynthOptions o = options("override.csv", {"fatigue", "gravity"});
  o.sets.insert(o.sets.end(), {"load.trials=1", "load.max_kPa=5", "load.hold_s=2", "load.mark_s=1",
                               "materials.silicone.fatigue.tau_s=300.0", "gravity.g_m_s2=[0.0, 0.0, -9.81]"});
  o.threads = 1;
  run_synth(o);
  const std::string j = slurp(dir() / "override.truth.json");
  const CandidateEffect& f = candidate_effect("fatigue");
  ASSERT_EQ(f.params[1].name, "tau_s");
  ASSERT_NE(f.params[1].truth, 300.0);
  EXPECT_NE(j.find("\"tau_s\": 300"), std::string::npos) << j;
  EXPECT_NE(j.find("\"W_th_MPa\": " + json::num(f.params[0].truth)), std::string::npos) << j;
  EXPECT_NE(j.find("\"" + candidate_effect("gravity").params[0].name + "\": null"), std::string::npos) << j;
  // ... and its "sets" are the overrides as applied: the --set, not the catalog's value it replaced.
  EXPECT_NE(j.find("\"materials.silicone.fatigue.tau_s=300.0\""), std::string::npos) << j;
  EXPECT_EQ(j.find("\"materials.silicone.fatigue.tau_s=" + json::num(f.params[1].truth) + "\""), std::string::npos) << j;
}

TEST(Synth, BadHiddenNameListsTheCandidates) {
  const std::string e = error_of([] { parse_hidden("stiffness,creep"); });
  EXPECT_NE(e.find("unknown candidate effect 'creep'"), std::string::npos) << e;
  EXPECT_NE(e.find("pressure_lag"), std::string::npos) << e;
  EXPECT_NE(error_of([] { parse_hidden("none,stiffness"); }).find("'none' cannot be combined"), std::string::npos);
  EXPECT_NE(error_of([] { parse_hidden("gravity,gravity"); }).find("twice"), std::string::npos);
  EXPECT_EQ(parse_hidden("none"), std::vector<std::string>{});
  EXPECT_EQ(parse_hidden("stiffness, gravity"), (std::vector<std::string>{"stiffness", "gravity"}));
  SynthOptions o = options("bad.csv", {});
  o.controller_damping = 1.2;
  EXPECT_NE(error_of([&] { run_synth(o); }).find("--controller-damping"), std::string::npos);
}

// The command line: a tiny run writes the three files and a bad --hidden exits with code 2 listing
// the candidates.
TEST(Synth, CommandLine) {
  auto run = [](const std::string& args) {
    const test::CliResult r = test::run_cli("synth " + args);
    return std::make_pair(r.code, r.out);
  };
  const auto [code, out] = run("--hidden creep --out " + (dir() / "cli.csv").string());
  EXPECT_EQ(code, 2) << out;
  EXPECT_NE(out.find("unknown candidate effect 'creep'; valid: stiffness"), std::string::npos) << out;
  fs::remove(dir() / "cli_ok.truth.json");
  std::string args = "--hidden stiffness --threads 1 --outliers 0 --out " + (dir() / "cli_ok.csv").string();
  for (const std::string& s : kSmall) args += " --set " + s;
  args += " --set load.trials=1 --set load.max_kPa=5 --set load.hold_s=2 --set load.mark_s=1";
  const auto [code_ok, out_ok] = run(args);
  EXPECT_EQ(code_ok, 0) << out_ok;
  EXPECT_NE(slurp(dir() / "cli_ok.truth.json").find("materials.silicone.stiffness_scale=1.3"), std::string::npos);
}

// The commanded steps come from the scene's staircase as every command builds it (inlet_load):
// one step per level change at the step starts, whatever the report settings.
TEST(Synth, CommandedStepsAreTheScenesStaircase) {
  for (const char* every : {"load.output_every_s=0.0", "load.output_every_s=1.0"}) {
    std::vector<std::string> sets = kSmall;
    sets.push_back(every);
    const LoadHistory load = inlet_load(Scene::load("", sets));
    ASSERT_EQ(load.trials.size(), 2u);
    for (const TrialLoad& t : load.trials) {
      const CommandedSteps c = commanded_steps(t);
      EXPECT_EQ(c.t_s, (std::vector<double>{4.0, 8.0})) << every;
      EXPECT_EQ(c.jump_kPa, (std::vector<double>{5.0, 5.0})) << every;
    }
  }
}

}  // namespace
}  // namespace pneufem
