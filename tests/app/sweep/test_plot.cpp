// The sweep's plot (app/sweep/plot.h): a single-column figure whose x axis is the swept range (not
// widened to whole ticks) and whose y axis spans the points (not from 0); failed points marked at
// the bottom; its CSV holds every plotted point.
#include "app/sweep/plot.h"

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace {

using namespace pneufem;

SweepPoint point(int index, double value, double final_nrmse, const std::string& status = "ok") {
  SweepPoint q;
  q.index = index;
  q.values = {value};
  q.status = status;
  if (status == "ok") q.nrmse = {0.01, final_nrmse};
  return q;
}

ParamSpec param(double lo, double hi, bool log) {
  ParamSpec p;
  p.key = "materials.silicone.fatigue.tau_s";
  p.lo = lo, p.hi = hi, p.log = log;
  return p;
}

TEST(SweepPlot, LinearAxisIsTheSweptRangeAndTheYAxisThePoints) {
  // 0.85..1.25 widened to whole 0.1 ticks would be 0.8..1.3; the NRMSEs 0.30..0.36 from 0 would
  // leave them in the top sixth of the plot (the plot of earlier versions).
  const std::vector<ParamSpec> params = {param(0.85, 1.25, false)};
  const std::vector<SweepPoint> points = {point(1, 0.85, 0.36), point(2, 1.05, 0.30), point(3, 1.25, 0.33)};
  const svg::Figure fig = sweep_figure(params, 0, points);
  const svg::Ticks x = fig.x_ticks(), y = fig.y_ticks();
  const double pad = 0.04 * (1.25 - 0.85);
  EXPECT_NEAR(x.lo, 0.85 - pad, 1e-12);
  EXPECT_NEAR(x.hi, 1.25 + pad, 1e-12);
  EXPECT_GT(y.lo, 0.29);  // at the data, not 0
  EXPECT_LT(y.lo, 0.30);
  EXPECT_GT(y.hi, 0.36);
  EXPECT_LT(y.hi, 0.37);
  const std::string svg = fig.svg();
  EXPECT_NE(svg.find("width=\"480\""), std::string::npos) << "single-column width";
  // Every point in the CSV, in the order of the swept value.
  const std::string csv = fig.csv();
  EXPECT_NE(csv.find(",ok,left,0.85,0.36,,"), std::string::npos) << csv;
  EXPECT_NE(csv.find(",ok,left,1.05,0.3,,"), std::string::npos) << csv;
  EXPECT_NE(csv.find(",ok,left,1.25,0.33,,"), std::string::npos) << csv;
}

TEST(SweepPlot, LogAxisIsTheSweptRangeInDecades) {
  // 150..800 s on a log axis: whole decades would be 100..1000.
  const std::vector<ParamSpec> params = {param(150.0, 800.0, true)};
  const std::vector<SweepPoint> points = {point(1, 150.0, 0.2), point(2, 800.0, 0.25)};
  const svg::Ticks x = sweep_figure(params, 0, points).x_ticks();
  const double f = std::pow(800.0 / 150.0, 0.04);
  EXPECT_NEAR(x.lo, 150.0 / f, 1e-9);
  EXPECT_NEAR(x.hi, 800.0 * f, 1e-9);
}

TEST(SweepPlot, FailedPointsSitAtTheBottomOfThePointsRange) {
  const std::vector<ParamSpec> params = {param(1.0, 3.0, false)};
  const std::vector<SweepPoint> points = {point(1, 1.0, 0.5), point(2, 2.0, 0.0, "failed"), point(3, 3.0, 0.7)};
  const svg::Figure fig = sweep_figure(params, 0, points);
  const std::string csv = fig.csv();
  EXPECT_NE(csv.find(",failed,left,2,0.5,,"), std::string::npos) << csv;
  EXPECT_GT(fig.y_ticks().lo, 0.45);  // the failed point does not pull the axis to 0
  EXPECT_NE(fig.svg().find(">failed</text>"), std::string::npos);
}

TEST(SweepPlot, NoFinishedPointSaysSo) {
  const std::vector<ParamSpec> params = {param(1.0, 3.0, false)};
  EXPECT_NE(sweep_figure(params, 0, {}).svg().find("no finished points yet"), std::string::npos);
  EXPECT_NE(sweep_figure(params, 0, {point(1, 2.0, 0.0, "failed")}).svg().find("no point succeeded"), std::string::npos);
}

}  // namespace
