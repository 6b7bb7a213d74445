// Hampel filter of the angle stream (analysis/hampel.h): tracking glitches are flagged, clean
// frames (including the fast rise after each pressure step) are left exactly as they were.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <set>
#include <string>
#include <vector>

#include "analysis/hampel.h"
#include "core/errors.h"
#include "tests/analysis/synthetic.h"

namespace pneufem {
namespace {

using testing::StaircaseSpec;

// Outliers of +50 deg: at the very first frame, two adjacent frames, frames during the fast rise
// right after a pressure command (16 s = frame 480, the rise lasts ~1 s = 30 frames), in the last
// window, and on the highest plateau.
const std::vector<std::size_t> kOutliers = {0, 700, 701, 1445, 1447, 2000, 4330, 4799};

// The paper's trial (30 fps, 0.3 deg tracking noise) over ten seeds: 48 000 clean frames. The
// filter must flag exactly the outlier frames (the rule's false-flag rate on clean Gaussian
// frames is ~1e-6, so none is expected here; the 50-deg glitches are > 100 sigma) and copy every
// other frame bit-for-bit.
TEST(Hampel, FlagsExactlyTheOutliersAndKeepsCleanFrames) {
  StaircaseSpec spec;
  spec.outlier_frames = kOutliers;
  for (unsigned seed = 1; seed <= 10; ++seed) {
    Series clean;
    const TrialRecording tr = testing::make_staircase_trial(spec, 1, 100u + seed, nullptr, &clean);
    ASSERT_EQ(tr.angle_deg.value.size(), 4800u);
    const HampelResult r = hampel_filter(tr.angle_deg);
    EXPECT_EQ(r.flagged, kOutliers) << "seed " << seed;
    std::set<std::size_t> out(kOutliers.begin(), kOutliers.end());
    std::vector<double> expected_t, expected_v;
    for (std::size_t j = 0; j < clean.t_s.size(); ++j)
      if (!out.count(j)) {
        expected_t.push_back(clean.t_s[j]);
        expected_v.push_back(clean.value[j]);
      }
    EXPECT_EQ(r.series.t_s, expected_t) << "seed " << seed;
    EXPECT_EQ(r.series.value, expected_v) << "seed " << seed;
  }
}

// Replace mode keeps the time grid and puts the window median in place of a glitch. On the
// plateau the median of 7 noisy frames is within ~3 * 1.25 * 0.3 / sqrt(7) = 0.43 deg of the
// truth; 1 deg is a safe bound that a left-in 50-deg spike violates.
TEST(Hampel, ReplaceModeUsesTheWindowMedian) {
  StaircaseSpec spec;
  spec.outlier_frames = {2000, 2001, 3000};  // on plateaus (commands at frames 480 k + 0..30)
  Series clean;
  const TrialRecording tr = testing::make_staircase_trial(spec, 1, 77u, nullptr, &clean);
  HampelOptions opt;
  opt.replace = true;
  const HampelResult r = hampel_filter(tr.angle_deg, opt);
  EXPECT_EQ(r.flagged, spec.outlier_frames);
  ASSERT_EQ(r.series.t_s, tr.angle_deg.t_s);
  for (std::size_t j : spec.outlier_frames)
    EXPECT_NEAR(r.series.value[j], testing::staircase_angle(spec, clean.t_s[j]), 1.0) << "frame " << j;
}

// A sharp step (one frame from 0 to 40 deg) and a steep monotone ramp are the response, not
// outliers: on a monotone stretch the window median is the centre sample itself.
TEST(Hampel, StepsAndRampsAreNotFlagged) {
  Series s;
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 0.3);
  for (int j = 0; j < 300; ++j) {
    const double base = j < 100 ? 0.0 : j < 200 ? 40.0 : 40.0 + 3.0 * (j - 200);
    s.t_s.push_back(j / 30.0);
    s.value.push_back(base + noise(rng));
  }
  const HampelResult r = hampel_filter(s);
  EXPECT_TRUE(r.flagged.empty()) << "first flagged frame " << r.flagged.front();
  EXPECT_EQ(r.series.value, s.value);
}

TEST(Hampel, RecordingFilterCountsAndWarnsPerTrial) {
  StaircaseSpec spec;
  spec.levels_kPa = {0, 10};
  spec.hold_s = 5.0;
  Recording rec;
  rec.source = "video.csv";
  spec.outlier_frames = {50, 200};
  rec.trials.push_back(testing::make_staircase_trial(spec, 1, 5u));
  spec.outlier_frames.clear();
  rec.trials.push_back(testing::make_staircase_trial(spec, 2, 6u));
  const std::size_t frames = rec.trials[0].angle_deg.t_s.size();
  EXPECT_EQ(filter_angle_outliers(rec), 2);
  EXPECT_EQ(rec.trials[0].angle_deg.t_s.size(), frames - 2);
  EXPECT_EQ(rec.trials[1].angle_deg.t_s.size(), frames);
  ASSERT_EQ(rec.warnings.size(), 1u);
  EXPECT_NE(rec.warnings[0].find("video.csv: trial 1: 2 outlier angle frame(s) dropped"), std::string::npos)
      << rec.warnings[0];
}

TEST(Hampel, ShortSeriesUnchangedAndBadOptionsRejected) {
  const Series s{{0.0, 1.0, 2.0}, {0.0, 90.0, 0.0}};
  const HampelResult r = hampel_filter(s);
  EXPECT_TRUE(r.flagged.empty());
  EXPECT_EQ(r.series.value, s.value);
  HampelOptions bad;
  bad.half_window = 0;
  EXPECT_THROW(hampel_filter(s, bad), InputError);
  bad = HampelOptions{};
  bad.k = 0.0;
  EXPECT_THROW(hampel_filter(s, bad), InputError);
}

}  // namespace
}  // namespace pneufem
