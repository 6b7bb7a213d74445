// The files `pneufem diagnose` writes (app/diagnose/output.cpp, and report.md of report.cpp, which
// needs the same diagnosis): what it leaves for a user who diagnoses a second recording of one protocol
// (issue 28, item 5): the cache of the first recording's elastic FEM work is reused, history.jsonl
// carries the error per trial of every model, and report.md tells the diagnosis with the numbers of
// diagnosis.json. One case for all of them (a suite fixture: the whole file is one ctest test):
// a small 3-chamber actuator, two trials to 20 kPa, hidden stiffness made by `pneufem synth`
// (full FEM, controller overshoot, sensor and tracking noise), and a second recording of the same
// protocol with noise of its own; each diagnosed once, sharing one cache directory.
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <sstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "analysis/measurements.h"
#include "app/compare/history.h"
#include "app/diagnose/command.h"
#include "app/diagnose/evaluator.h"
#include "app/synth/command.h"

namespace fs = std::filesystem;

namespace pneufem {
namespace {

const std::vector<std::string> kScene = {"geometry.chambers=3", "mesh.h_mm=6",   "load.max_kPa=20", "load.step_kPa=10",
                                         "load.hold_s=3",       "load.ramp_s=0.5", "load.trials=2",  "output.vtu=\"none\""};

std::string read_text(const fs::path& p) {
  std::ifstream in(p);
  return std::string((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
}

double peak_kPa(const Recording& rec) {
  double m = 0.0;
  for (const TrialRecording& t : rec.trials)
    for (double p : t.pressure_kPa.value) m = std::max(m, p);
  return m;
}

class DiagnoseOutputs : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = fs::temp_directory_path() / "pneufem_diag_outputs";
    fs::remove_all(dir_);
    fs::create_directories(dir_);
    SynthOptions so;
    so.sets = kScene;
    so.hidden = {"stiffness"};
    so.out_csv = (dir_ / "first.csv").string();
    so.seed = 11;
    so.angle_noise_deg = 0.05;
    run_synth(so);
    // The second recording: the same protocol (the same inlet, trials and frames), its own
    // pressure sensor noise (synth's 0.1 kPa) and tracking noise (0.05 deg), so its measured peak
    // differs from the first's, as two recordings of one protocol do.
    first_ = read_measurements_csv(so.out_csv);
    second_ = first_;
    std::mt19937_64 rng(12);
    std::normal_distribution<double> pressure_noise(0.0, 0.1), angle_noise(0.0, 0.05);
    for (TrialRecording& t : second_.trials) {
      for (double& p : t.pressure_kPa.value) p += pressure_noise(rng);
      for (double& a : t.angle_deg.value) a += angle_noise(rng);
    }
    write_measurements_csv((dir_ / "second.csv").string(), second_);
    auto options = [](const std::string& data, const std::string& out) {
      DiagnoseOptions o;
      o.data_path = (dir_ / data).string();
      o.out_dir = (dir_ / out).string();
      o.candidates = {"stiffness", "pressure_lag"};
      o.max_effects = 2;
      o.max_evaluations = 15;  // the outputs are the point here, not the last digit of the fit
      o.cache_dir = (dir_ / "cache").string();
      return o;
    };
    first_result_ = run_diagnosis(Scene::load("", kScene), options("first.csv", "first"));
    second_result_ = run_diagnosis(Scene::load("", kScene), options("second.csv", "second"));
  }
  static void TearDownTestSuite() { fs::remove_all(dir_); }

  static nlohmann::json diagnosis_json(const std::string& out) {
    return nlohmann::json::parse(read_text(dir_ / out / "diagnosis.json"));
  }

  static inline fs::path dir_;
  static inline Recording first_, second_;
  static inline DiagnosisResult first_result_, second_result_;
};

// The key of the elastic work (elastic_reference_peak_Pa): a recording of the scene's protocol gets
// 1.1 x the commanded peak whatever its own peak; another one its peak rounded up to the grid (5 kPa
// for 10-100 kPa). Always at or above the recorded peak. The hidden datasets peak at 30.93 kPa on a
// 30 kPa protocol (7 % overshoot of a 10 kPa step).
TEST(ElasticReferencePeak, SameForEveryRecordingOfOneProtocolAndAboveItsPeak) {
  EXPECT_DOUBLE_EQ(elastic_reference_peak_Pa(30e3, 30.93e3), 33e3);
  EXPECT_DOUBLE_EQ(elastic_reference_peak_Pa(30e3, 30.10e3), 33e3);
  EXPECT_DOUBLE_EQ(elastic_reference_peak_Pa(30e3, 30e3), 33e3);       // angles only: the scene's pressure
  EXPECT_DOUBLE_EQ(elastic_reference_peak_Pa(45e3, 30.9e3), 35e3);     // another protocol: the grid
  EXPECT_DOUBLE_EQ(elastic_reference_peak_Pa(45e3, 31.4e3), 35e3);
  EXPECT_DOUBLE_EQ(elastic_reference_peak_Pa(45e3, 49.6e3), 50e3);     // above the headroom: the grid
  EXPECT_DOUBLE_EQ(elastic_reference_peak_Pa(0.0, 7.3e3), 7.5e3);      // no protocol; 0.5 kPa grid below 10 kPa
  EXPECT_DOUBLE_EQ(elastic_reference_peak_Pa(0.0, 120e3), 150e3);      // 50 kPa grid above 100 kPa
  for (double p = 1e3; p < 200e3; p *= 1.07) {
    EXPECT_GE(elastic_reference_peak_Pa(0.0, p), p);
    EXPECT_GE(elastic_reference_peak_Pa(20e3, p), p);
  }
}

// Item 1: the second recording's diagnosis reads the elastic path from the first one's cache entry.
// Keyed by the exact measured peak (before 2026-11-27) it missed: the peaks differ (checked).
TEST_F(DiagnoseOutputs, ASecondRecordingOfTheSameProtocolReusesTheCache) {
  ASSERT_NE(peak_kPa(first_), peak_kPa(second_));  // what defeated the old key
  const nlohmann::json a = diagnosis_json("first"), b = diagnosis_json("second");
  EXPECT_EQ(a["method"]["elastic_path_source"], "computed");
  EXPECT_TRUE(b["method"]["elastic_path_source"].get<std::string>().starts_with("cache ")) << b["method"];
  const double ref_kPa = b["method"]["reference_peak_kPa"].get<double>();
  EXPECT_EQ(a["method"]["reference_peak_kPa"].get<double>(), ref_kPa);
  EXPECT_DOUBLE_EQ(ref_kPa, 22.0);  // 1.1 x the protocol's 20 kPa
  EXPECT_GE(ref_kPa, peak_kPa(first_));
  EXPECT_GE(ref_kPa, peak_kPa(second_));
  // The report says so too.
  EXPECT_NE(read_text(dir_ / "second" / "report.md").find("elastic path cache "), std::string::npos);
  // The recording is diagnosed, not the cache: hidden stiffness is found in both.
  EXPECT_EQ(first_result_.missing_effect, "stiffness");
  EXPECT_EQ(second_result_.missing_effect, "stiffness");
}

// Item 2: every line of history.jsonl (the baseline and the model after each round) carries the
// NRMSE and the RMSE (deg) of every trial, equal to diagnosis.json's to the bit (both are written
// with the shortest round-trip representation), and the fitted model's error is below the baseline's
// in every trial (hidden stiffness: 30 % in the catalog's truth, far above the noise).
TEST_F(DiagnoseOutputs, HistoryCarriesTheErrorPerTrialOfEveryModel) {
  const std::vector<HistoryEntry> h = read_history((dir_ / "second").string());
  ASSERT_EQ(h.size(), 1 + second_result_.selected.size());
  ASSERT_GE(h.size(), 2u);
  for (const HistoryEntry& e : h) {
    EXPECT_EQ(e.trial_nrmse.size(), 2u) << e.label;
    EXPECT_EQ(e.trial_rmse_deg.size(), 2u) << e.label;
  }
  EXPECT_EQ(h.front().trial_nrmse, second_result_.baseline_nrmse_per_trial);
  EXPECT_EQ(h.front().trial_rmse_deg, second_result_.baseline_rmse_deg_per_trial);
  EXPECT_EQ(h.back().trial_nrmse, second_result_.final_nrmse_per_trial);
  EXPECT_EQ(h.back().trial_rmse_deg, second_result_.final_rmse_deg_per_trial);
  EXPECT_EQ(h.back().label, "diagnose + stiffness (path model)");
  const nlohmann::json j = diagnosis_json("second");
  EXPECT_EQ(j["final_nrmse_per_trial"].get<std::vector<double>>(), h.back().trial_nrmse);
  for (std::size_t k = 0; k < 2; ++k) EXPECT_LT(h.back().trial_nrmse[k], h.front().trial_nrmse[k]) << "trial " << k + 1;
}

/// The numbers of the row of `trial` in report.md's per-trial table ("| 1 | a | b | c | d |").
std::vector<double> table_row(const std::string& report, int trial) {
  const std::string start = "\n| " + std::to_string(trial) + " | ";
  const std::size_t at = report.find(start);
  if (at == std::string::npos) return {};
  std::string row = report.substr(at + start.size(), report.find('\n', at + 1) - at - start.size());
  std::replace(row.begin(), row.end(), '|', ' ');
  std::istringstream in(row);
  std::vector<double> v;
  for (double x; in >> x;) v.push_back(x);
  return v;
}

// Item 3: report.md exists (written atomically: no temporary left), holds the per-trial table of the
// baseline beside the final model with diagnosis.json's numbers (printed to 4 decimals for NRMSE, 3
// for degrees: equal within half the last digit printed, plus round-off), every round with its
// candidates and their reasons, and the constants chosen.
TEST_F(DiagnoseOutputs, ReportHoldsThePerTrialTableOfDiagnosisJson) {
  const fs::path out = dir_ / "second";
  ASSERT_TRUE(fs::exists(out / "report.md"));
  EXPECT_FALSE(fs::exists(out / "report.md.tmp"));
  const std::string report = read_text(out / "report.md");
  const nlohmann::json j = diagnosis_json("second");
  EXPECT_NE(report.find("| trial | baseline NRMSE | final NRMSE | baseline RMSE (deg) | final RMSE (deg) |"), std::string::npos)
      << report;
  for (int k = 1; k <= 2; ++k) {
    const std::vector<double> row = table_row(report, k);
    ASSERT_EQ(row.size(), 4u) << "trial " << k << "\n" << report;
    const std::size_t i = static_cast<std::size_t>(k - 1);
    EXPECT_NEAR(row[0], j["baseline"]["nrmse_per_trial"][i].get<double>(), 0.5e-4 + 1e-12);
    EXPECT_NEAR(row[1], j["final_nrmse_per_trial"][i].get<double>(), 0.5e-4 + 1e-12);
    EXPECT_NEAR(row[2], j["baseline"]["rmse_deg_per_trial"][i].get<double>(), 0.5e-3 + 1e-12);
    EXPECT_NEAR(row[3], j["final_rmse_deg_per_trial"][i].get<double>(), 0.5e-3 + 1e-12);
  }
  EXPECT_NE(report.find("**Missing effect: stiffness**"), std::string::npos);
  EXPECT_NE(report.find("## Round 1"), std::string::npos);
  EXPECT_NE(report.find("Chosen: **stiffness** with scale = "), std::string::npos);
  EXPECT_NE(report.find("Constants of the selected effects"), std::string::npos);
  for (const CandidateResult& c : second_result_.candidates) EXPECT_NE(report.find(c.why), std::string::npos) << c.effect;
  EXPECT_NE(report.find("Recording: `" + (dir_ / "second.csv").string() + "`: 2 trial(s)"), std::string::npos);
}

}  // namespace
}  // namespace pneufem
