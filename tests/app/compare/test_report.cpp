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

/// The width in px of an SVG document (its root's width attribute).
double svg_width(const std::string& svg) {
  const std::size_t p = svg.find("width=\"", svg.find("<svg"));
  return std::stod(svg.substr(p + 7));
}

/// The smallest text of an SVG document printed `columns` journal columns wide (3.5 in, 252 pt each).
double smallest_text_pt(const std::string& svg, int columns) {
  double smallest = 1e9;
  for (std::size_t p = svg.find("font-size=\""); p != std::string::npos; p = svg.find("font-size=\"", p + 1))
    smallest = std::min(smallest, std::stod(svg.substr(p + 11)) * 252.0 * columns / svg_width(svg));
  return smallest;
}

TEST_F(CompareReport, TextIsAtLeastSevenPointAtAColumnWidth) {
  // Every figure printed one journal column wide (3.5 in), or two for the two-panel figure and a
  // residual map of two columns (960 px).
  for (const ReportFigure& f : figs_) {
    const int columns = f.name == "fig_error_spread" ? 2
                        : f.name == "fig_residual_map" ? static_cast<int>(svg_width(f.svg) / svg::kColumnWidthPx)
                                                       : 1;
    EXPECT_GE(smallest_text_pt(f.svg, columns), 7.0 - 1e-9) << f.name;
    EXPECT_LT(smallest_text_pt(f.svg, columns), 1e9) << f.name << ": no text";
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

// The residual map is one or two journal columns wide (480 or 960 px) with 14 px text whatever the
// number of steps (a 10-step map was 744 px: 4.7 pt text at one column's width, 9.5 pt at two).
TEST(CompareReportHeatmap, AWideMapIsTwoColumnsWideWithTextReadableThere) {
  auto map = [](std::size_t steps) {
    std::vector<std::string> cols;
    std::vector<double> row;
    for (std::size_t j = 0; j < steps; ++j) cols.push_back(std::to_string(5 * j)), row.push_back(0.01 * j - 0.05);
    return heatmap_svg({row, row}, {"trial 1", "trial 2"}, cols, "t", "deg", "pressure step (kPa)");
  };
  // The first step's cells (-0.05 deg in both trials) with their number printed.
  auto cell_numbers = [](const std::string& svg) { return count(svg, ">-0.05</text>"); };
  const std::string seven = map(7), ten = map(10), thirty = map(30);
  EXPECT_EQ(svg_width(seven), svg::kColumnWidthPx);
  EXPECT_GE(smallest_text_pt(seven, 1), 7.0);
  EXPECT_EQ(cell_numbers(seven), 2u);
  EXPECT_EQ(svg_width(ten), 2 * svg::kColumnWidthPx);
  EXPECT_GE(smallest_text_pt(ten, 2), 7.0);
  EXPECT_EQ(cell_numbers(ten), 2u);
  EXPECT_EQ(count(ten, ">45</text>"), 1u);  // every step labelled
  // Thirty steps: cells of 28.5 px hold colour only; every second step is labelled.
  EXPECT_EQ(svg_width(thirty), 2 * svg::kColumnWidthPx);
  EXPECT_GE(smallest_text_pt(thirty, 2), 7.0);
  EXPECT_EQ(cell_numbers(thirty), 0u);
  EXPECT_EQ(count(thirty, ">140</text>"), 1u);
  EXPECT_EQ(count(thirty, ">145</text>"), 0u);
  EXPECT_EQ(count(thirty, "<rect x="), 60u);  // every cell is drawn
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
