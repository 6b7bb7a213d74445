// `pneufem compare` end to end: a tiny scene against a canonical CSV made from the model itself
// (its staircase sampled at 400 Hz / 30 fps, driven through simulate_recording) plus a known
// perturbation of the angle, so the metrics are non-trivial. The CLI's metrics.json must equal
// the library's numbers, report.html must be well-formed and hold every figure, history.jsonl
// must grow by one line per run, and malformed data must fail cleanly without touching DIR. A
// recording of angles alone is driven by the scene's staircase (compare and diagnose).
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "analysis/csv_scan.h"
#include "analysis/model_vs_measured.h"
#include "app/compare/command.h"
#include "app/diagnose/command.h"
#include "app/simulate/drive.h"
#include "core/errors.h"
#include "scenes/build_model.h"
#include "tests/app/cli_helpers.h"
#include "tests/app/recording_helpers.h"

namespace pneufem {
namespace {

namespace fs = std::filesystem;

using Result = pneufem::test::CliResult;
inline Result run(const std::string& args) { return pneufem::test::run_cli(args); }
using pneufem::test::slurp;


long lines(const fs::path& p) {
  const std::string s = slurp(p);
  return static_cast<long>(std::count(s.begin(), s.end(), '\n'));
}

/// The number after the top-level key (two-space indent) of our metrics.json.
double top_number(const std::string& json, const std::string& key) {
  const std::string k = "\n  \"" + key + "\": ";
  const std::size_t p = json.find(k);
  if (p == std::string::npos) return std::nan("");
  return std::strtod(json.c_str() + p + k.size(), nullptr);
}

/// Tag balance of an HTML page with inline SVG: every non-void element closed in order.
std::string html_problem(const std::string& h) {
  static const std::vector<std::string> kVoid = {"meta", "br", "hr", "img", "input", "link"};
  std::vector<std::string> stack;
  for (std::size_t i = h.find('<'); i != std::string::npos; i = h.find('<', i + 1)) {
    if (h.compare(i, 4, "<!--") == 0 || h.compare(i, 2, "<!") == 0 || h.compare(i, 2, "<?") == 0) continue;
    const std::size_t e = h.find('>', i);
    if (e == std::string::npos) return "unterminated tag";
    const bool closing = h[i + 1] == '/';
    const std::size_t n0 = i + (closing ? 2 : 1);
    std::size_t n1 = n0;
    while (n1 < e && (std::isalnum(static_cast<unsigned char>(h[n1])) || h[n1] == '-')) ++n1;
    const std::string name = h.substr(n0, n1 - n0);
    if (name.empty()) return "bad tag at " + std::to_string(i);
    if (closing) {
      if (stack.empty() || stack.back() != name) return "unexpected </" + name + "> at " + std::to_string(i);
      stack.pop_back();
    } else if (h[e - 1] != '/' && std::find(kVoid.begin(), kVoid.end(), name) == kVoid.end()) {
      stack.push_back(name);
    }
  }
  return stack.empty() ? "" : "unclosed <" + stack.back() + ">";
}

const char* kScene = R"([geometry]
chambers = 3
[mesh]
h_mm = 6.0
[load]
max_kPa = 10.0
step_kPa = 5.0
hold_s = 4.0
ramp_s = 0.5
trials = 2
)";

class CompareCli : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(fs::temp_directory_path() / ("pneufem_compare_cli_" + std::to_string(::getpid())));
    fs::remove_all(*dir_);
    fs::create_directories(*dir_);
    std::ofstream(*dir_ / "tiny.toml") << kScene;
    const Scene scene = Scene::load((*dir_ / "tiny.toml").string());
    const std::unique_ptr<BuiltModel> bm = build_model(scene);
    Recording rec = test::rig_sampled(bm->load);
    const DriveResult model = simulate_recording(scene, rec, DriveOptions{});
    // Known perturbation: trial 1 = model + a slow wobble, trial 2 = a 5 % stiffer-looking
    // actuator (model / 1.05) lagging by a constant 0.2 deg.
    for (std::size_t k = 0; k < rec.trials.size(); ++k)
      for (std::size_t j = 0; j < rec.trials[k].angle_deg.t_s.size(); ++j) {
        const double t = rec.trials[k].angle_deg.t_s[j], m = model.trials[k].angle_deg.value[j];
        rec.trials[k].angle_deg.value[j] = k == 0 ? m + 0.1 * std::sin(t) : m / 1.05 - 0.2;
      }
    write_measurements_csv((*dir_ / "data.csv").string(), rec);
    std::vector<Series> traces;
    for (const TrialTrace& t : model.trials) traces.push_back(t.angle_deg);
    expected_ = new Comparison(compare_recording(read_measurements_csv((*dir_ / "data.csv").string()), traces));
  }
  static void TearDownTestSuite() {
    fs::remove_all(*dir_);
    delete expected_;
    delete dir_;
  }
  /// data.csv's angles alone, as video tracking writes them: no pressure column; with a trial
  /// column, or without one (each trial's clock restarting at 0).
  static void write_angles_alone(const fs::path& path, bool trial_column) {
    const Recording full = read_measurements_csv((*dir_ / "data.csv").string());
    ASSERT_EQ(full.trials.size(), 2u);
    std::ofstream out(path);
    out << (trial_column ? "trial,time_s,angle_deg\n" : "Time (s),Angle (deg)\n");
    for (const TrialRecording& tr : full.trials)
      for (std::size_t j = 0; j < tr.angle_deg.t_s.size(); ++j)
        out << (trial_column ? std::to_string(tr.trial) + "," : "") << csv::number_text(tr.angle_deg.t_s[j]) << ","
            << csv::number_text(tr.angle_deg.value[j]) << "\n";
  }
  static fs::path* dir_;
  static Comparison* expected_;
};
fs::path* CompareCli::dir_ = nullptr;
Comparison* CompareCli::expected_ = nullptr;

TEST_F(CompareCli, WritesEverythingAndMatchesTheLibrary) {
  const fs::path out = *dir_ / "out";
  const std::string args = "compare " + (*dir_ / "tiny.toml").string() + " --data " + (*dir_ / "data.csv").string() +
                           " --out " + out.string() + " --threads 2";
  const Result r = run(args);
  ASSERT_EQ(r.code, 0) << r.out;
  for (const char* f : {"metrics.json", "metrics.csv", "report.html", "history.jsonl", "scene.toml", "fig_trial_1.svg",
                        "fig_trial_2.svg", "fig_angle_pressure.svg", "fig_nrmse.svg", "fig_abs_error.svg",
                        "fig_error_spread.svg", "fig_residual_map.svg", "fig_residual_profile.svg", "fig_history.svg"})
    EXPECT_TRUE(fs::exists(out / f)) << f;
  EXPECT_TRUE(fs::exists(out / "vtu" / "worst_1.vtu"));
  const std::string m = slurp(out / "metrics.json");
  // Same data (the CSV round-trips bit for bit), same deterministic model: equal numbers.
  EXPECT_DOUBLE_EQ(top_number(m, "nrmse"), expected_->nrmse);
  EXPECT_DOUBLE_EQ(top_number(m, "rss_deg2"), expected_->rss_deg2);
  EXPECT_EQ(top_number(m, "n"), static_cast<double>(expected_->n));
  EXPECT_DOUBLE_EQ(top_number(m, "noise_floor_nrmse"), expected_->noise_floor_nrmse);
  EXPECT_GT(expected_->nrmse, 1e-3) << "the perturbation must show";
  ASSERT_EQ(expected_->trials.size(), 2u);
  EXPECT_NE(m.find("\"nrmse_mark\": "), std::string::npos);
  // metrics.csv: header + one row per trial x step.
  long rows = 1;
  for (const TrialComparison& t : expected_->trials) rows += static_cast<long>(t.steps.size());
  EXPECT_EQ(lines(out / "metrics.csv"), rows);

  const std::string html = slurp(out / "report.html");
  EXPECT_EQ(html_problem(html), "");
  std::size_t figs = 0;
  for (const auto& e : fs::directory_iterator(out))
    if (e.path().extension() == ".svg") ++figs;
  std::size_t inlined = 0;
  for (std::size_t p = html.find("<svg"); p != std::string::npos; p = html.find("<svg", p + 1)) ++inlined;
  EXPECT_EQ(inlined, figs);
  for (const char* s : {"Summary", "Where it fails", "Region sensitivity", "History"})
    EXPECT_NE(html.find(s), std::string::npos) << s;
  EXPECT_EQ(html.find("<script"), std::string::npos);
  EXPECT_EQ(html.find("<link"), std::string::npos);  // nothing loaded from elsewhere

  EXPECT_EQ(lines(out / "history.jsonl"), 1);
  const Result again = run(args + " --label second");
  ASSERT_EQ(again.code, 0) << again.out;
  EXPECT_EQ(lines(out / "history.jsonl"), 2);
  const std::vector<HistoryEntry> h = read_history(out.string());
  ASSERT_EQ(h.size(), 2u);
  EXPECT_EQ(h[0].label, "tiny.toml");
  EXPECT_EQ(h[1].label, "second");
  EXPECT_EQ(h[0].scene_hash, h[1].scene_hash);
  EXPECT_DOUBLE_EQ(h[1].nrmse, expected_->nrmse);
  EXPECT_EQ(h[1].trial_nrmse.size(), 2u);

  // Malformed data: exit 2 naming file and line; DIR untouched (no temporary files, same history).
  std::ofstream(*dir_ / "bad.csv") << "trial,time_s,pressure_kPa,angle_deg\n1,0,0.1,0\n1,0.0025,abc,\n";
  const Result bad = run("compare " + (*dir_ / "tiny.toml").string() + " --data " + (*dir_ / "bad.csv").string() +
                         " --out " + out.string());
  EXPECT_EQ(bad.code, 2) << bad.out;
  EXPECT_NE(bad.out.find("bad.csv:3:"), std::string::npos) << bad.out;
  EXPECT_EQ(lines(out / "history.jsonl"), 2);
  for (const auto& e : fs::directory_iterator(out)) EXPECT_NE(e.path().extension(), ".tmp") << e.path();
  const fs::path fresh = *dir_ / "fresh";
  EXPECT_EQ(run("compare --data " + (*dir_ / "bad.csv").string() + " --out " + fresh.string()).code, 2);
  EXPECT_FALSE(fs::exists(fresh));
}

// The same data as video alone (no pressure column, no trial column: each trial's clock restarts
// at 0): the scene's own staircase drives the model. The rig's record was that staircase sampled
// without noise, so the model solves the same pressures and the metrics are the library's to the
// equilibrium tolerance (1e-6 deg on angles of ~5 deg: 1e-6 relative is ample for NRMSEs ~1e-2).
TEST_F(CompareCli, AnglesAloneAreDrivenByTheScenesProtocol) {
  write_angles_alone(*dir_ / "video.csv", false);
  const fs::path out = *dir_ / "video_out";
  const Result r = run("compare " + (*dir_ / "tiny.toml").string() + " --data " + (*dir_ / "video.csv").string() +
                       " --out " + out.string() + " --threads 2");
  ASSERT_EQ(r.code, 0) << r.out;
  EXPECT_NE(r.out.find("no pressure column: the model is driven by the scene's [load]"), std::string::npos) << r.out;
  const std::string m = slurp(out / "metrics.json");
  EXPECT_NEAR(top_number(m, "nrmse"), expected_->nrmse, 1e-6 * expected_->nrmse);
  EXPECT_EQ(top_number(m, "n"), static_cast<double>(expected_->n));
  EXPECT_NE(m.find("\"trial\": 2"), std::string::npos);
}

// diagnose reads angles alone the same way: its baseline (the reduced elastic model against the
// data) is the one it finds with the pressure record, to the same tolerance as above, and so is the
// stiffness it calibrates (1e-4: the optimiser's tolerance on the scale).
TEST_F(CompareCli, DiagnoseOfAnglesAloneMatchesTheRecordWithPressure) {
  write_angles_alone(*dir_ / "video_diag.csv", true);
  const Scene scene = Scene::load((*dir_ / "tiny.toml").string());
  auto diagnose = [&](const std::string& data) {
    DiagnoseOptions o;
    o.data_path = (*dir_ / data).string();
    o.out_dir = (*dir_ / ("diag_" + data)).string();
    o.candidates = {"stiffness"};
    o.max_effects = 1;
    o.threads = 2;
    return run_diagnosis(scene, o);
  };
  const DiagnosisResult with_p = diagnose("data.csv"), alone = diagnose("video_diag.csv");
  EXPECT_NEAR(alone.baseline_nrmse, with_p.baseline_nrmse, 1e-6 * with_p.baseline_nrmse);
  ASSERT_EQ(alone.candidates.size(), 1u);
  ASSERT_EQ(with_p.candidates.size(), 1u);
  EXPECT_NEAR(alone.candidates[0].params[0], with_p.candidates[0].params[0], 1e-4);
}

// A model the FEM cannot follow to the end (trial 2's inlet driven 10x past the tiny actuator's
// ballooning limit): compare still compares and writes the frames solved before, says so
// ("status": "incomplete", the failure, exit code 3 as every physical failure), keeps trial 1's
// numbers exactly, and leaves the study history alone.
TEST_F(CompareCli, ModelThatStopsEarlyWritesTheSolvedPart) {
  Recording rec = read_measurements_csv((*dir_ / "data.csv").string());
  for (double& p : rec.trials[1].pressure_kPa.value) p *= 10.0;
  write_measurements_csv((*dir_ / "data_fail.csv").string(), rec);
  const fs::path out = *dir_ / "out_fail";
  const Result r = run("compare " + (*dir_ / "tiny.toml").string() + " --data " + (*dir_ / "data_fail.csv").string() +
                       " --out " + out.string() + " --threads 2 --set solver.min_increment_kPa=0.5");
  EXPECT_EQ(r.code, 3) << r.out;
  EXPECT_NE(r.out.find("simulation failed"), std::string::npos) << r.out;
  const std::string m = slurp(out / "metrics.json");
  EXPECT_NE(m.find("\"status\": \"incomplete\""), std::string::npos);
  EXPECT_NE(m.find("stopped early"), std::string::npos);
  EXPECT_EQ(m.find("nan"), std::string::npos) << "JSON has no NaN literal";
  const std::size_t t1 = m.find("\"trials\"");
  ASSERT_NE(t1, std::string::npos);
  const std::size_t n1 = m.find("\"nrmse\": ", t1);  // trial 1's (after its "nrmse_mark")
  ASSERT_NE(n1, std::string::npos);
  EXPECT_DOUBLE_EQ(std::strtod(m.c_str() + n1 + 9, nullptr), expected_->trials[0].nrmse);  // trial 1 complete
  EXPECT_EQ(html_problem(slurp(out / "report.html")), "");
  EXPECT_FALSE(fs::exists(out / "history.jsonl"));
}

TEST_F(CompareCli, RegionSensitivityFindsAPerturbedRegion) {
  // Measured = the model with the roof 5 % softer. Linearised about scale 1 with the 0.9
  // sensitivity, the roof's best scale is 0.95 up to the curvature of angle(scale) over
  // [0.9, 1] (a few 1e-3 for a smooth response), and it explains nearly all of the residual.
  const Scene scene = Scene::load((*dir_ / "tiny.toml").string());
  Recording rec = read_measurements_csv((*dir_ / "data.csv").string());
  const DriveResult soft = simulate_recording(scene.with({"regions.roof.stiffness_scale=0.95"}), rec, DriveOptions{});
  for (std::size_t k = 0; k < rec.trials.size(); ++k) rec.trials[k].angle_deg = soft.trials[k].angle_deg;
  write_measurements_csv((*dir_ / "soft.csv").string(), rec);
  CompareRunOptions opt;
  opt.data_path = (*dir_ / "soft.csv").string();
  opt.out_dir = (*dir_ / "regions").string();
  opt.regions = true;
  const CompareRunResult r = run_compare(scene, opt);
  ASSERT_GE(r.regions.size(), 2u);
  const auto roof = std::find_if(r.regions.begin(), r.regions.end(), [](const RegionSensitivity& g) {
    return g.region == "roof";
  });
  ASSERT_NE(roof, r.regions.end());
  EXPECT_NEAR(roof->best_scale, 0.95, 0.01);
  EXPECT_GT(roof->variance_fraction, 0.99);
  const std::string m = slurp(*dir_ / "regions" / "metrics.json");
  EXPECT_NE(m.find("\"region\": \"roof\""), std::string::npos);
  EXPECT_NE(slurp(*dir_ / "regions" / "report.html").find("fig_regions"), std::string::npos);
}

}  // namespace
}  // namespace pneufem
