// The SVG chart writer: 1-2-5 ticks and log ticks for chosen ranges, data-to-pixel mapping on
// linear, log and right-hand axes, text escaping, well-formed and deterministic output, atomic save.
#include "viz/svg_plot.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include <gtest/gtest.h>

namespace {

using namespace pneufem;
namespace fs = std::filesystem;

// A minimal XML well-formedness check: one root element, balanced and properly nested tags,
// quoted attributes without '<', only the five predefined entities or character references,
// no raw '<' or '&' in text, and no control characters. Returns "" or what is wrong.
std::string xml_problem(const std::string& s) {
  std::vector<std::string> stack;
  int roots = 0;
  auto entity_ok = [&](std::size_t amp) {
    const std::size_t semi = s.find(';', amp);
    if (semi == std::string::npos || semi - amp > 8) return false;
    const std::string e = s.substr(amp + 1, semi - amp - 1);
    if (e == "amp" || e == "lt" || e == "gt" || e == "quot" || e == "apos") return true;
    return e.size() > 1 && e[0] == '#';
  };
  std::size_t i = 0;
  if (s.rfind("<?xml", 0) == 0) i = s.find("?>") + 2;
  while (i < s.size()) {
    const char c = s[i];
    if (static_cast<unsigned char>(c) < 0x20 && c != '\n' && c != '\t' && c != '\r') return "control character";
    if (c == '&') {
      if (!entity_ok(i)) return "bad entity at " + std::to_string(i);
      ++i;
      continue;
    }
    if (c != '<') {
      if (stack.empty() && !std::isspace(static_cast<unsigned char>(c))) return "text outside the root";
      ++i;
      continue;
    }
    if (s.compare(i, 4, "<!--") == 0) {
      i = s.find("-->", i);
      if (i == std::string::npos) return "unclosed comment";
      i += 3;
      continue;
    }
    const bool closing = s[i + 1] == '/';
    std::size_t j = i + (closing ? 2 : 1);
    std::size_t k = j;
    while (k < s.size() && (std::isalnum(static_cast<unsigned char>(s[k])) || s[k] == ':' || s[k] == '-' || s[k] == '_')) ++k;
    const std::string name = s.substr(j, k - j);
    if (name.empty()) return "empty tag name at " + std::to_string(i);
    // Attributes: name="value" pairs.
    while (k < s.size() && s[k] != '>' && s[k] != '/') {
      if (std::isspace(static_cast<unsigned char>(s[k]))) {
        ++k;
        continue;
      }
      while (k < s.size() && s[k] != '=' && s[k] != '>') ++k;
      if (s[k] != '=' || s[k + 1] != '"') return "unquoted attribute in <" + name + ">";
      const std::size_t end = s.find('"', k + 2);
      if (end == std::string::npos) return "unterminated attribute";
      for (std::size_t m = k + 2; m < end; ++m) {
        if (s[m] == '<') return "'<' in an attribute of <" + name + ">";
        if (s[m] == '&' && !entity_ok(m)) return "bad entity in an attribute";
      }
      k = end + 1;
    }
    if (k >= s.size()) return "unterminated tag <" + name;
    const bool self_closing = s[k] == '/';
    if (self_closing && s[k + 1] != '>') return "bad self-closing tag <" + name + ">";
    i = k + (self_closing ? 2 : 1);
    if (closing) {
      if (stack.empty() || stack.back() != name) return "unbalanced </" + name + ">";
      stack.pop_back();
    } else if (!self_closing) {
      if (stack.empty()) ++roots;
      stack.push_back(name);
    } else if (stack.empty()) {
      ++roots;
    }
  }
  if (!stack.empty()) return "unclosed <" + stack.back() + ">";
  if (roots != 1) return "expected one root element, found " + std::to_string(roots);
  return "";
}

std::size_t count(const std::string& s, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t p = s.find(what); p != std::string::npos; p = s.find(what, p + 1)) ++n;
  return n;
}

std::vector<double> v(std::initializer_list<double> l) { return l; }

svg::Style style(const std::string& color, svg::Marker marker = svg::Marker::None, svg::YAxis axis = svg::YAxis::Left) {
  svg::Style s;
  s.color = color;
  s.marker = marker;
  s.axis = axis;
  return s;
}

TEST(SvgTicks, LinearStepsAreOneTwoFive) {
  svg::Ticks t = svg::linear_ticks(0.0, 1.0);
  EXPECT_DOUBLE_EQ(t.step, 0.2);
  ASSERT_EQ(t.major.size(), 6u);
  EXPECT_EQ(t.major[3], 0.6);  // one rounding: not 0.6000000000000001
  EXPECT_EQ(t.lo, 0.0);
  EXPECT_EQ(t.hi, 1.0);

  t = svg::linear_ticks(0.0, 45.0);  // the 0-45 kPa staircase
  EXPECT_EQ(t.step, 10.0);
  EXPECT_EQ(t.hi, 50.0);
  EXPECT_EQ(t.major, v({0, 10, 20, 30, 40, 50}));

  t = svg::linear_ticks(-3.7, 12.1);
  EXPECT_EQ(t.step, 5.0);
  EXPECT_EQ(t.major, v({-5, 0, 5, 10, 15}));

  t = svg::linear_ticks(0.0012, 0.0047);
  EXPECT_DOUBLE_EQ(t.step, 0.001);
  EXPECT_EQ(t.major.size(), 5u);

  t = svg::linear_ticks(0.3, 9.7, 5, false);  // fixed limits: ticks inside only
  EXPECT_EQ(t.lo, 0.3);
  EXPECT_EQ(t.major, v({2, 4, 6, 8}));

  t = svg::linear_ticks(7.0, 7.0);  // degenerate range is opened around the value
  EXPECT_LT(t.lo, 7.0);
  EXPECT_GT(t.hi, 7.0);

  // Any range: the step is 1, 2 or 5 x 10^k, the ticks cover the range, not too many or few.
  for (double lo : {-1234.5, -0.02, 0.0, 3.3e-7, 17.0})
    for (double span : {1e-6, 0.37, 1.0, 42.0, 9.9e5}) {
      t = svg::linear_ticks(lo, lo + span);
      const double m = t.step / std::pow(10.0, std::floor(std::log10(t.step) + 1e-9));
      EXPECT_TRUE(std::abs(m - 1) < 1e-9 || std::abs(m - 2) < 1e-9 || std::abs(m - 5) < 1e-9) << lo << " " << span;
      EXPECT_LE(t.lo, lo);
      EXPECT_GE(t.hi, lo + span);
      EXPECT_GE(t.major.size(), 3u);
      EXPECT_LE(t.major.size(), 12u);
    }
}

TEST(SvgTicks, LabelsHaveTheDecimalsOfTheStep) {
  EXPECT_EQ(svg::tick_label(0.6000000000000001, 0.2), "0.6");
  EXPECT_EQ(svg::tick_label(-0.0, 1.0), "0");
  EXPECT_EQ(svg::tick_label(-1e-17, 0.05), "0.00");
  EXPECT_EQ(svg::tick_label(45.0, 5.0), "45");
  EXPECT_EQ(svg::tick_label(2.5e-5, 5e-6), "2.5e-05");
  EXPECT_EQ(svg::tick_label(3e6, 1e6), "3e+06");
}

TEST(SvgTicks, LogDecadesAndMantissas) {
  svg::Ticks t = svg::log_ticks(100.0, 1000.0);
  EXPECT_EQ(t.major, v({100, 200, 500, 1000}));
  EXPECT_EQ(t.minor.size(), 6u);  // 300, 400, 600, 700, 800, 900

  t = svg::log_ticks(3.0, 700.0);  // widened to whole decades
  EXPECT_EQ(t.lo, 1.0);
  EXPECT_EQ(t.hi, 1000.0);
  EXPECT_EQ(t.major.size(), 10u);  // 1 2 5 10 20 50 100 200 500 1000

  t = svg::log_ticks(1.0, 1e6);  // many decades: decades only, 2..9 as minor ticks
  EXPECT_EQ(t.major, v({1, 10, 100, 1e3, 1e4, 1e5, 1e6}));
  EXPECT_EQ(t.minor.size(), 6u * 8u);

  t = svg::log_ticks(1e-3, 1e12);  // 15 decades: every second decade labelled
  EXPECT_EQ(t.major.size(), 8u);
  EXPECT_TRUE(t.minor.empty());

  t = svg::log_ticks(150.0, 400.0, false);  // inside one decade: linear positions
  EXPECT_GE(t.major.size(), 3u);
  for (double x : t.major) EXPECT_TRUE(x >= 150.0 && x <= 400.0) << x;
}

TEST(SvgFigure, DataPointMapsToTheExpectedPixel) {
  svg::Figure fig(480, 320);  // one column at the print width: margins as given
  fig.axes().xlim(0, 10).ylim(0, 100).scatter({5.0}, {25.0}, "", style("#123456"));
  // Plot area = figure minus the default margins: left 76, right 20, top 16, bottom 58.
  const svg::Rect r = fig.plot_area();
  EXPECT_EQ(r.x, 76.0);
  EXPECT_EQ(r.y, 16.0);
  EXPECT_EQ(r.width, 384.0);
  EXPECT_EQ(r.height, 246.0);
  EXPECT_DOUBLE_EQ(fig.x_scale()(5.0), 268.0);  // 76 + 384 / 2
  EXPECT_DOUBLE_EQ(fig.y_scale()(25.0), 200.5);  // 16 + 246 * (1 - 0.25)
  const std::string s = fig.svg();
  EXPECT_NE(s.find("<circle cx=\"268\" cy=\"200.5\" r=\"3.5\"/>"), std::string::npos) << s;
  EXPECT_EQ(xml_problem(s), "");
  // A figure twice as wide per column has twice the margins (and text): the same figure, scaled.
  svg::Figure big(960, 640);
  big.axes().xlim(0, 10).ylim(0, 100);
  EXPECT_EQ(big.plot_area().x, 152.0);
  EXPECT_EQ(big.plot_area().width, 768.0);
}

TEST(SvgFigure, LogAxisMapsDecadesEvenly) {
  svg::Figure fig(480, 320);
  svg::Axes& ax = fig.axes();
  ax.xlog().xlim(10, 1000).ylim(0, 1).scatter({100.0, std::sqrt(10.0) * 100.0, -1.0}, {0.5, 0.5, 0.5});
  const svg::Scale x = fig.x_scale();
  EXPECT_TRUE(x.log());
  EXPECT_DOUBLE_EQ(x(10.0), 76.0);
  EXPECT_DOUBLE_EQ(x(100.0), 76.0 + 192.0);
  EXPECT_NEAR(x(std::sqrt(10.0) * 100.0), 76.0 + 288.0, 1e-9);
  EXPECT_TRUE(std::isnan(x(-1.0)));  // not drawable on a log axis
  const std::string s = fig.svg();
  EXPECT_EQ(count(s, "<circle"), 2u);  // the negative x is left out
  EXPECT_EQ(xml_problem(s), "");

  // The auto range is the data's, padded by 4 % of its decades (not widened to whole decades);
  // labels outside 1e-3..1e4 use a superscript exponent, printed at 7 pt in a column.
  svg::Figure f2(480, 320);
  f2.axes().xlog().line({2e-7, 3e-5}, {1.0, 2.0});
  const double pad = std::pow(3e-5 / 2e-7, 0.04);
  EXPECT_DOUBLE_EQ(f2.x_ticks().lo, 2e-7 / pad);
  EXPECT_DOUBLE_EQ(f2.x_ticks().hi, 3e-5 * pad);
  EXPECT_NE(f2.svg().find("font-size=\"13.5\">-5</tspan>"), std::string::npos) << f2.svg();
}

TEST(SvgFigure, TextIsEscaped) {
  svg::Figure fig(300, 200);
  fig.title("a < b & \"c\" 'd'\x01");
  fig.axes().xlabel("p (kPa) <in>").ylabel("angle (\xC2\xB0)").line({0, 1}, {0, 1}, "R&D \"fit\"");
  const std::string s = fig.svg();
  EXPECT_NE(s.find("a &lt; b &amp; &quot;c&quot; &apos;d&apos;</text>"), std::string::npos) << s;
  EXPECT_NE(s.find("p (kPa) &lt;in&gt;"), std::string::npos);
  EXPECT_NE(s.find("R&amp;D &quot;fit&quot;"), std::string::npos);
  EXPECT_NE(s.find("angle (\xC2\xB0)"), std::string::npos);  // UTF-8 passes through
  EXPECT_EQ(s.find('\x01'), std::string::npos);
  EXPECT_EQ(xml_problem(s), "");
  EXPECT_EQ(svg::escape("x\ty\nz\x1f"), "x\ty\nz");
}

// A figure with everything: two axes, a right-hand y axis, lines with NaN gaps and markers,
// range and error bars, grouped bars with errors, log x, a legend in each corner and a note.
svg::Figure everything() {
  svg::Figure fig(720, 640, 2, 2);
  fig.title("Pneu-net <fatigue> & creep");
  svg::Style dashed;
  dashed.dash = "5 3";
  svg::Style hollow = style("", svg::Marker::Diamond);
  hollow.filled = false;
  svg::Axes& yy = fig.axes(0, 0);
  yy.title("trial 1").xlabel("time (s)").ylabel("pressure (kPa)").y2label("angle (deg)");
  yy.line({0, 1, 2, 3, 4}, {0, 5, 5, 10, 10}, "pressure", dashed);
  yy.line({0, 1, 2, std::nan(""), 4}, {0, 30, 33, 60, 62}, "angle",
          style("", svg::Marker::Circle, svg::YAxis::Right));
  svg::Axes& ap = fig.axes(0, 1);
  ap.xlabel("pressure (kPa)").ylabel("angle (deg)").legend(svg::Legend::UpperLeft);
  ap.line({5, 10, 15}, {10, 25, 45}, "model", style("", svg::Marker::Square));
  ap.range_bars({5, 10, 15}, {8, 22, 40}, {12, 27, 49}, "spread");
  ap.error_bars({5, 10, 15}, {11, 26, 44}, {1, 2, 3}, "", style("#000000"));
  ap.scatter({5, 10, 15}, {9, 24, 47}, "data", hollow);
  svg::Axes& bars = fig.axes(1, 0);
  bars.xlabel("pressure step").ylabel("|error| (deg)").legend(svg::Legend::LowerRight);
  bars.grouped_bars({"5 kPa", "10 kPa", "15 kPa"},
                    {{"trial 1", {1, 2, 3}, {0.1, 0.2, 0.3}, ""}, {"trial 2", {1.5, std::nan(""), -0.5}, {}, ""}});
  svg::Axes& lg = fig.axes(1, 1);
  lg.xlog().xlabel("tau_s (s)").ylabel("NRMSE").legend(svg::Legend::LowerLeft);
  lg.scatter({100, 316, 1000}, {0.1, 0.05, 0.02}, "ok", style("", svg::Marker::Triangle));
  lg.scatter({3000}, {0.0}, "failed", style("#cc0000", svg::Marker::Cross));
  lg.scatter({10}, {0.0}, "", style("", svg::Marker::Plus));
  lg.note("note & more");
  return fig;
}

TEST(SvgFigure, ComplexFigureIsWellFormedAndDeterministic) {
  const svg::Figure fig = everything();
  const std::string s = fig.svg();
  EXPECT_EQ(xml_problem(s), "") << s;
  EXPECT_EQ(s.rfind("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<svg xmlns=\"http://www.w3.org/2000/svg\"", 0), 0u);
  EXPECT_EQ(s, everything().svg());  // same figure, same bytes
  for (const char* label : {"pressure", "angle", "model", "spread", "data", "trial 1", "trial 2", "ok", "failed",
                            "5 kPa", "15 kPa", "note &amp; more"})
    EXPECT_NE(s.find(label), std::string::npos) << label;
  EXPECT_EQ(count(s, "<clipPath"), 4u);
  EXPECT_EQ(xml_problem(fig.svg_element()), "");

  // The right-hand axis widens the right margin and has its own scale.
  // 360 px per column: margins at 360/480 of theirs.
  const svg::Rect r = fig.plot_area(0, 0);
  EXPECT_DOUBLE_EQ(r.width, 360.0 - 0.75 * (76.0 + 76.0));
  EXPECT_DOUBLE_EQ(fig.y_ticks(0, 0, svg::YAxis::Left).lo, 0.0);  // the data start at 0: no padding below
  EXPECT_NEAR(fig.y_ticks(0, 0, svg::YAxis::Left).hi, 10.4, 1e-12);
  const svg::Ticks right = fig.y_ticks(0, 0, svg::YAxis::Right);
  EXPECT_GE(right.hi, 62.0);
  EXPECT_LT(right.hi, 100.0);
  EXPECT_NE(right.step, fig.y_ticks(0, 0, svg::YAxis::Left).step);

  // Ids: derived from the content (distinct figures do not clash when inlined), or given.
  svg::Figure other(300, 200);
  other.axes().line({0, 1}, {1, 0});
  const auto clip_id = [](const std::string& t) {
    const std::size_t p = t.find("<clipPath id=\"");
    return t.substr(p + 14, t.find('"', p + 14) - p - 14);
  };
  EXPECT_NE(clip_id(s), clip_id(other.svg()));
  other.id("fig7");
  EXPECT_EQ(clip_id(other.svg()), "fig7-clip-0");
}

TEST(SvgFigure, GroupedBarHeightsFollowTheScale) {
  svg::Figure fig(480, 320);
  fig.axes().ylim(0, 20).grouped_bars({"a", "b"}, {{"g", {10, 20}, {}, "#111111"}});
  // Plot height 246: value 10 is half of it, value 20 all of it; bars fill 80 % of each slot.
  const std::string s = fig.svg();
  EXPECT_NE(s.find("height=\"123\""), std::string::npos) << s;
  EXPECT_NE(s.find("height=\"246\"/>"), std::string::npos);
  EXPECT_NE(s.find("width=\"153.6\""), std::string::npos);  // 0.8 * 384 / 2
  EXPECT_THROW(fig.axes().line({1, 2}, {1}), std::invalid_argument);
  EXPECT_THROW(fig.axes(1, 0), std::out_of_range);
}

TEST(SvgFigure, SaveIsAtomic) {
  const fs::path dir = fs::temp_directory_path() / "pneufem_svg_test";
  fs::remove_all(dir);
  fs::create_directories(dir);
  const svg::Figure fig = everything();
  const fs::path f = dir / "fig.svg";
  fig.save(f.string());
  auto read = [](const fs::path& p) {
    std::ifstream in(p);
    std::stringstream text;
    text << in.rdbuf();
    return text.str();
  };
  EXPECT_EQ(read(f), fig.svg());
  EXPECT_EQ(read(dir / "fig.csv"), fig.csv());  // the series next to the picture
  EXPECT_FALSE(fs::exists(dir / "fig.svg.tmp"));
  EXPECT_FALSE(fs::exists(dir / "fig.csv.tmp"));
  EXPECT_THROW(fig.save((dir / "missing" / "fig.svg").string()), std::runtime_error);
  fs::remove_all(dir);
}

// Axes start at the data: a measured pressure that dips to -0.3 kPa (sensor noise) and reaches 45
// kPa gets an axis from just below -0.3 to just above 45 (before 2026-11-27: -10 to 50, widened to
// whole ticks), with its ticks inside; an axis whose data start at 0 starts at 0.
TEST(SvgFigure, AxesSpanTheDataNotWholeTicks) {
  svg::Figure fig;
  svg::Axes& ax = fig.axes();
  ax.line({0, 10, 20}, {-0.3, 20.0, 45.0}, "pressure").line({0, 10, 20}, {0.0, 5.0, 33.0}, "angle", style("", svg::Marker::None, svg::YAxis::Right));
  const svg::Ticks y = fig.y_ticks(), y2 = fig.y_ticks(0, 0, svg::YAxis::Right), x = fig.x_ticks();
  EXPECT_NEAR(y.lo, -0.3 - 0.04 * 45.3, 1e-12);
  EXPECT_NEAR(y.hi, 45.0 + 0.04 * 45.3, 1e-12);
  EXPECT_EQ(y.major.front(), 0.0);  // ticks inside the data's range
  EXPECT_LE(y.major.back(), 45.0);
  EXPECT_EQ(y2.lo, 0.0);
  EXPECT_EQ(x.lo, 0.0);
  EXPECT_NEAR(x.hi, 20.8, 1e-12);
  // Negative data keep their padding; data ending at 0 end there.
  svg::Figure neg;
  neg.axes().line({0, 1}, {-4.0, 0.0});
  EXPECT_NEAR(neg.y_ticks().lo, -4.16, 1e-12);
  EXPECT_EQ(neg.y_ticks().hi, 0.0);
}

TEST(SvgFigure, IntegerAxisTicksOnlyWholeNumbers) {
  for (int n : {1, 2, 3, 10}) {
    svg::Figure fig;
    std::vector<double> trial, nrmse;
    for (int k = 1; k <= n; ++k) trial.push_back(k), nrmse.push_back(0.01 * k);
    fig.axes().xinteger().line(trial, nrmse);
    const svg::Ticks t = fig.x_ticks();
    ASSERT_FALSE(t.major.empty()) << n;
    for (double m : t.major) EXPECT_EQ(m, std::round(m)) << n;
    EXPECT_GE(t.major.front(), 1.0) << n;
    EXPECT_LE(t.major.back(), n) << n;
    if (n <= 3) {
      EXPECT_EQ(t.major.front(), 1.0) << n;
    }
  }
  EXPECT_EQ(svg::linear_ticks(0.9, 3.1, 5, false, true).major, v({1, 2, 3}));
  EXPECT_EQ(svg::linear_ticks(0.9, 3.1, 5, false, false).step, 0.5);
}

/// Every font-size of an SVG document, px.
std::vector<double> font_sizes(const std::string& svg) {
  std::vector<double> out;
  for (std::size_t p = svg.find("font-size=\""); p != std::string::npos; p = svg.find("font-size=\"", p + 1))
    out.push_back(std::stod(svg.substr(p + 11)));
  return out;
}

// Printed at a journal's single column (3.5 in = 252 pt per column of axes), no text of any
// figure is below 7 pt, whatever the figure's pixel size.
TEST(SvgFigure, TextIsAtLeastSevenPointAtASingleColumnWidth) {
  struct Case {
    double width, height;
    int rows, cols;
  };
  for (const Case c : {Case{480, 320, 1, 1}, Case{320, 240, 1, 1}, Case{640, 420, 1, 1}, Case{960, 320, 1, 2},
                       Case{720, 640, 2, 2}}) {
    svg::Figure fig(c.width, c.height, c.rows, c.cols);
    fig.title("a title");
    for (int r = 0; r < c.rows; ++r)
      for (int k = 0; k < c.cols; ++k)
        fig.axes(r, k).title("t").xlabel("x").ylabel("y").y2label("y2").xlog().line({1e-6, 1e-5}, {1, 2}, "a");
    const double pt_per_px = 252.0 / (c.width / c.cols);
    const std::vector<double> sizes = font_sizes(fig.svg());
    ASSERT_GE(sizes.size(), 5u);
    for (double f : sizes) EXPECT_GE(f * pt_per_px, 7.0 - 1e-9) << c.width << " px: " << f;
  }
}

TEST(SvgFigure, CsvHoldsEveryPlottedPoint) {
  const svg::Figure fig = everything();
  const std::string csv = fig.csv();
  EXPECT_EQ(csv.rfind("# Pneu-net <fatigue> & creep: every plotted series", 0), 0u) << csv;
  EXPECT_NE(csv.find("# panel trial 1: x = time (s); y = pressure (kPa); right y = angle (deg)\n"), std::string::npos);
  EXPECT_NE(csv.find("\npanel,series,axis,x,y,y_low,y_high\n"), std::string::npos);
  // A line point, a NaN (an empty cell), a right-axis point, a range bar, an error bar, a bar with its
  // error and a bar without a value.
  EXPECT_NE(csv.find("trial 1,pressure,left,3,10,,\n"), std::string::npos);
  EXPECT_NE(csv.find("trial 1,angle,right,,60,,\n"), std::string::npos);  // x NaN: an empty cell
  EXPECT_NE(csv.find("trial 1,angle,right,4,62,,\n"), std::string::npos);
  EXPECT_NE(csv.find("2,spread,left,10,,22,27\n"), std::string::npos);
  EXPECT_NE(csv.find("2,series 1,left,15,,41,47\n"), std::string::npos);  // unlabelled error bars
  EXPECT_NE(csv.find("3,trial 1,left,15 kPa,3," + svg::csv_number(3 - 0.3) + "," + svg::csv_number(3 + 0.3) + "\n"),
            std::string::npos);
  EXPECT_NE(csv.find("3,trial 2,left,10 kPa,,,\n"), std::string::npos);
  // One row per point: 5 + 5 + 3 + 3 + 3 + 3 (panel 2) + 3 + 3 (bars) + 3 + 1 + 1 (log panel).
  const std::string body = csv.substr(csv.find("\npanel,series") + 1);
  EXPECT_EQ(count(body, "\n"), 1u + 33u);
  EXPECT_EQ(svg::csv_field("a,b"), "\"a,b\"");
  EXPECT_EQ(svg::csv_field("say \"x\""), "\"say \"\"x\"\"\"");
  EXPECT_EQ(svg::csv_field("#1"), "\"#1\"");
  EXPECT_EQ(svg::csv_number(0.1), "0.1");
  EXPECT_EQ(svg::csv_number(std::nan("")), "");
}

TEST(SvgColours, PaletteAndDivergingMapAreColourBlindSafe) {
  EXPECT_EQ(svg::palette_color(0), "#0072B2");  // Okabe & Ito blue, vermillion, bluish green ...
  EXPECT_EQ(svg::palette_color(1), "#D55E00");
  EXPECT_EQ(svg::palette_color(8), svg::palette_color(0));
  EXPECT_EQ(svg::diverging_color(-1.0), "#2166AC");  // ColorBrewer RdBu ends and centre
  EXPECT_EQ(svg::diverging_color(0.0), "#F7F7F7");
  EXPECT_EQ(svg::diverging_color(1.0), "#B2182B");
  EXPECT_EQ(svg::diverging_color(7.0), "#B2182B");
  EXPECT_EQ(svg::diverging_color(std::nan("")), "#F7F7F7");
  EXPECT_EQ(svg::diverging_color(0.25), "#FDDBC7");  // a stop of the map: (0.25 + 1) / 2 * 8 = 5
}

// The default legend takes the emptiest corner: data rising to the upper right push it to the upper
// left; a falling line to the upper right.
TEST(SvgFigure, BestLegendCornerAvoidsTheData) {
  auto legend_x = [](const svg::Figure& f) {
    const std::string s = f.svg();
    const std::size_t p = s.find("fill-opacity=\"0.85\"");
    const std::size_t r = s.rfind("<rect x=\"", p);
    return std::stod(s.substr(r + 9));
  };
  svg::Figure rising;
  rising.axes().line({0, 1, 2, 3, 4}, {0, 1, 4, 9, 16}, "rising");
  svg::Figure falling;
  falling.axes().line({0, 1, 2, 3, 4}, {16, 9, 4, 1, 0}, "falling");
  const double mid = rising.plot_area().x + 0.5 * rising.plot_area().width;
  EXPECT_LT(legend_x(rising), mid);
  EXPECT_GT(legend_x(falling), mid);
  svg::Figure pinned;
  pinned.axes().legend(svg::Legend::LowerRight).line({0, 1, 2, 3, 4}, {0, 1, 4, 9, 16}, "rising");
  EXPECT_GT(legend_x(pinned), mid);  // a chosen corner is kept even where it covers data
}

}  // namespace
