// The figures of the compare report (app/compare/report.h), on a recording and model traces made
// here without the FEM: each trial keeps one colour (measured and model alike), axes start at the
// data (no -10 kPa pressure axis, whole-number trial ticks), text is readable at a journal's
// column width, and every figure comes with the CSV of its series.
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include <gtest/gtest.h>

#include "analysis/model_vs_measured.h"
#include "app/compare/report.h"
#include "viz/svg_plot.h"

namespace pneufem {
namespace {

namespace fs = std::filesystem;

/// Staircase 0-30 kPa in 10 kPa steps held 4 s, 400 Hz pressure (dipping to -0.3 kPa at rest, as a
/// sensor's noise does) and 30 fps angle; the angle creeps in each hold and grows by trial.
Recording recording(int trials) {
  Recording rec;
  for (int k = 1; k <= trials; ++k) {
    TrialRecording t;
    t.trial = k;
    for (int i = 0; i <= 6400; ++i) {
      const double s = i / 400.0, level = 10.0 * std::min(3.0, std::floor(s / 4.0));
      t.pressure_kPa.t_s.push_back(s);
      t.pressure_kPa.value.push_back(level == 0.0 ? -0.3 * (i % 2) : level);
    }
    for (int j = 0; j <= 480; ++j) {
      const double s = j / 30.0, level = 10.0 * std::min(3.0, std::floor(s / 4.0)), in_hold = std::fmod(s, 4.0);
      t.angle_deg.t_s.push_back(s);
      t.angle_deg.value.push_back(level * (1.0 + 0.05 * k) + 0.1 * level * in_hold / 4.0 + 0.02 * std::sin(7.0 * j));
    }
    rec.trials.push_back(t);
  }
  return rec;
}

/// The model: the elastic part of the measurement, 10 % low.
CompareRunResult model_of(const Recording& rec) {
  CompareRunResult r;
  std::vector<Series> model;
  for (const TrialRecording& t : rec.trials) {
    TrialTrace tr;
    tr.trial = t.trial;
    tr.angle_deg.t_s = t.angle_deg.t_s;
    for (double s : t.angle_deg.t_s) tr.angle_deg.value.push_back(0.9 * 10.0 * std::min(3.0, std::floor(s / 4.0)));
    model.push_back(tr.angle_deg);
    r.drive.trials.push_back(tr);
  }
  r.comparison = compare_recording(rec, model);
  return r;
}

const ReportFigure& find(const std::vector<ReportFigure>& figs, const std::string& name) {
  for (const ReportFigure& f : figs)
    if (f.name == name) return f;
  throw std::runtime_error("no figure " + name);
}

std::size_t count(const std::string& s, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t p = s.find(what); p != std::string::npos; p = s.find(what, p + 1)) ++n;
  return n;
}

class CompareReport : public ::testing::Test {
 protected:
  void SetUp() override {
    rec_ = recording(3);
    r_ = model_of(rec_);
    HistoryEntry h;
    h.label = "test";
    h.nrmse = r_.comparison.nrmse;
    figs_ = compare_figures(rec_, r_, {h});
  }
  Recording rec_;
  CompareRunResult r_;
  std::vector<ReportFigure> figs_;
};

TEST_F(CompareReport, EachTrialKeepsOneColourForMeasuredAndModel) {
  for (std::size_t k = 0; k < 3; ++k) {
    const std::string svg = find(figs_, "fig_trial_" + std::to_string(k + 1)).svg;
    const std::string c = svg::palette_color(k);
    EXPECT_NE(svg.find("<g fill=\"" + c + "\" stroke=\"" + c + "\""), std::string::npos) << k;  // measured dots
    EXPECT_NE(svg.find("stroke=\"" + c + "\" stroke-width=\"1.5\""), std::string::npos) << k;   // model line
    for (std::size_t other = 0; other < 3; ++other) {
      if (other != k) {
        EXPECT_EQ(svg.find(svg::palette_color(other)), std::string::npos) << k << " " << other;
      }
    }
  }
  // Angle vs pressure: the dots, the spread bars and the dashed model of trial 2 share its colour,
  // and the legend lists each trial once.
  const std::string ap = find(figs_, "fig_angle_pressure").svg;
  const std::string c2 = svg::palette_color(1);
  EXPECT_NE(ap.find("<g fill=\"" + c2 + "\" stroke=\"" + c2 + "\""), std::string::npos);
  EXPECT_NE(ap.find("stroke=\"" + c2 + "\" stroke-width=\"1.5\" stroke-linejoin=\"round\" stroke-linecap=\"round\" "
                    "stroke-dasharray=\"5 3\""),
            std::string::npos);
  EXPECT_NE(ap.find("stroke=\"" + c2 + "\" stroke-width=\"1\""), std::string::npos);  // the range bars
  EXPECT_EQ(count(ap, ">trial 2 measured<"), 1u);
  EXPECT_EQ(count(ap, ">trial 2 model<"), 0u);  // named in the CSV, explained by the caption
  EXPECT_NE(find(figs_, "fig_angle_pressure").csv.find(",trial 2 model,left,"), std::string::npos);
}

TEST_F(CompareReport, AxesStartAtTheData) {
  // The pressure dips to -0.3 kPa: its axis starts just below that, not at -10 kPa.
  const std::string t1 = find(figs_, "fig_trial_1").svg;
  EXPECT_EQ(t1.find(">-10<"), std::string::npos);
  EXPECT_EQ(t1.find(">-5<"), std::string::npos);
  EXPECT_NE(t1.find("text-anchor=\"start\" font-size=\"14\">0<"), std::string::npos);  // the right axis's 0
  // Trials are whole numbers.
  const std::string nrmse = find(figs_, "fig_nrmse").svg;
  for (const char* label : {">1<", ">2<", ">3<"}) EXPECT_NE(nrmse.find(label), std::string::npos) << label;
  for (const char* label : {">0.5<", ">1.5<", ">2.5<", ">3.5<"}) EXPECT_EQ(nrmse.find(label), std::string::npos) << label;
}

TEST_F(CompareReport, TextIsAtLeastSevenPointAtAColumnWidth) {
  // Every figure is 480 px wide per column of axes (the heat map at least 480 px), printed at 3.5 in.
  for (const ReportFigure& f : figs_) {
    const std::string& s = f.svg;
    std::size_t fonts = 0;
    for (std::size_t p = s.find("font-size=\""); p != std::string::npos; p = s.find("font-size=\"", p + 1), ++fonts)
      EXPECT_GE(std::stod(s.substr(p + 11)) * 252.0 / svg::kColumnWidthPx, 7.0 - 1e-9) << f.name;
    EXPECT_GT(fonts, 0u) << f.name;
  }
}

TEST_F(CompareReport, EveryFigureHasItsSeriesAsCsvAndTheFramesAreWrittenToo) {
  std::set<std::string> names;
  for (const ReportFigure& f : figs_) {
    EXPECT_TRUE(names.insert(f.name).second) << f.name;
    EXPECT_GT(count(f.csv, "\n"), 3u) << f.name;
  }
  // The heat map: one row per trial x step; the trial time series: every plotted point.
  const ReportFigure& map = find(figs_, "fig_residual_map");
  EXPECT_EQ(map.csv.rfind("trial,step_kPa,mean_residual_deg\n", 0), 0u);
  EXPECT_EQ(count(map.csv, "\n"), 1u + 3u * 4u);
  EXPECT_NE(map.csv.find("\n2,30,"), std::string::npos) << map.csv;
  const std::string t1 = find(figs_, "fig_trial_1").csv;
  EXPECT_EQ(count(t1, ",pressure (measured),right,"), 1601u);  // 6401 samples, every 4th: <= 2000 points
  EXPECT_NE(t1.find("1,angle (model),left,0,0,,\n"), std::string::npos) << t1.substr(0, 400);

  const std::string frames = model_vs_measured_csv(r_.comparison);
  EXPECT_EQ(frames.rfind("trial,time_s,measured_deg,model_deg,residual_deg\n", 0), 0u);
  EXPECT_EQ(count(frames, "\n"), 1u + r_.comparison.frames.size());
  const ComparedFrame& f = r_.comparison.frames.back();
  EXPECT_NE(frames.find("3," + svg::csv_number(f.t_s) + "," + svg::csv_number(f.measured_deg) + "," +
                        svg::csv_number(f.model_deg) + "," + svg::csv_number(f.model_deg - f.measured_deg) + "\n"),
            std::string::npos);

  const fs::path dir = fs::temp_directory_path() / "pneufem_test_report";
  fs::remove_all(dir);
  fs::create_directories(dir);
  write_report_figures(dir.string(), figs_, r_.comparison);
  for (const ReportFigure& fig : figs_) {
    EXPECT_TRUE(fs::exists(dir / (fig.name + ".svg"))) << fig.name;
    EXPECT_TRUE(fs::exists(dir / (fig.name + ".csv"))) << fig.name;
  }
  std::ifstream in(dir / "model_vs_measured.csv");
  std::stringstream text;
  text << in.rdbuf();
  EXPECT_EQ(text.str(), frames);
  fs::remove_all(dir);
}

TEST(CompareReportHeatmap, ColoursComeFromTheColourBlindSafeMap) {
  const std::string s = heatmap_svg({{-2.0, 0.0, 1.0}}, {"trial 1"}, {"0", "10", "20"}, "t", "deg");
  EXPECT_NE(s.find("fill=\"" + svg::diverging_color(-1.0) + "\""), std::string::npos);
  EXPECT_NE(s.find("fill=\"" + svg::diverging_color(0.0) + "\""), std::string::npos);
  EXPECT_NE(s.find("fill=\"" + svg::diverging_color(0.5) + "\""), std::string::npos);
  EXPECT_EQ(heatmap_csv({{-2.0, std::nan("")}}, {"1"}, {"0", "10"}, "trial", "step_kPa", "v"),
            "trial,step_kPa,v\n1,0,-2\n1,10,\n");
}

}  // namespace
}  // namespace pneufem
