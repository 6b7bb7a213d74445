// Model-vs-measurement metrics (analysis/model_vs_measured.h) on synthetic records where every metric is
// known in closed form: a noise-free staircase pressure (tests/analysis/synthetic.h), a measured
// angle that is constant (trial 1) or creeps linearly (trial 2) inside each step, and a model
// that differs from it by a known per-step offset b_k plus a known drift g (t - T_k).
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <random>
#include <vector>

#include "analysis/model_vs_measured.h"
#include "core/errors.h"
#include "tests/analysis/synthetic.h"

namespace pneufem {
namespace {

using testing::StaircaseSpec;

struct TrialTruth {
  double c = 0.0;               ///< measured creep inside each step, deg/s
  std::vector<double> b;        ///< model offset per step, deg
  double g = 0.0;               ///< model drift inside each step, deg/s
};

/// Commands fall 17 ms after a frame (frames every 33.3 ms), so the ~2 ms uncertainty of the
/// detected step starts cannot move a frame from one step to another.
StaircaseSpec spec() {
  StaircaseSpec s;
  s.levels_kPa = {0, 5, 10, 15, 20};
  s.command_phase_s = 0.017;
  s.noise_kPa = 0.0;
  return s;
}

double command(const StaircaseSpec& s, std::size_t k) { return k == 0 ? 0.0 : k * s.hold_s + s.command_phase_s; }

std::size_t step_of(const StaircaseSpec& s, double t) {
  std::size_t k = 0;
  while (k + 1 < s.levels_kPa.size() && t >= command(s, k + 1)) ++k;
  return k;
}

double measured(const StaircaseSpec& s, const TrialTruth& tt, double t) {
  const std::size_t k = step_of(s, t);
  return 10.0 * static_cast<double>(k) + tt.c * (t - command(s, k));
}

double residual(const StaircaseSpec& s, const TrialTruth& tt, double t) {
  const std::size_t k = step_of(s, t);
  return tt.b[k] + tt.g * (t - command(s, k));
}

/// Recording + model traces for the truths; frame `outlier` of trial 1 gets +50 deg.
void make(const StaircaseSpec& s, const std::vector<TrialTruth>& truths, std::size_t outlier, Recording& rec,
          std::vector<Series>& model) {
  rec.source = "synthetic";
  for (std::size_t n = 0; n < truths.size(); ++n) {
    TrialRecording tr = testing::make_staircase_trial(s, static_cast<int>(n + 1), 1);
    Series m;
    for (std::size_t j = 0; j < tr.angle_deg.t_s.size(); ++j) {
      const double t = tr.angle_deg.t_s[j];
      tr.angle_deg.value[j] = measured(s, truths[n], t);
      m.t_s.push_back(t);
      m.value.push_back(measured(s, truths[n], t) + residual(s, truths[n], t));
    }
    if (n == 0) tr.angle_deg.value[outlier] += 50.0;
    rec.trials.push_back(tr);
    model.push_back(m);
  }
}

TEST(Compare, EveryMetricMatchesClosedForm) {
  const StaircaseSpec s = spec();
  const std::vector<TrialTruth> truths = {{0.0, {1.0, 1.5, 2.0, 2.5, 3.0}, 0.0}, {0.1, {-2, -2, -2, -2, -2}, 0.05}};
  const std::size_t outlier = 700;  // mid-hold of step 1 in trial 1
  Recording rec;
  std::vector<Series> model;
  make(s, truths, outlier, rec, model);
  CompareOptions opt;
  opt.bin_s = 0.5;  // bin edges fall on frame times, >= 16 ms from any step start
  const Comparison c = compare_recording(rec, model, opt);

  // Mark times move with the detected start (a few ms); the creep c and drift g turn that into
  // at most 0.15 deg/s * 5 ms < 1e-3 deg. Slopes, ranges and sums are exact up to rounding.
  constexpr double kMarkTol = 1e-3, kExact = 1e-9;
  ASSERT_EQ(c.trials.size(), 2u);
  double rss_all = 0;
  long n_all = 0;
  double lo_all = 1e300, hi_all = -1e300;
  std::map<long, std::pair<double, long>> bins_all;
  for (std::size_t n = 0; n < 2; ++n) {
    const TrialTruth& tt = truths[n];
    const TrialComparison& tc = c.trials[n];
    EXPECT_EQ(tc.outliers, n == 0 ? 1 : 0);
    ASSERT_EQ(tc.steps.size(), s.levels_kPa.size());
    const Series& frames = rec.trials[n].angle_deg;
    double rss = 0, lo = 1e300, hi = -1e300, mark_ss = 0;
    std::vector<double> step_sum(5, 0.0);
    std::vector<long> step_n(5, 0), last_frame(5, -1);
    for (std::size_t j = 0; j < frames.t_s.size(); ++j) {
      if (n == 0 && j == outlier) continue;
      const double t = frames.t_s[j], r = residual(s, tt, t), m = measured(s, tt, t);
      const std::size_t k = step_of(s, t);
      rss += r * r;
      lo = std::min(lo, m);
      hi = std::max(hi, m);
      step_sum[k] += r;
      ++step_n[k];
      last_frame[k] = static_cast<long>(j);
      auto& bin = bins_all[static_cast<long>((t - command(s, k)) / opt.bin_s)];
      bin.first += r;
      ++bin.second;
    }
    rss_all += rss;
    n_all += static_cast<long>(frames.t_s.size()) - (n == 0 ? 1 : 0);
    lo_all = std::min(lo_all, lo);
    hi_all = std::max(hi_all, hi);
    EXPECT_NEAR(tc.rss_deg2, rss, kExact * rss);
    EXPECT_NEAR(tc.range_deg, hi - lo, kExact);
    EXPECT_NEAR(tc.nrmse, std::sqrt(rss / tc.frames) / (hi - lo), kExact);
    for (std::size_t k = 0; k < 5; ++k) {
      const StepComparison& st = tc.steps[k];
      SCOPED_TRACE("trial " + std::to_string(n + 1) + " step " + std::to_string(k));
      EXPECT_NEAR(st.level_kPa, s.levels_kPa[k], 1e-6);
      const double err = tt.b[k] + tt.g * opt.mark_s;
      EXPECT_NEAR(st.abs_error_deg, std::abs(err), kMarkTol);
      mark_ss += err * err;
      EXPECT_NEAR(st.measured_mark_deg, 10.0 * k + tt.c * opt.mark_s, kMarkTol);
      const double t_end = frames.t_s[static_cast<std::size_t>(last_frame[k])] - command(s, k);
      EXPECT_NEAR(st.spread_measured_deg, tt.c * (t_end - opt.mark_s), kMarkTol);
      EXPECT_NEAR(st.spread_model_deg, (tt.c + tt.g) * (t_end - opt.mark_s), kMarkTol);
      EXPECT_NEAR(st.slope_measured_deg_s, tt.c, kExact);
      EXPECT_NEAR(st.slope_model_deg_s, tt.c + tt.g, kExact);
      EXPECT_NEAR(st.slope_residual_deg_s, tt.g, kExact);
      // Steady: drift over the settled hold (0.1 deg/s * 13.5 s) against the noise-free floor.
      EXPECT_EQ(st.steady, tt.c == 0.0);
      EXPECT_EQ(st.steady_model, tt.c + tt.g == 0.0);
      EXPECT_EQ(st.frames, step_n[k]);
      EXPECT_NEAR(c.residual_map_deg[n][k], step_sum[k] / step_n[k], kExact);
    }
    // The mark range is the measured levels' span, 40 deg (the creep shifts every mark alike).
    EXPECT_NEAR(tc.nrmse_mark, std::sqrt(mark_ss / 5) / 40.0, kMarkTol / 40.0);
    EXPECT_NEAR(tc.noise_deg, 0.0, 1e-12);  // piecewise linear: second differences vanish (up to rounding)
  }
  EXPECT_EQ(c.n, n_all);
  EXPECT_NEAR(c.rss_deg2, rss_all, kExact * rss_all);
  EXPECT_NEAR(c.range_deg, hi_all - lo_all, kExact);
  EXPECT_NEAR(c.nrmse, std::sqrt(rss_all / n_all) / (hi_all - lo_all), kExact);
  EXPECT_EQ(static_cast<long>(c.frames.size()), n_all);
  for (const auto& [i, sum_n] : bins_all) {
    ASSERT_LT(static_cast<std::size_t>(i), c.profile.mean_deg.size());
    EXPECT_EQ(c.profile.count[static_cast<std::size_t>(i)], sum_n.second);
    EXPECT_NEAR(c.profile.mean_deg[static_cast<std::size_t>(i)], sum_n.first / sum_n.second, kExact);
  }
  // Trial 1 is "early", trial 2 "late": trial 2's residual is -2 + 0.05 (t - T_k) <= -1.2.
  for (double v : c.profile_late_trials.mean_deg)
    if (std::isfinite(v)) {
      EXPECT_LT(v, -1.19);
    }
  for (double v : c.profile_early_trials.mean_deg)
    if (std::isfinite(v)) {
      EXPECT_GT(v, 0.99);
    }
}

// A recording in the opposite sign convention, or in radians under angle_deg, is named as such; a
// recording in the model's convention (even a poor fit) gets no such note.
TEST(Compare, AnOppositeSignOrRadiansIsPointedOut) {
  const StaircaseSpec s = spec();
  const std::vector<TrialTruth> truths = {{0.0, {0, 1, 2, 3, 4}, 0.0}};
  auto notes = [&](double factor) {
    Recording rec;
    std::vector<Series> model;
    make(s, truths, 0, rec, model);
    rec.trials[0].angle_deg.value[0] -= 50.0;  // no outlier here
    for (double& v : rec.trials[0].angle_deg.value) v *= factor;
    std::string all;
    for (const std::string& w : compare_recording(rec, model).warnings) all += w + "\n";
    return all;
  };
  EXPECT_EQ(notes(1.0).find("opposite"), std::string::npos) << notes(1.0);
  EXPECT_EQ(notes(0.6).find("opposite"), std::string::npos);   // too stiff a model is not a convention
  EXPECT_EQ(notes(0.6).find("radians"), std::string::npos);
  const std::string neg = notes(-1.0);
  EXPECT_NE(neg.find("runs opposite to the model's (least-squares fit measured = -0.9"), std::string::npos) << neg;
  EXPECT_NE(neg.find("negate angle_deg"), std::string::npos) << neg;
  const std::string rad = notes(3.14159265358979 / 180.0);
  EXPECT_NE(rad.find("probably in radians; name the column angle_rad"), std::string::npos) << rad;
}

TEST(Compare, NoiseFloorRecoversTheTrackingNoise) {
  // Smooth response + Gaussian noise sigma = 0.3 deg + glitches. The MAD estimator of 6000
  // second differences (correlated at lags 1, 2) has a relative standard error of ~2 %; 8 % is
  // four of them.
  Recording rec;
  rec.source = "noise";
  std::mt19937_64 rng(7);
  std::normal_distribution<double> noise(0.0, 0.3);
  double lo = 1e300, hi = -1e300;
  for (int n = 1; n <= 2; ++n) {
    TrialRecording tr;
    tr.trial = n;
    for (int j = 0; j < 3000; ++j) {
      const double t = j / 30.0, clean = 40.0 * std::sin(t / 20.0);
      const double v = clean + noise(rng);
      lo = std::min(lo, v);
      hi = std::max(hi, v);
      tr.angle_deg.t_s.push_back(t);
      tr.angle_deg.value.push_back(j % 500 == 250 ? v + 50.0 : v);
    }
    EXPECT_NEAR(angle_noise_deg(tr.angle_deg), 0.3, 0.08 * 0.3);
    rec.trials.push_back(tr);
  }
  EXPECT_NEAR(noise_floor_nrmse(rec), 0.3 / (hi - lo), 0.08 * 0.3 / (hi - lo));
}

TEST(Compare, ProjectionOfResidualOntoSensitivity) {
  // e = 2 s + o with o orthogonal to s: delta = -2, fraction = 4|s|^2 / (4|s|^2 + |o|^2).
  const std::vector<double> s = {1, 0, 1, 0}, o = {0, 3, 0, -1};
  std::vector<double> e(4);
  for (int i = 0; i < 4; ++i) e[i] = 2 * s[i] + o[i];
  const Projection p = project_residual(e, s);
  EXPECT_NEAR(p.delta, -2.0, 1e-15);
  EXPECT_NEAR(p.fraction, 8.0 / (8.0 + 10.0), 1e-15);
  EXPECT_EQ(project_residual(e, {0, 0, 0, 0}).fraction, 0.0);
  EXPECT_THROW(project_residual(e, {1.0}), InputError);
  EXPECT_NEAR(ls_slope({0, 1, 2, 3}, {1, 3, 5, 7}), 2.0, 1e-15);
  EXPECT_TRUE(std::isnan(ls_slope({0, 1}, {0, 1})));
}

TEST(Compare, BadInputIsReported) {
  const StaircaseSpec s = spec();
  Recording rec;
  std::vector<Series> model;
  make(s, {{0.0, {0, 0, 0, 0, 0}, 0.0}}, 10, rec, model);
  model.push_back(model.front());
  try {
    compare_recording(rec, model);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("2 model traces for 1 trials"), std::string::npos) << e.what();
  }
  model.pop_back();
  for (double& v : rec.trials[0].angle_deg.value) v = 3.0;
  EXPECT_THROW(compare_recording(rec, model), InputError);
}

}  // namespace
}  // namespace pneufem
