// The seed paper's story (Libby et al., sec. IV: Figs. 8-11) reproduced by the three inelastic
// effects of damage/ on the pneu-net of scenes/examples/paper_story.toml, compared with the ideal
// elastic model (the same scene with the effects off), in the paper's own metrics
// (analysis/paper_metrics.h):
//   1. NRMSE of the 2.5 s-mark angles ~4 % in trial 1 and growing over the trials (~20 % by trial 10);
//   2. the low steps (the first half of the levels, 0-20 kPa) stay within a few degrees of the ideal;
//   3. the top three steps are still rising at the end of the hold (spread mark -> end > 0 and larger
//      than at the low steps);
//   4. fatigue damage peaks in the interior walls (region tag) and no point reaches d_fail.
// The full 10-trial story on the example's mesh takes many minutes (bench/results/story.md); CI runs
// it on a smaller actuator and fewer trials (kReducedModel, kTrials) and checks the reduced story: the
// trial-1 level and the growth from trial 1 to the last trial. Ranges follow from the story's
// definition (argued at each test), not from one run's numbers.
#include <algorithm>
#include <cmath>
#include <map>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "analysis/paper_metrics.h"
#include "engine/mesh.h"
#include "engine/quasi_static.h"
#include "scenes/build_model.h"

namespace pneufem {
namespace {

const std::string kStoryScene = std::string(PNEUFEM_TEST_DATA_DIR) + "/../../scenes/examples/paper_story.toml";

// CI model: the example's h = 6 mm mesh of a 3-chamber pneu-net (same chamber, wall, roof and base
// cross-section; 1.8k instead of 7.4k nodes). The story is per chamber and the metrics are relative
// to the ideal model's angle range, so the 3-chamber actuator tells the same story (ideal angle per
// chamber at 45 kPa 3.1 deg vs 3.5 deg for 15 chambers; the 15-chamber story with its own fatigue rate: story.md r13);
// three trials instead of ten (202 s CPU for the whole suite, story.md): ten trials do not fit in CI.
// The fatigue rate is the 3-chamber calibration (tau = 80 s: 2.8 % -> 20.5 % over ten trials, story.md
// r10); the file's tau = 160 s is the 15-chamber one (r12-r13), whose top steps sit closer to the
// limit point and so soften faster for the same damage.
const std::vector<std::string> kReducedModel = {"geometry.chambers=3", "mesh.h_mm=6.0", "output.vtu=\"none\"",
                                                "materials.silicone.fatigue.tau_s=80.0"};
constexpr int kTrials = 3;

struct StoryRun {
  std::vector<StateRecord> records;
  std::vector<double> state;  ///< committed material state at the end of the last trial
  std::unique_ptr<BuiltModel> bm;
};

StoryRun run_scene(const Scene& scene) {
  StoryRun r;
  r.bm = build_model(scene);
  const Assembler A(r.bm->model);
  QuasiStaticRun run(A, r.bm->solver.quasi_static);
  run.run(r.bm->load, [&](const StateRecord& s, const Eigen::VectorXd&, const std::vector<double>&) { r.records.push_back(s); });
  r.state = run.state();
  return r;
}

/// The angles of one trial at each step's mark and end (reports at exactly those times).
StepAngles sample(const TrialLoad& tl, int trial, const std::vector<StateRecord>& recs) {
  StepAngles s;
  s.trial = trial;
  auto at = [&](double t) {
    for (const StateRecord& r : recs)
      if (r.trial == trial && std::abs(r.time_s - t) < 1e-9) return r.angle_deg;
    ADD_FAILURE() << "no report at t = " << t << " s of trial " << trial;
    return 0.0;
  };
  for (std::size_t k = 0; k < tl.step_start_s.size(); ++k) {
    s.level_kPa.push_back(tl.step_level_Pa[k] * 1e-3);
    s.at_mark_deg.push_back(at(tl.step_start_s[k] + tl.mark_s));
    s.at_end_deg.push_back(at(tl.step_end_s[k]));
  }
  return s;
}

struct RegionDamage {
  double sum = 0.0, max = 0.0;
  long points = 0;
  double mean() const { return points ? sum / static_cast<double>(points) : 0.0; }
};

class PaperStory : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    std::vector<std::string> sets = kReducedModel;
    sets.push_back("load.trials=" + std::to_string(kTrials));
    const Scene story = Scene::load(kStoryScene, sets);
    run_ = new StoryRun(run_scene(story));
    ideal_ = new StoryRun(run_scene(story.with({"materials.silicone.mullins.enabled=false",
                                                "materials.silicone.fatigue.enabled=false",
                                                "materials.silicone.viscoelastic.enabled=false", "load.trials=1"})));
    const StepAngles ref = sample(ideal_->bm->load.trials[0], 1, ideal_->records);
    metrics_ = new std::vector<TrialMetrics>;
    for (int k = 0; k < kTrials; ++k)
      metrics_->push_back(paper_metrics(sample(run_->bm->load.trials[k], k + 1, run_->records), ref));
    for (const TrialMetrics& m : *metrics_) {
      std::string line = "trial " + std::to_string(m.trial) + ": NRMSE " + std::to_string(100 * m.nrmse) + " %, error/spread:";
      for (std::size_t i = 0; i < m.abs_error_deg.size(); ++i) {
        char buf[64];  // snprintf rather than string sums: GCC 12 -O3 warns falsely (-Wrestrict) on "x" + string
        std::snprintf(buf, sizeof buf, " %f/%f", m.mark_deg[i] - m.reference_deg[i], m.spread_deg[i]);
        line += buf;
      }
      std::printf("%s\n", line.c_str());
    }
  }
  static void TearDownTestSuite() {
    delete run_;
    delete ideal_;
    delete metrics_;
  }
  static std::size_t steps() { return metrics_->front().abs_error_deg.size(); }
  /// "Low" = the first half of the levels (0-20 kPa of the 0-45 kPa staircase).
  static std::size_t low_steps() { return steps() / 2; }

  static StoryRun* run_;
  static StoryRun* ideal_;
  static std::vector<TrialMetrics>* metrics_;
};
StoryRun* PaperStory::run_ = nullptr;
StoryRun* PaperStory::ideal_ = nullptr;
std::vector<TrialMetrics>* PaperStory::metrics_ = nullptr;

TEST_F(PaperStory, Trial1MatchesTheIdealModelToAFewPercent) {
  // The paper: 4 % in trial 1 (the model's "96 % accuracy"). The story's band is 2.5-6 %: above
  // 2.5 % so the effects are visible before any fatigue has built up, below 6 % so trial 1 is still
  // the "before fatigue" trial.
  EXPECT_GT(metrics_->front().nrmse, 0.025);
  EXPECT_LT(metrics_->front().nrmse, 0.06);
}

TEST_F(PaperStory, NrmseGrowsOverTheTrials) {
  // Fatigue is irreversible and is driven again in every trial, so the error must grow strictly
  // from trial to trial (Mullins saturates after trial 1 and viscoelasticity repeats; neither grows).
  for (std::size_t k = 1; k < metrics_->size(); ++k)
    EXPECT_GT((*metrics_)[k].nrmse, (*metrics_)[k - 1].nrmse) << "trial " << k + 1;
}

TEST_F(PaperStory, GrowthPerTrialHeadsForTwentyPercentByTrialTen) {
  // Reduced check of "~20 % by trial 10" (14-28 %) from trial 1 at 2.5-6 %: the average growth is
  // (14 - 6) / 9 = 0.9 to (28 - 2.5) / 9 = 2.8 points per trial. The first trials can grow slower
  // than the average (the fatigue first cancels trial 1's viscous lag at 45 kPa; how the growth
  // evolves later depends on the law's saturation, n), so over kTrials - 1 trials at least 0.5 x the
  // smallest average and at most the largest.
  const double growth = (metrics_->back().nrmse - metrics_->front().nrmse) / (kTrials - 1);
  EXPECT_GT(growth, 0.5 * 0.009);
  EXPECT_LT(growth, 0.028);
}

TEST_F(PaperStory, LowStepsStayWithinAFewDegreesOfTheIdeal) {
  // The paper's low pressures "continue to match the simulation" in every trial. "A few degrees" is
  // relative to the actuator's angle scale: 2-3 deg of the ~64 deg ideal range of the full actuator
  // (h = 4 mm), i.e. 4 % of the ideal model's range of mark angles (the NRMSE's normaliser).
  const double range = metrics_->front().reference_deg.back() - metrics_->front().reference_deg.front();
  for (const TrialMetrics& m : *metrics_)
    for (std::size_t i = 0; i < low_steps(); ++i)
      EXPECT_LT(m.abs_error_deg[i], 0.04 * range) << "trial " << m.trial << ", step " << i;
}

TEST_F(PaperStory, TopThreeStepsStillRiseAtTheEndOfTheHold) {
  // Non-plateau behaviour at the three highest pressures (spread 2.5 s -> 16 s > 0), clearly more
  // than at any low step (whose spread is viscoelastic creep only): at least twice the largest low
  // spread, in the last trial.
  const TrialMetrics& last = metrics_->back();
  const double low_spread = *std::max_element(last.spread_deg.begin(), last.spread_deg.begin() + low_steps());
  for (std::size_t i = steps() - 3; i < steps(); ++i) {
    EXPECT_GT(last.spread_deg[i], 0.0) << "step " << i;
    EXPECT_GT(last.spread_deg[i], 2.0 * std::max(low_spread, 0.0)) << "step " << i;
  }
}

TEST_F(PaperStory, FatigueDamagePeaksInTheInteriorWallsAndNothingFails) {
  const Model& model = run_->bm->model;
  const Assembler A(model);
  std::map<std::string, RegionDamage> by_region;
  bool any_failed = false;
  double d_max = 0.0;
  std::string d_max_region;
  for (int e = 0; e < model.mesh.num_elements(); ++e) {
    const Material& mat = model.material_of(e);
    const int ss = mat.state_size();
    if (ss == 0) continue;  // the elastic fabric
    const std::span<const double> es = A.element_state(run_->state, e);
    const std::string& region = model.mesh.region_names[model.mesh.region[e]];
    RegionDamage& rd = by_region[region];
    for (int q = 0; q < A.geometry().nqp; ++q) {
      const PointFields f = mat.fields(es.subspan(static_cast<std::size_t>(q * ss), static_cast<std::size_t>(ss)));
      rd.sum += f.fatigue_damage;
      rd.max = std::max(rd.max, f.fatigue_damage);
      ++rd.points;
      any_failed = any_failed || f.failed;
      if (f.fatigue_damage > d_max) {
        d_max = f.fatigue_damage;
        d_max_region = region;
      }
    }
  }
  for (const auto& [name, rd] : by_region)
    std::printf("region %-14s mean fatigue damage %.4f  max %.4f  (%ld points)\n", name.c_str(), rd.mean(), rd.max, rd.points);
  ASSERT_TRUE(by_region.count(regions::kInteriorWall));
  // The paper (sec. I, Fig. 4): the highest stress, and so the most fatigue, is in the interior walls.
  EXPECT_EQ(d_max_region, regions::kInteriorWall);
  const double wall_mean = by_region[regions::kInteriorWall].mean();
  EXPECT_GT(wall_mean, 0.0);
  for (const auto& [name, rd] : by_region) {
    if (name != regions::kInteriorWall) {
      EXPECT_GT(wall_mean, rd.mean()) << name;
    }
  }
  // Fatigue softens but does not break the actuator: no point reaches d_fail.
  EXPECT_FALSE(any_failed);
  EXPECT_LT(d_max, Scene::load(kStoryScene).number("materials.silicone.fatigue.d_fail"));
}

}  // namespace
}  // namespace pneufem
