// engine/load_history.h: the staircase protocol, its size estimate, the pressure of a trial
// between breakpoints and the Ramer-Douglas-Peucker simplification of a pressure record.
#include "engine/load_history.h"

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/errors.h"

namespace pneufem {
namespace {

std::string error_of(double p_max, double dp, double hold, double ramp, int trials, double mark, double rest,
                     double every) {
  try {
    staircase(p_max, dp, hold, ramp, trials, mark, rest, every);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

// 0 -> 20 kPa in 10 kPa steps, 4 s holds reached in 0.5 s: the levels' breakpoints, the steps and
// the reports at the mark and the end of each hold, the same in every trial.
TEST(LoadHistory, StaircaseLevelsStepsAndReports) {
  const LoadHistory h = staircase(20e3, 10e3, 4.0, 0.5, 2, 2.5, 7.0);
  ASSERT_EQ(h.trials.size(), 2u);
  EXPECT_EQ(h.rest_between_trials_s, 7.0);
  const TrialLoad& t = h.trials[0];
  EXPECT_EQ(t.time_s, (std::vector<double>{0.0, 4.0, 4.5, 8.0, 8.5, 12.0}));
  EXPECT_EQ(t.pressure_Pa, (std::vector<double>{0.0, 0.0, 10e3, 10e3, 20e3, 20e3}));
  EXPECT_EQ(t.step_start_s, (std::vector<double>{0.0, 4.0, 8.0}));
  EXPECT_EQ(t.step_end_s, (std::vector<double>{4.0, 8.0, 12.0}));
  EXPECT_EQ(t.step_level_Pa, (std::vector<double>{0.0, 10e3, 20e3}));
  EXPECT_EQ(t.output_s, (std::vector<double>{2.5, 4.0, 6.5, 8.0, 10.5, 12.0}));
  EXPECT_EQ(t.mark_s, 2.5);
  EXPECT_EQ(t.duration(), 12.0);
  EXPECT_EQ(h.trials[1].time_s, t.time_s);
  EXPECT_EQ(h.description, "staircase 0-20 kPa in 10 kPa steps, 4 s hold, 2 trial(s)");
}

TEST(LoadHistory, ExtraReportsInsideEachHold) {
  const TrialLoad t = staircase(10e3, 10e3, 4.0, 0.5, 1, 2.5, 0.0, 1.5).trials[0];
  // 1.5 and 3 inside the first hold, the mark 2.5 and the end 4; then the same from 4 s on.
  EXPECT_EQ(t.output_s, (std::vector<double>{1.5, 2.5, 3.0, 4.0, 5.5, 6.5, 7.0, 8.0}));
}

// Without a ramp a step is a jump: a breakpoint 1e-9 hold after the step's start.
TEST(LoadHistory, AStepWithoutRampIsAJump) {
  const TrialLoad t = staircase(5e3, 5e3, 2.0, 0.0, 1, 1.0, 0.0).trials[0];
  ASSERT_EQ(t.time_s.size(), 4u);
  EXPECT_EQ(t.time_s[2], 2.0 + 2e-9);
  EXPECT_EQ(t.pressure_Pa[2], 5e3);
}

TEST(LoadHistory, PressureIsLinearBetweenBreakpointsAndHeldOutside) {
  TrialLoad t;
  t.time_s = {0.0, 2.0, 4.0};
  t.pressure_Pa = {0.0, 10.0, 4.0};
  EXPECT_EQ(t.pressure(-1.0), 0.0);
  EXPECT_DOUBLE_EQ(t.pressure(0.5), 2.5);
  EXPECT_DOUBLE_EQ(t.pressure(3.0), 7.0);
  EXPECT_EQ(t.pressure(9.0), 4.0);
  EXPECT_EQ(TrialLoad().pressure(1.0), 0.0);
  EXPECT_EQ(TrialLoad().duration(), 0.0);
}

// 45 / 5 is 9 levels above 0 even where the division rounds below; reports: mark and end per level.
TEST(LoadHistory, StaircaseSize) {
  const StaircaseSize z = staircase_size(45e3, 5e3, 16.0, 10, 0.0);
  EXPECT_EQ(z.levels, 10.0);
  EXPECT_EQ(z.reports, 200.0);  // the paper's ten trials
  EXPECT_EQ(staircase_size(0.3, 0.1, 1.0, 1, 0.0).levels, 4.0);
  EXPECT_EQ(staircase_size(10e3, 5e3, 4.0, 2, 1.0).reports, 2.0 * 3.0 * (2.0 + 4.0));
}

// Each bad value names its load key; a protocol past the limits says what the limit is.
TEST(LoadHistory, BadStaircasesNameTheKey) {
  EXPECT_EQ(error_of(10e3, 0.0, 4, 0.5, 1, 2.5, 0, 0), "load.step_kPa: must be > 0");
  EXPECT_EQ(error_of(-1.0, 5e3, 4, 0.5, 1, 2.5, 0, 0), "load.max_kPa: must be >= 0");
  EXPECT_EQ(error_of(10e3, 5e3, 0, 0.0, 1, 0.0, 0, 0), "load.hold_s: must be > 0");
  EXPECT_EQ(error_of(10e3, 5e3, 4, 4.0, 1, 4.0, 0, 0), "load.ramp_s: must be >= 0 and shorter than hold_s");
  EXPECT_EQ(error_of(10e3, 5e3, 4, 0.5, 0, 2.5, 0, 0), "load.trials: must be >= 1");
  EXPECT_EQ(error_of(10e3, 5e3, 4, 0.5, 1, 0.2, 0, 0), "load.mark_s: must lie within the hold, after the ramp");
  EXPECT_EQ(error_of(10e3, 5e3, 4, 0.5, 1, 2.5, -1, 0), "load.rest_s: must be >= 0");
  EXPECT_EQ(error_of(10e3, 5e3, 4, 0.5, 1, 2.5, 0, -1), "load.output_every_s: must be >= 0 (0 = off)");
  EXPECT_EQ(error_of(1e9, 1.0, 4, 0.5, 1, 2.5, 0, 0).rfind("load.step_kPa: gives 1e+09 levels", 0), 0u);
  EXPECT_EQ(error_of(10e3, 5e3, 4, 0.5, 1, 2.5, 0, 1e-6).rfind("load.output_every_s: the protocol would make", 0), 0u);
}

// RDP keeps the corners of a piecewise-linear record and drops the samples within tol of a line.
TEST(LoadHistory, RdpKeepsTheCorners) {
  const std::vector<double> t = {0, 1, 2, 3, 4, 5, 6};
  const std::vector<double> p = {0, 1, 2, 3, 3.01, 2.99, 3};
  const std::vector<char> keep = rdp_keep(t, p, 0.05);
  EXPECT_EQ(keep, (std::vector<char>{1, 0, 0, 1, 0, 0, 1}));
  const std::vector<char> fine = rdp_keep(t, p, 0.001);
  EXPECT_EQ(fine, (std::vector<char>{1, 0, 0, 1, 1, 1, 1}));
  EXPECT_TRUE(rdp_keep({}, {}, 1.0).empty());
  EXPECT_EQ(rdp_keep({0.0}, {5.0}, 1.0), std::vector<char>{1});
}

}  // namespace
}  // namespace pneufem
