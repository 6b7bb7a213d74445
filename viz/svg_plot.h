#pragma once
// Publication-style 2-D charts as standalone SVG, with no dependencies, for the offline HTML
// reports and the sweep plots: a Figure holds a grid of Axes; an Axes draws line, marker,
// vertical range/error-bar and grouped-bar series against a linear or log x axis and one or two
// y axes (Y-Y plots, e.g. pressure and angle against time), with 1-2-5 ticks, labels with units,
// a legend and a title.
//
// Output is deterministic: the same figure gives the same bytes (fixed number formatting, ids
// derived from the content), so plots can be compared in tests and kept under version control.
//
//   svg::Figure fig(640, 400);
//   svg::Axes& ax = fig.axes();
//   ax.xlabel("pressure (kPa)").ylabel("bending angle (deg)");
//   svg::Style dots;
//   dots.marker = svg::Marker::Circle;
//   ax.line(p, angle, "trial 1", dots);
//   ax.range_bars(p, lo, hi, "spread");
//   fig.save("angle.svg");
#include <cstdint>
#include <string>
#include <vector>

namespace pneufem::svg {

/// Tick positions of one axis.
struct Ticks {
  double lo = 0.0, hi = 1.0;  ///< the axis range (the data range widened to whole ticks when asked)
  double step = 0.0;          ///< linear: the 1-2-5 step between major ticks; log: 0
  std::vector<double> major;  ///< labelled ticks
  std::vector<double> minor;  ///< unlabelled ticks (log axes: 2..9 within each decade)
};

/// About `target` intervals of a 1, 2 or 5 times 10^k step covering [lo, hi]; with `widen` the
/// range grows outward to whole steps. A degenerate range (lo == hi) is opened around the value.
Ticks linear_ticks(double lo, double hi, int target = 5, bool widen = true);
/// Log axis (lo > 0): decades, with 2 and 5 of each decade labelled when the range spans at most
/// three decades; with `widen` the range grows outward to whole decades.
Ticks log_ticks(double lo, double hi, bool widen = true);
/// Label of a linear tick: as many decimals as the step needs, no "-0".
std::string tick_label(double v, double step);
/// Text made safe for SVG/XML character data and attribute values (& < > " ' escaped, control
/// characters other than tab and newline dropped).
std::string escape(const std::string& text);

enum class Marker { None, Circle, Square, Diamond, Triangle, Cross, Plus };
enum class YAxis { Left, Right };
enum class Legend { UpperRight, UpperLeft, LowerRight, LowerLeft, None };

/// Look of a series. Empty colour = the next colour of the (colour-blind safe) palette.
struct Style {
  std::string color;
  double line_width = 1.5;      ///< px; 0 = no line
  std::string dash;             ///< SVG dash array, e.g. "5 3"; empty = solid
  Marker marker = Marker::None;
  double marker_size = 3.5;     ///< marker radius, px
  bool filled = true;           ///< filled or hollow markers
  YAxis axis = YAxis::Left;
};

/// One group of grouped bars: a value per category (NaN = no bar) and optional symmetric errors.
struct BarGroup {
  std::string label;
  std::vector<double> values;
  std::vector<double> errors;  ///< empty or one per value
  std::string color;           ///< empty = palette
};

struct Rect {
  double x = 0, y = 0, width = 0, height = 0;
};

/// Data-to-pixel map of one axis (px_lo is where `lo` lands; y axes run upward).
class Scale {
 public:
  Scale(double lo, double hi, double px_lo, double px_hi, bool log);
  double operator()(double v) const;
  bool log() const { return log_; }

 private:
  double lo_, hi_, px_lo_, px_hi_;
  bool log_;
};

class Axes {
 public:
  Axes& title(const std::string& text);
  Axes& xlabel(const std::string& text);
  Axes& ylabel(const std::string& text);
  /// Label of the right-hand y axis (shown when set or when a series uses YAxis::Right).
  Axes& y2label(const std::string& text);
  Axes& xlog(bool on = true);
  /// Fixed limits; without them the range is the data's, widened to whole ticks.
  Axes& xlim(double lo, double hi);
  Axes& ylim(double lo, double hi);
  Axes& y2lim(double lo, double hi);
  Axes& legend(Legend where);
  /// A line through (x, y); NaN values break it. With style.marker also marks the points.
  Axes& line(const std::vector<double>& x, const std::vector<double>& y, const std::string& label = "",
             Style style = {});
  /// Markers only (default: filled circles).
  Axes& scatter(const std::vector<double>& x, const std::vector<double>& y, const std::string& label = "",
                Style style = {});
  /// Vertical bars from lo to hi at each x, with caps (a range or spread).
  Axes& range_bars(const std::vector<double>& x, const std::vector<double>& lo, const std::vector<double>& hi,
                   const std::string& label = "", Style style = {});
  /// Vertical error bars y +- err.
  Axes& error_bars(const std::vector<double>& x, const std::vector<double>& y, const std::vector<double>& err,
                   const std::string& label = "", Style style = {});
  /// Grouped bars: the x axis becomes categorical (category i at x = i), one bar per group in
  /// each category, e.g. the error per pressure step grouped by trial. Replaces earlier bars.
  Axes& grouped_bars(const std::vector<std::string>& categories, const std::vector<BarGroup>& groups);
  /// A one-line note centred in the plot area (e.g. "no data").
  Axes& note(const std::string& text);

 private:
  friend class Figure;
  enum class Kind { Line, Scatter, Range };
  struct Series {
    Kind kind;
    std::vector<double> x, y, y_hi;  ///< Range: y = lo, y_hi = hi
    std::string label;
    Style style;
  };
  Axes& add(Series s);

  std::string title_, xlabel_, ylabel_, y2label_, note_;
  bool xlog_ = false;
  bool has_xlim_ = false, has_ylim_ = false, has_y2lim_ = false;
  double xlim_[2] = {0, 1}, ylim_[2] = {0, 1}, y2lim_[2] = {0, 1};
  Legend legend_ = Legend::UpperRight;
  std::vector<Series> series_;
  std::vector<std::string> categories_;
  std::vector<BarGroup> bars_;
  int colors_used_ = 0;
};

class Figure {
 public:
  /// Space around each plot area, px (the right margin grows when a right y axis is shown).
  struct Margins {
    double left = 68, right = 20, right_y2 = 68, top = 14, bottom = 50, axes_title = 22, figure_title = 30;
  };

  Figure(double width_px = 640, double height_px = 420, int rows = 1, int cols = 1);
  Figure& title(const std::string& text);
  /// Prefix of the element ids (clip paths); by default derived from the content, so several
  /// figures can be inlined in one HTML page without clashing.
  Figure& id(const std::string& prefix);
  Axes& axes(int row = 0, int col = 0);
  const Axes& axes(int row = 0, int col = 0) const;

  /// Pixel rectangle of the data area of an axes, and its resolved scales.
  Rect plot_area(int row = 0, int col = 0) const;
  Scale x_scale(int row = 0, int col = 0) const;
  Scale y_scale(int row = 0, int col = 0, YAxis which = YAxis::Left) const;
  Ticks x_ticks(int row = 0, int col = 0) const;
  Ticks y_ticks(int row = 0, int col = 0, YAxis which = YAxis::Left) const;

  /// The complete SVG document (with XML declaration), or just the <svg> element for inlining.
  std::string svg() const;
  std::string svg_element() const;
  /// Writes svg() atomically (temporary file + rename); throws std::runtime_error naming the path.
  void save(const std::string& path) const;

  Margins margins;

 private:
  struct Layout;
  const Axes& at(int row, int col) const;
  Layout layout(int row, int col) const;
  std::string render_axes(int row, int col) const;

  double width_, height_;
  int rows_, cols_;
  std::string title_, id_;
  std::vector<Axes> axes_;
};

}  // namespace pneufem::svg
