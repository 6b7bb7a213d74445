// app/simulate/ideal_cache.h: the ideal elastic model's angles shared between runs — computed once
// and read back to the bit, an entry of other report times or a damaged one recomputed with a
// warning, a key that changes with pneufem's version but not with the constants of an effect the
// ideal model switches off, and angles.csv's extrapolated column only when a trial was skipped.
// (Its use by simulate and sweep, end to end: IdealCache.SharedBetweenRuns... in tests/app/sweep/test_command.cpp.)
#include "app/simulate/ideal_cache.h"

#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "scenes/build_model.h"

namespace fs = std::filesystem;

namespace pneufem {
namespace {

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / name;
  fs::remove_all(d);
  return d;
}

std::vector<StateRecord> one_trial(const std::vector<double>& times) {
  std::vector<StateRecord> recs;
  for (double t : times) {
    StateRecord r;
    r.trial = 1;
    r.time_s = t;
    r.pressure_Pa = 1e3 * t / 3.0;
    r.angle_deg = 0.1 * t / 7.0 + 1e-13;
    recs.push_back(r);
  }
  return recs;
}

const std::vector<double> kTimes = {0.5, 2.5, 1.0 / 3.0 + 5.0, 21.0};

TEST(CachedIdeal, ComputesOnceThenReadsTheAnglesToTheBit) {
  const fs::path dir = fresh_dir("pneufem_ideal_cache_once");
  const Scene scene = Scene::load("");
  int calls = 0;
  auto compute = [&] { return ++calls, one_trial(kTimes); };
  std::vector<std::string> warnings;
  const IdealResult first = cached_ideal(dir.string(), "k1", scene, kTimes, compute, warnings);
  EXPECT_EQ(first.source, "computed");
  const IdealResult again = cached_ideal(dir.string(), "k1", scene, kTimes, compute, warnings);
  EXPECT_EQ(calls, 1);
  EXPECT_EQ(again.source, "cache " + (dir / "ideal_k1.csv").string());
  EXPECT_TRUE(fs::exists(dir / "ideal_k1.toml"));  // the scene it belongs to, for people
  ASSERT_EQ(again.records.size(), kTimes.size());
  for (std::size_t i = 0; i < kTimes.size(); ++i) {
    EXPECT_EQ(again.records[i].time_s, first.records[i].time_s) << i;
    EXPECT_EQ(again.records[i].angle_deg, first.records[i].angle_deg) << i;
    // Written in kPa: back to Pa within an ulp or so.
    EXPECT_NEAR(again.records[i].pressure_Pa, first.records[i].pressure_Pa, 1e-15 * 1e3) << i;
  }
  EXPECT_TRUE(warnings.empty());
  fs::remove_all(dir);
}

TEST(CachedIdeal, AnEntryOfOtherReportTimesOrADamagedOneIsRecomputedWithAWarning) {
  const fs::path dir = fresh_dir("pneufem_ideal_cache_stale");
  const Scene scene = Scene::load("");
  int calls = 0;
  std::vector<double> times = kTimes;
  auto compute = [&] { return ++calls, one_trial(times); };
  std::vector<std::string> warnings;
  cached_ideal(dir.string(), "k", scene, times, compute, warnings);
  times.push_back(30.0);  // another protocol's reports under the same key (an edited file)
  EXPECT_EQ(cached_ideal(dir.string(), "k", scene, times, compute, warnings).source, "computed");
  EXPECT_EQ(calls, 2);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("does not hold this protocol's report times"), std::string::npos) << warnings[0];
  EXPECT_EQ(cached_ideal(dir.string(), "k", scene, times, compute, warnings).records.size(), times.size());
  EXPECT_EQ(calls, 2);  // replaced: read now

  std::ofstream(dir / "ideal_k.csv") << "trial,time_s,pressure_kPa,angle_deg\n1,0.5,0.1,";  // cut short
  EXPECT_EQ(cached_ideal(dir.string(), "k", scene, times, compute, warnings).source, "computed");
  EXPECT_EQ(calls, 3);
  EXPECT_EQ(warnings.size(), 2u);
  fs::remove_all(dir);
}

TEST(CachedIdeal, KeyChangesWithTheVersionNotWithASwitchedOffEffectsConstants) {
  const std::vector<std::string> small = {"geometry.chambers=2", "mesh.h_mm=8"};
  const Scene scene = Scene::load("", small);
  const Model model = build_model(scene)->model;
  std::vector<std::string> other_tau = small;
  other_tau.push_back("materials.silicone.fatigue.tau_s=123.0");  // fatigue is off: no part of the ideal model
  std::vector<std::string> softer = small;
  softer.push_back("materials.silicone.stiffness_scale=0.9");
  const std::string key = ideal_cache_key(scene, model, "v1");
  EXPECT_EQ(key, ideal_cache_key(Scene::load("", other_tau), model, "v1"));
  EXPECT_NE(key, ideal_cache_key(scene, model, "v2"));
  EXPECT_NE(key, ideal_cache_key(Scene::load("", softer), model, "v1"));
}

TEST(CachedIdeal, AnglesCsvHasTheExtrapolatedColumnOnlyWhenATrialWasSkipped) {
  std::vector<StateRecord> recs = one_trial({1.0, 2.0});
  EXPECT_EQ(angles_csv(recs).substr(0, angles_csv(recs).find('\n')), "trial,time_s,pressure_kPa,angle_deg");
  EXPECT_NE(angles_csv(recs).find("\n1,1.000000,0.333333,0.014286\n"), std::string::npos) << angles_csv(recs);
  recs[1].extrapolated = true;
  const std::string text = angles_csv(recs);
  EXPECT_EQ(text.substr(0, text.find('\n')), "trial,time_s,pressure_kPa,angle_deg,extrapolated");
  EXPECT_NE(text.find(",0\n"), std::string::npos);
  EXPECT_NE(text.find(",1\n"), std::string::npos);
}

}  // namespace
}  // namespace pneufem
