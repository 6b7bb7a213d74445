#pragma once
// Publication-style 2-D charts as standalone SVG, with no dependencies, for the offline HTML
// reports and the sweep plots: a Figure holds a grid of Axes; an Axes draws line, marker,
// vertical range/error-bar and grouped-bar series against a linear or log x axis and one or two
// y axes (Y-Y plots, e.g. pressure and angle against time), with 1-2-5 ticks, labels with units,
// a legend and a title.
//
// Fit for a paper: every text size and margin scales with the width per column of axes, so that a
// figure printed at a journal's single-column width (3.5 in per column) has 7.4 pt tick labels,
// whatever its pixel size (kColumnWidthPx); axes span the data (padded by a few per cent, not
// widened to whole ticks, and not across zero when the data stop there); colours are Okabe & Ito's
// colour-blind safe palette, and the diverging map of heat maps is ColorBrewer's RdBu. Every
// plotted series is also available as CSV (Figure::csv; save() writes it next to the SVG), to
// redraw in matplotlib or a spreadsheet.
//
// Output is deterministic: the same figure gives the same bytes (fixed number formatting, ids
// derived from the content), so plots can be compared in tests and kept under version control.
//
//   svg::Figure fig(480, 320);
//   svg::Axes& ax = fig.axes();
//   ax.xlabel("pressure (kPa)").ylabel("bending angle (deg)");
//   svg::Style dots;
//   dots.marker = svg::Marker::Circle;
//   ax.line(p, angle, "trial 1", dots);
//   ax.range_bars(p, lo, hi, "spread");
//   fig.save("angle.svg");
#include <array>
#include <cstddef>
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

/// Width in px of one column of axes that is printed at a journal's single column (3.5 in): text
/// sizes and margins are given for it and scale with a figure's actual width per column.
inline constexpr double kColumnWidthPx = 480.0;

/// About `target` intervals of a 1, 2 or 5 times 10^k step covering [lo, hi]; with `widen` the
/// range grows outward to whole steps. A degenerate range (lo == hi) is opened around the value.
/// With `integer` the step is at least 1 (whole-number ticks: trials, counts).
Ticks linear_ticks(double lo, double hi, int target = 5, bool widen = true, bool integer = false);
/// Log axis (lo > 0): decades, with 2 and 5 of each decade labelled when the range spans at most
/// three decades; with `widen` the range grows outward to whole decades.
Ticks log_ticks(double lo, double hi, bool widen = true);
/// Label of a linear tick: as many decimals as the step needs, no "-0".
std::string tick_label(double v, double step);
/// Text made safe for SVG/XML character data and attribute values: xml_escape (viz/xml_escape.h),
/// the one escape of viz/'s XML (& < > " ' escaped, the control characters XML 1.0 forbids dropped).
std::string escape(const std::string& text);

/// A CSV field: quoted (quotes doubled) when it holds a comma, a quote or a newline, or starts with '#'.
std::string csv_field(const std::string& text);
/// A CSV number: the shortest text that reads back exactly; empty for NaN or infinity (no value).
std::string csv_number(double v);

/// Colour i of the palette (Okabe & Ito, colour-blind safe; cycles after 8): give one series of
/// a trial, measured and model alike, palette_color(trial index) so it keeps its colour everywhere.
std::string palette_color(std::size_t i);
/// Diverging colour for v in [-1, 1] (clamped): ColorBrewer RdBu, blue (-1) - near white (0) - red
/// (+1), readable with the common colour-vision deficiencies; "#RRGGBB".
std::string diverging_color(double v);

enum class Marker { None, Circle, Square, Diamond, Triangle, Cross, Plus };
enum class YAxis { Left, Right };
/// Where the legend goes; Best (the default) takes the corner of the plot area that covers the
/// least of the data (points, lines, bars), as matplotlib's loc="best".
enum class Legend { Best, UpperRight, UpperLeft, LowerRight, LowerLeft, None };

/// Look of a series. Empty colour = the next colour of the (colour-blind safe) palette.
struct Style {
  std::string color;
  double line_width = 1.5;      ///< px; 0 = no line
  std::string dash;             ///< SVG dash array, e.g. "5 3"; empty = solid
  Marker marker = Marker::None;
  double marker_size = 3.5;     ///< marker radius, px
  bool filled = true;           ///< filled or hollow markers
  YAxis axis = YAxis::Left;
  bool in_legend = true;        ///< false: the label names the series in csv() but not in the legend
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
  /// Whole-number ticks on the x axis (trials, runs).
  Axes& xinteger(bool on = true);
  /// Fixed limits; without them the range is the data's, padded by a few per cent.
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
  bool xlog_ = false, xinteger_ = false;
  bool has_xlim_ = false, has_ylim_ = false, has_y2lim_ = false;
  double xlim_[2] = {0, 1}, ylim_[2] = {0, 1}, y2lim_[2] = {0, 1};
  Legend legend_ = Legend::Best;
  std::vector<Series> series_;
  std::vector<std::string> categories_;
  std::vector<BarGroup> bars_;
  int colors_used_ = 0;
};

class Figure {
 public:
  /// Space around each plot area, px at kColumnWidthPx per column (scaled with the figure's width
  /// per column, as the text is); the right margin grows when a right y axis is shown.
  struct Margins {
    double left = 76, right = 20, right_y2 = 76, top = 16, bottom = 58, axes_title = 26, figure_title = 32;
  };

  Figure(double width_px = kColumnWidthPx, double height_px = 320, int rows = 1, int cols = 1);
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
  /// Every plotted series, one row per point: columns panel (the axes' title, or its number from
  /// 1), series (its legend label, or "series N"), axis (left/right), x (a category for bars), y,
  /// y_low, y_high (range and error bars); '#' lines first name the figure and each panel's axis
  /// labels (pandas.read_csv(path, comment="#")). Numbers are written to round-trip exactly.
  std::string csv() const;
  /// Writes svg() to `path` and csv() next to it (the same name ending in .csv), each atomically
  /// (temporary file + rename); throws std::runtime_error naming the path.
  void save(const std::string& path) const;

  Margins margins;

 private:
  struct Layout;
  /// Text and margin scale: the width per column over kColumnWidthPx.
  double text_scale() const { return width_ / cols_ / kColumnWidthPx; }
  const Axes& at(int row, int col) const;
  Layout layout(int row, int col) const;
  std::string render_axes(int row, int col) const;
  // The parts of render_axes, in drawing order (svg_plot.cpp): one axes being drawn is a Panel.
  struct Panel;
  static std::string draw_grid(const Panel& p);            ///< grid lines at the major ticks
  static std::string draw_data(const Panel& p);            ///< bars, range bars, lines (clipped)
  static std::string draw_markers(const Panel& p);         ///< markers (not clipped)
  std::string draw_frame_and_text(const Panel& p) const;   ///< frame, ticks, tick and axis labels, title, note
  static std::string draw_legend(const Panel& p);
  /// Pixel positions covered by the data of `a` (for the legend's Best corner).
  static std::vector<std::array<double, 2>> ink_samples(const Axes& a, const Scale& X, const Scale& Y, const Scale& Y2);

  double width_, height_;
  int rows_, cols_;
  std::string title_, id_;
  std::vector<Axes> axes_;
};

}  // namespace pneufem::svg
