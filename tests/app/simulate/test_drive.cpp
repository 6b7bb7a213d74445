// Simulating a recording (app/simulate/drive.h): a recording made from the model itself (the scene's own
// staircase sampled like the rig, 400 Hz pressure and 30 fps frames) must reproduce the angles
// of a direct run of that staircase; sensor noise on the pressure may change them only within a
// bound derived from the denoising; results are bit-identical for 1 and 2 threads.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <random>

#include "analysis/steps.h"
#include "app/simulate/drive.h"
#include "core/errors.h"
#include "engine/assembly.h"
#include "scenes/build_model.h"
#include "scenes/pressure_lag.h"

namespace pneufem {
namespace {

/// A tiny elastic pneu-net: 3 chambers, coarse mesh, 0-10-20-30 kPa in 4 s holds, two trials.
Scene tiny_scene() {
  return Scene::load("", {"geometry.chambers=3", "mesh.h_mm=6", "load.max_kPa=30", "load.step_kPa=10", "load.hold_s=4",
                          "load.ramp_s=0.5", "load.trials=2", "output.vtu=\"none\""});
}

/// The scene's own staircase sampled at 400 Hz (pressure) and 30 fps (frames; angle 0), with
/// Gaussian noise of sigma_kPa on the pressure.
Recording sampled_staircase(const Scene& scene, double sigma_kPa, unsigned seed) {
  const std::unique_ptr<BuiltModel> bm = build_model(scene);
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  Recording rec;
  rec.source = "staircase";
  for (std::size_t k = 0; k < bm->load.trials.size(); ++k) {
    const TrialLoad& tl = bm->load.trials[k];
    TrialRecording tr;
    tr.trial = static_cast<int>(k + 1);
    for (long i = 0; i <= std::lround(tl.duration() * 400); ++i) {
      const double t = i / 400.0;
      tr.pressure_kPa.t_s.push_back(t);
      tr.pressure_kPa.value.push_back(tl.pressure(t) * 1e-3 + sigma_kPa * noise(rng));
    }
    for (long j = 0; j / 30.0 <= tl.duration(); ++j) {
      tr.angle_deg.t_s.push_back(j / 30.0);
      tr.angle_deg.value.push_back(0.0);
    }
    rec.trials.push_back(tr);
  }
  return rec;
}

struct Direct {
  std::vector<StateRecord> records;  ///< reports at each step's mark and end
};

Direct direct_run(const Scene& scene) {
  const std::unique_ptr<BuiltModel> bm = build_model(scene);
  const Assembler asmb(bm->model);
  QuasiStaticRun run(asmb, bm->solver.quasi_static);
  Direct d;
  run.run(bm->load, [&](const StateRecord& r, const Eigen::VectorXd&, const std::vector<double>&) { d.records.push_back(r); });
  return d;
}

// Shared, computed on first use: ctest runs every test in its own process, so a test that needs
// none of these pays nothing for them.
class DriveTest : public ::testing::Test {
 protected:
  static const Scene& scene() {
    static const Scene s = tiny_scene();
    return s;
  }
  static const Direct& direct() {
    static const Direct d = direct_run(scene());
    return d;
  }
  static const DriveResult& clean() {
    static const DriveResult r = [] {
      DriveOptions opt;
      opt.threads = 2;
      return simulate_recording(scene(), sampled_staircase(scene(), 0.0, 1), opt);
    }();
    return r;
  }
};

TEST_F(DriveTest, NoiseFreeRecordingReproducesTheDirectRun) {
  // Noise-free: the running median passes the monotone staircase unchanged and RDP keeps exactly
  // its corners, so both runs solve the same pressures; the model is elastic, so the angle at a
  // pressure does not depend on the path. What remains is the equilibrium tolerance (|R| <=
  // 1e-8 |f|) reached from different starting states; 1e-6 deg is ~1e-6 of the angles here and
  // far below anything a comparison with measurements resolves (observed: ~2e-14 deg).
  constexpr double kTol_deg = 1e-6;
  ASSERT_EQ(clean().trials.size(), 2u);
  for (const StateRecord& r : direct().records) {
    const TrialTrace& tt = clean().trials[static_cast<std::size_t>(r.trial - 1)];
    EXPECT_NEAR(value_at(tt.states_angle_deg, r.time_s), r.angle_deg, kTol_deg) << "trial " << r.trial << " t " << r.time_s;
  }
  // Model angle at every frame: same times as the frames; inside holds (after the ramp) it is
  // the level's angle.
  for (const TrialTrace& tt : clean().trials) {
    ASSERT_FALSE(tt.angle_deg.t_s.empty());
    for (std::size_t j = 0; j < tt.angle_deg.t_s.size(); ++j) {
      const double t = tt.angle_deg.t_s[j];
      const double in_step = std::fmod(t, 4.0);
      if (in_step < 0.6 || in_step > 3.9) continue;
      for (const StateRecord& r : direct().records) {
        if (r.trial == tt.trial && std::floor(r.time_s / 4.0 - 1e-9) == std::floor(t / 4.0)) {
          EXPECT_NEAR(tt.angle_deg.value[j], r.angle_deg, kTol_deg) << "frame at " << t;
        }
      }
    }
  }
  EXPECT_GT(std::abs(direct().records.back().angle_deg), 1.0) << "the actuator must bend for this test to mean anything";
}

// Angles alone (video of a commanded protocol): the scene's own staircase fills the pressure, so
// the drive must solve the same pressures as from the rig's noise-free pressure record and give
// the same angle at every frame. Same tolerance as above: two runs to the same equilibria.
TEST_F(DriveTest, AnglesAloneAreDrivenByTheScenesProtocol) {
  Recording rec = sampled_staircase(scene(), 0.0, 1);
  for (TrialRecording& tr : rec.trials) tr.pressure_kPa = Series{};
  rec.pressure_recorded = false;
  rec.warnings = {rec.source + ": no pressure column: only angles were recorded"};  // the reader's note: replaced
  // frames running 3 s past the protocol's trial end are noted (they see the last level held)
  rec.trials[1].angle_deg.t_s.push_back(rec.trials[1].angle_deg.t_s.back() + 3.0);
  rec.trials[1].angle_deg.value.push_back(0.0);
  fill_commanded_pressure(rec, scene());
  EXPECT_TRUE(rec.pressure_recorded);
  ASSERT_EQ(rec.warnings.size(), 2u);
  EXPECT_NE(rec.warnings[0].find("no pressure column: the model is driven by the scene's [load] (staircase 0-30 kPa"),
            std::string::npos) << rec.warnings[0];
  EXPECT_NE(rec.warnings[1].find("trial 2 has frames up to time_s = "), std::string::npos) << rec.warnings[1];
  const LoadHistory load = inlet_load(scene());
  for (const TrialRecording& tr : rec.trials) {
    ASSERT_GT(tr.pressure_kPa.t_s.size(), 3000u);  // 16 s at 200 Hz
    for (std::size_t i = 0; i < tr.pressure_kPa.t_s.size(); ++i)
      ASSERT_EQ(tr.pressure_kPa.value[i], load.trials[0].pressure(tr.pressure_kPa.t_s[i]) * 1e-3);
  }
  DriveOptions opt;
  opt.threads = 2;
  const DriveResult r = simulate_recording(scene(), rec, opt);
  ASSERT_EQ(r.trials.size(), clean().trials.size());
  for (std::size_t k = 0; k < r.trials.size(); ++k)
    for (std::size_t j = 0; j < clean().trials[k].angle_deg.t_s.size(); ++j)
      EXPECT_NEAR(r.trials[k].angle_deg.value[j], clean().trials[k].angle_deg.value[j], 1e-6) << "trial " << k + 1;
  EXPECT_GT(std::abs(r.trials[1].angle_deg.value.back()), 1.0);
  // A recording with pressure is left as it is.
  Recording measured = sampled_staircase(scene(), 0.1, 2);
  const Series before = measured.trials[0].pressure_kPa;
  fill_commanded_pressure(measured, scene());
  EXPECT_EQ(measured.trials[0].pressure_kPa.value, before.value);
  EXPECT_TRUE(measured.warnings.empty());
}

TEST_F(DriveTest, PressureNoiseChangesTheAnglesOnlyWithinTheDenoisingBound) {
  const double sigma = 0.2;  // kPa, a typical inlet sensor
  DriveOptions opt;
  opt.threads = 2;
  const DriveResult noisy = simulate_recording(scene(), sampled_staircase(scene(), sigma, 3), opt);
  // Pressure error of a hold: RDP keeps within `tol` of the running median, whose own error is
  // below 5 standard errors of a 21-sample median (1.2533 sigma / sqrt(21)). The angle error is
  // at most that times the steepest dtheta/dp, bounded by 1.5 x the largest secant slope between
  // levels (the curve's tangent stays within 50 % of its secant over one 5 kPa step).
  const double p_err = noisy.tolerance_kPa + 5 * 1.2533 * sigma / std::sqrt(21.0);
  double slope = 0;
  for (std::size_t i = 1; i < direct().records.size(); ++i) {
    const StateRecord &a = direct().records[i - 1], &b = direct().records[i];
    if (b.trial == a.trial && std::abs(b.pressure_Pa - a.pressure_Pa) > 1.0)
      slope = std::max(slope, std::abs(b.angle_deg - a.angle_deg) / (std::abs(b.pressure_Pa - a.pressure_Pa) * 1e-3));
  }
  ASSERT_GT(slope, 0.0);
  const double bound_deg = 1.5 * slope * p_err;
  for (const StateRecord& r : direct().records) {
    const TrialTrace& tt = noisy.trials[static_cast<std::size_t>(r.trial - 1)];
    EXPECT_NEAR(value_at(tt.states_angle_deg, r.time_s), r.angle_deg, bound_deg) << "t " << r.time_s;
  }
  // Noise must not become states: 400 Hz x 16 s of noise would be thousands.
  EXPECT_LE(noisy.states, 3 * clean().states + 20) << "clean " << clean().states;
}

TEST_F(DriveTest, BitIdenticalForOneAndTwoThreads) {
  DriveOptions one;
  one.threads = 1;
  const DriveResult r1 = simulate_recording(scene(), sampled_staircase(scene(), 0.0, 1), one);
  ASSERT_EQ(r1.trials.size(), clean().trials.size());
  for (std::size_t k = 0; k < r1.trials.size(); ++k) {
    EXPECT_EQ(r1.trials[k].angle_deg.value, clean().trials[k].angle_deg.value);
    EXPECT_EQ(r1.trials[k].states_angle_deg.value, clean().trials[k].states_angle_deg.value);
  }
}

TEST_F(DriveTest, ChamberPressureLagActsOnTheMeasuredInlet) {
  // With load.pressure_lag_s the solved states carry the chamber pressure, the exact first-order
  // response (scenes/pressure_lag.h) to the inlet: within the lag's 0.05 kPa breakpoint tolerance
  // plus rounding, also in the rise right after a step, where the inlet is 10 kPa away. The same
  // with load.pressure_lag2_s: the exact second-order response (under-damped, zeta 0.45).
  for (const PressureLag lag : {PressureLag{0.3, 0.0}, PressureLag{0.24, 0.265}}) {
    const Scene lagged = scene().with({"load.pressure_lag_s=" + std::to_string(lag.tau_s),
                                       "load.pressure_lag2_s=" + std::to_string(lag.tau2_s)});
    DriveOptions opt;
    opt.threads = 2;
    const DriveResult r = simulate_recording(lagged, sampled_staircase(scene(), 0.0, 1), opt);
    const std::unique_ptr<BuiltModel> bm = build_model(scene());  // the inlet staircase
    for (double t : {4.2, 4.5, 4.8, 5.5, 8.3, 9.0}) {
      const double exact_kPa = lagged_pressure(bm->load.trials[0], lag, t) * 1e-3;
      EXPECT_NEAR(value_at(r.trials[0].states_pressure_kPa, t), exact_kPa, 0.05 + 1e-9) << "t " << t << " tau2 " << lag.tau2_s;
    }
    EXPECT_GT(std::abs(lagged_pressure(bm->load.trials[0], lag, 4.5) - bm->load.trials[0].pressure(4.5)), 1e3)
        << "the lag must matter at the test times";
  }
}

// A run the FEM cannot finish (trial 2 drives the actuator far past its ballooning limit): by
// default the PhysicsError propagates (compare must not report half a run as a result); with
// partial_on_failure the frames solved before the failure keep their values, identical to a run
// that did not fail (same equilibria), and every later frame is NaN (diagnose --refine uses this).
TEST_F(DriveTest, PartialRunOnFailureKeepsTheSolvedFrames) {
  Recording rec = sampled_staircase(scene(), 0.0, 1);
  for (double& p : rec.trials[1].pressure_kPa.value) p *= 10.0;  // 0 ... 300 kPa
  const Scene s = scene().with({"solver.min_increment_kPa=0.5"});  // give up quickly at the limit
  DriveOptions opt;
  opt.threads = 2;
  EXPECT_THROW(simulate_recording(s, rec, opt), PhysicsError);
  opt.partial_on_failure = true;
  const DriveResult r = simulate_recording(s, rec, opt);
  EXPECT_FALSE(r.failure.empty());
  std::printf("stopped at t = %.3f s of trial 2: %s\n", r.failure_time_s, r.failure.c_str());
  ASSERT_EQ(r.trials.size(), 2u);
  EXPECT_EQ(r.trials[0].angle_deg.value, clean().trials[0].angle_deg.value);  // trial 1 unaffected
  const Series& a = r.trials[1].angle_deg;
  std::size_t finite = 0, nan_after = 0, finite_after = 0;
  for (std::size_t j = 0; j < a.t_s.size(); ++j) {
    if (std::isfinite(a.value[j])) ++finite;
    if (a.t_s[j] > r.failure_time_s) (std::isfinite(a.value[j]) ? finite_after : nan_after) += 1;
  }
  EXPECT_GT(finite, 30u) << "the 0 kPa hold and the first ramp of trial 2 were solved";
  EXPECT_GT(nan_after, 0u) << "the run must have stopped before the end of trial 2";
  EXPECT_EQ(finite_after, 0u) << "no model value after the last solved state";
  EXPECT_GT(r.failure_time_s, 4.0);
}

// DriveOptions::chamber_pressure maps every pressure of the load (diagnose drives a coarser mesh
// with the pressure at which it bends as the scene's mesh does): halving it is the same run as a
// recording of half the pressure. Exactly: halving a noise-free staircase keeps its breakpoints
// (the 0.05 kPa simplification tolerance is met by both) and 0.5 p is exact in binary.
TEST_F(DriveTest, ChamberPressureMapDrivesTheMappedPressure) {
  DriveOptions opt;
  opt.threads = 2;
  opt.chamber_pressure = [](double p) { return 0.5 * p; };
  const DriveResult mapped = simulate_recording(scene(), sampled_staircase(scene(), 0.0, 1), opt);
  Recording half = sampled_staircase(scene(), 0.0, 1);
  for (TrialRecording& tr : half.trials)
    for (double& p : tr.pressure_kPa.value) p *= 0.5;
  opt.chamber_pressure = nullptr;
  const DriveResult direct_half = simulate_recording(scene(), half, opt);
  ASSERT_EQ(mapped.trials.size(), direct_half.trials.size());
  for (std::size_t k = 0; k < mapped.trials.size(); ++k) {
    EXPECT_EQ(mapped.trials[k].states_pressure_kPa.value, direct_half.trials[k].states_pressure_kPa.value);
    for (std::size_t j = 0; j < mapped.trials[k].angle_deg.value.size(); ++j)
      EXPECT_NEAR(mapped.trials[k].angle_deg.value[j], direct_half.trials[k].angle_deg.value[j], 1e-9);
  }
  const auto top = [](const DriveResult& r) {
    const std::vector<double>& a = r.trials[0].states_angle_deg.value;
    return *std::max_element(a.begin(), a.end(), [](double x, double y) { return std::abs(x) < std::abs(y); });
  };
  EXPECT_LT(std::abs(top(mapped)), 0.8 * std::abs(top(clean()))) << "the map must change the angles for this test to mean anything";
}

TEST(Drive, CreepCarriesOverBetweenTrialsAsInADirectRun) {
  // Viscoelastic silicone (one Prony term, tau = 2 s, so a 3 s hold creeps visibly and trial 2
  // starts before trial 1's creep has recovered). Both runs solve the same pressures but at
  // different physical time steps (the drive adds a state every 0.5 s in holds); the engine's
  // step control bounds the viscous-strain change per step by time_tol = 0.01, so they differ by
  // the time-discretisation error only: observed 6e-5 deg, bound 1e-3 deg.
  constexpr double kTol_deg = 1e-3;
  const Scene scene = tiny_scene().with({"load.max_kPa=20", "load.hold_s=3", "materials.silicone.viscoelastic.enabled=true",
                                         "materials.silicone.viscoelastic.moduli=long_term",  // as measured
                                         "materials.silicone.viscoelastic.gamma=[0.3]",
                                         "materials.silicone.viscoelastic.tau_s=[2.0]"});
  const Direct direct = direct_run(scene);
  DriveOptions opt;
  opt.threads = 2;
  opt.max_report_gap_s = 0.5;
  const DriveResult drive = simulate_recording(scene, sampled_staircase(scene, 0.0, 1), opt);
  for (const StateRecord& r : direct.records) {
    const double a = value_at(drive.trials[static_cast<std::size_t>(r.trial - 1)].states_angle_deg, r.time_s);
    EXPECT_NEAR(a, r.angle_deg, kTol_deg) << "trial " << r.trial << " t " << r.time_s;
  }
  // The carry-over is real: the same step of trial 2 bends more than in trial 1 (unrecovered
  // creep), by far more than the tolerance, and within a hold the angle creeps.
  const std::size_t half = direct.records.size() / 2;
  EXPECT_GT(direct.records[2 + half].angle_deg - direct.records[2].angle_deg, 10 * kTol_deg);
  EXPECT_GT(direct.records[3].angle_deg - direct.records[2].angle_deg, 5 * kTol_deg);  // mark -> end: 0.5 s
}

TEST(Drive, SimplifyKeepsTheCornersOfANoiseFreeStaircase) {
  Series p;
  for (int i = 0; i <= 4000; ++i) {
    const double t = i / 400.0;  // 0..10 s: 0 kPa, ramp 2-2.5 s to 5 kPa, hold
    p.t_s.push_back(t);
    p.value.push_back(t < 2 ? 0.0 : t < 2.5 ? 10.0 * (t - 2) : 5.0);
  }
  double tol = 0;
  const Series s = simplify_pressure(p, 0.0, 0.05, &tol);
  EXPECT_EQ(tol, 0.05);  // noise-free: the floor
  ASSERT_EQ(s.t_s.size(), 4u);
  EXPECT_EQ(s.t_s[1], 2.0);
  EXPECT_EQ(s.t_s[2], 2.5);
  EXPECT_NEAR(s.value[1], 0.0, 1e-12);  // the least-squares values reproduce a piecewise-linear
  EXPECT_NEAR(s.value[2], 5.0, 1e-12);  // record with these knots (to round-off)
}

// A noisy staircase at the top of the actuator's curve: the model must be driven at each plateau's
// mean pressure, not at the value of one filtered sample (at 45 kPa the angle rises ~5°/kPa, so
// 0.05 kPa is 0.25°). 0-45 kPa in 5 kPa steps, 0.2 s ramps, 10 s holds, 100 Hz, sensor noise
// sigma = 0.1 kPa (a deterministic Box-Muller stream).
TEST(Drive, SimplifyDrivesEachPlateauAtItsMeanPressure) {
  Series p;
  std::uint64_t state = 12345;
  auto uniform = [&state] {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return (static_cast<double>(state >> 11) + 0.5) / 9007199254740992.0;
  };
  const double dt = 0.01, hold = 10.0, sigma = 0.1;
  for (int i = 0; i <= 10 * 1000; ++i) {
    const double t = i * dt;
    const int level = std::min(9, static_cast<int>(t / hold));
    const double into = t - level * hold;
    const double clean = level == 0 ? 0.0 : 5.0 * (level - 1) + 5.0 * std::min(1.0, into / 0.2);
    const double g = std::sqrt(-2 * std::log(uniform())) * std::cos(2 * M_PI * uniform());
    p.t_s.push_back(t);
    p.value.push_back(clean + sigma * g);
  }
  double tol = 0;
  const Series s = simplify_pressure(p, 0.0, 0.05, &tol);
  EXPECT_NEAR(tol, 3 * sigma, 0.05);  // auto tolerance: 3 sigma of the raw noise
  EXPECT_LT(s.t_s.size(), 80u);      // a few breakpoints per step, not 10^4 states
  // The driven pressure 1 s after each ramp and 0.5 s before the next. Bound 0.02 kPa: the
  // filtered samples scatter by ~0.055 kPa (a 5-sample median of sigma 0.1), a fitted plateau of
  // ~1000 of them by ~0.005 (their errors are correlated over the window); the value of one
  // filtered sample, as a breakpoint used to be, misses 0.02 in most cases. (Within ~0.2 s of a
  // corner the error is bounded by the RDP tolerance instead: the corner's breakpoint may be a
  // sample off, and the chord to it is then up to `tol` from the record.)
  for (int level = 1; level <= 9; ++level)
    for (const double into : {1.2, 9.5}) {
      const double t = level * hold + into;
      const std::size_t i = static_cast<std::size_t>(std::upper_bound(s.t_s.begin(), s.t_s.end(), t) - s.t_s.begin());
      ASSERT_GT(i, 0u);
      ASSERT_LT(i, s.t_s.size());
      const double w = (t - s.t_s[i - 1]) / (s.t_s[i] - s.t_s[i - 1]);
      EXPECT_NEAR((1 - w) * s.value[i - 1] + w * s.value[i], 5.0 * level, 0.02) << "level " << level << ", t " << t;
    }
}

TEST(Drive, HoldStatesOnlyForModelsWithHistory) {
  Recording rec;
  rec.source = "r.csv";
  TrialRecording tr;
  tr.trial = 3;
  tr.pressure_kPa = {{-1.0, 0.0, 9.0}, {5.0, 5.0, 5.0}};
  rec.trials.push_back(tr);
  DriveOptions opt;
  std::vector<double> offset;
  const LoadHistory elastic = measured_load(rec, opt, 0.0, false, offset);
  EXPECT_EQ(offset, std::vector<double>{-1.0});
  EXPECT_EQ(elastic.trials[0].time_s.size(), 2u);  // constant pressure: no extra states
  const LoadHistory creep = measured_load(rec, opt, 0.0, true, offset);
  const std::vector<double>& t = creep.trials[0].time_s;
  EXPECT_EQ(t.front(), 0.0);
  EXPECT_DOUBLE_EQ(t.back(), 10.0);
  for (std::size_t i = 1; i < t.size(); ++i) EXPECT_LE(t[i] - t[i - 1], opt.max_report_gap_s + 1e-12);
  rec.trials[0].pressure_kPa = {};
  try {
    measured_load(rec, opt, 0.0, false, offset);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("r.csv: trial 3"), std::string::npos) << e.what();
  }
}

// Absolute pressure (a record that rests at ~101 kPa) and Pa labelled kPa would drive the model far
// past its limit point at once; they are named as what they are, with the fix.
TEST(Drive, AbsolutePressureOrPascalsAreCaughtBeforeTheModelRuns) {
  Recording rec;
  rec.source = "rig.csv";
  TrialRecording tr;
  tr.trial = 2;
  tr.pressure_kPa = {{0.0, 1.0, 2.0}, {101.3, 106.3, 101.2}};
  rec.trials.push_back(tr);
  DriveOptions opt;
  std::vector<double> offset;
  auto error = [&] {
    try {
      measured_load(rec, opt, 0.0, false, offset);
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  std::string e = error();
  EXPECT_NE(e.find("rig.csv: the pressure never falls below 101.2 kPa (lowest sample at trial 2, time_s = 2)"),
            std::string::npos) << e;
  EXPECT_NE(e.find("ABSOLUTE pressure"), std::string::npos) << e;
  rec.trials[0].pressure_kPa.value = {0.0, 45000.0, 0.0};
  e = error();
  EXPECT_NE(e.find("pressure_kPa reaches 45000 kPa (at trial 2, time_s = 1)"), std::string::npos) << e;
  EXPECT_NE(e.find("name it pressure_Pa"), std::string::npos) << e;
  rec.trials[0].pressure_kPa.value = {0.0, 45.0, 20.0};  // a gauge record in kPa: accepted
  EXPECT_EQ(error(), "");
}

TEST_F(DriveTest, WritesTheWorstStatesAsVtu) {
  Recording rec = sampled_staircase(scene(), 0.0, 1);
  // Measured 1000 deg throughout trial 2 (constant: no outlier frames), 0 in trial 1: the states
  // of trial 2 are the worst.
  for (double& v : rec.trials[1].angle_deg.value) v = 1000.0;
  DriveOptions opt;
  opt.vtu_dir = (std::filesystem::temp_directory_path() / ("pneufem_drive_vtu_" + std::to_string(::getpid()))).string();
  const DriveResult r = simulate_recording(scene(), rec, opt);
  ASSERT_EQ(r.worst.size(), 3u);
  EXPECT_EQ(r.worst[0].trial, 2);
  for (const WorstState& w : r.worst) EXPECT_TRUE(std::filesystem::exists(w.file)) << w.file;
  std::filesystem::remove_all(opt.vtu_dir);
}

}  // namespace
}  // namespace pneufem
