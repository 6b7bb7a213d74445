#include "viz/svg_plot.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <limits>
#include <stdexcept>

#include "core/atomic_file.h"
#include "core/json_writer.h"
#include "viz/xml_escape.h"

namespace pneufem::svg {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
// Okabe & Ito's colour-blind safe palette (yellow left out: too light on white).
constexpr const char* kPalette[] = {"#0072B2", "#D55E00", "#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000", "#999999"};
constexpr int kPaletteSize = 8;
// Stands for the id prefix while rendering; escape() drops control characters, so user text
// can never contain it.
constexpr const char* kIdToken = "\x01";
// Fonts for print: a figure kColumnWidthPx wide (per column of axes) is printed at a journal's single
// column, 3.5 in, where 1 px = 3.5 * 72 / 480 = 0.525 pt; the smallest text (ticks, legend) is then
// 14 px = 7.4 pt, labels 7.9 pt, titles 8.4-8.9 pt, exponents 7.1 pt (journals ask for 6-8 pt).
constexpr double kTickFont = 14, kLabelFont = 15, kTitleFont = 16, kFigureTitleFont = 17, kExponentFont = 13.5;
// Padding of an axis range beyond its data, as a fraction of the span (points stay off the frame).
constexpr double kPad = 0.04;
constexpr const char* kInk = "#222222";

/// Pixel coordinates: two decimals, trailing zeros dropped, never "-0".
std::string px(double v) {
  if (!std::isfinite(v)) return "0";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.2f", v);
  std::string s = buf;
  if (s.find('.') != std::string::npos) {
    while (s.back() == '0') s.pop_back();
    if (s.back() == '.') s.pop_back();
  }
  if (s == "-0") s = "0";
  return s;
}

double pow10i(int e) { return e >= 0 ? std::pow(10.0, e) : 1.0 / std::pow(10.0, -e); }

/// k * m * 10^e with one rounding where possible (0.6, not 0.6000000000000001).
double scaled(double km, int e) { return e >= 0 ? km * std::pow(10.0, e) : km / std::pow(10.0, -e); }

/// Rough width of a text in px (UTF-8 code points times an average glyph width).
double text_width(const std::string& s, double font) {
  std::size_t n = 0;
  for (unsigned char c : s)
    if ((c & 0xC0) != 0x80) ++n;
  return 0.56 * font * static_cast<double>(n);
}

bool inside(double v, double lo, double hi) {
  const double tol = 1e-9 * std::max(std::abs(hi - lo), std::numeric_limits<double>::min());
  return v >= lo - tol && v <= hi + tol;
}

/// Log-axis label as SVG markup: plain numbers for 0.001 .. 10000, else m x 10^k.
std::string log_label(double v, double exponent_font) {
  const int e = static_cast<int>(std::floor(std::log10(v) + 1e-9));
  const double m = std::round(v / pow10i(e) * 1e6) / 1e6;
  char buf[48];
  if (e >= -3 && e <= 4) {
    std::snprintf(buf, sizeof buf, "%.6g", v);
    return buf;
  }
  std::string s;
  if (std::abs(m - 1.0) > 1e-9) {
    std::snprintf(buf, sizeof buf, "%g", m);
    s = std::string(buf) + "\xC3\x97";  // U+00D7 multiplication sign
  }
  std::snprintf(buf, sizeof buf, "%d", e);
  return s + "10<tspan dy=\"" + px(-0.45 * exponent_font) + "\" font-size=\"" + px(exponent_font) + "\">" + buf + "</tspan>";
}

std::string marker_svg(Marker m, double cx, double cy, double r) {
  const std::string x = px(cx), y = px(cy);
  switch (m) {
    case Marker::None: return "";
    case Marker::Circle: return "<circle cx=\"" + x + "\" cy=\"" + y + "\" r=\"" + px(r) + "\"/>";
    case Marker::Square:
      return "<rect x=\"" + px(cx - 0.9 * r) + "\" y=\"" + px(cy - 0.9 * r) + "\" width=\"" + px(1.8 * r) +
             "\" height=\"" + px(1.8 * r) + "\"/>";
    case Marker::Diamond:
      return "<path d=\"M" + x + " " + px(cy - 1.25 * r) + "L" + px(cx + 1.25 * r) + " " + y + "L" + x + " " +
             px(cy + 1.25 * r) + "L" + px(cx - 1.25 * r) + " " + y + "Z\"/>";
    case Marker::Triangle:
      return "<path d=\"M" + x + " " + px(cy - 1.3 * r) + "L" + px(cx + 1.15 * r) + " " + px(cy + 0.65 * r) + "L" +
             px(cx - 1.15 * r) + " " + px(cy + 0.65 * r) + "Z\"/>";
    case Marker::Cross:
      return "<path d=\"M" + px(cx - r) + " " + px(cy - r) + "L" + px(cx + r) + " " + px(cy + r) + "M" + px(cx - r) +
             " " + px(cy + r) + "L" + px(cx + r) + " " + px(cy - r) + "\"/>";
    case Marker::Plus:
      return "<path d=\"M" + px(cx - r) + " " + y + "L" + px(cx + r) + " " + y + "M" + x + " " + px(cy - r) + "L" + x +
             " " + px(cy + r) + "\"/>";
  }
  return "";
}

/// Opening <g> of a marker group: filled/hollow shapes, stroked crosses.
std::string marker_group(const Style& s) {
  if (s.marker == Marker::Cross || s.marker == Marker::Plus)
    return "<g fill=\"none\" stroke=\"" + escape(s.color) + "\" stroke-width=\"1.6\">";
  return "<g fill=\"" + (s.filled ? escape(s.color) : std::string("#ffffff")) + "\" stroke=\"" + escape(s.color) +
         "\" stroke-width=\"1.2\">";
}

std::string stroke_attrs(const Style& s) {
  std::string a = " fill=\"none\" stroke=\"" + escape(s.color) + "\" stroke-width=\"" + px(s.line_width) +
                  "\" stroke-linejoin=\"round\" stroke-linecap=\"round\"";
  if (!s.dash.empty()) a += " stroke-dasharray=\"" + escape(s.dash) + "\"";
  return a;
}

std::string text_el(double x, double y, const std::string& anchor, double font, const std::string& markup,
                    const std::string& extra = "") {
  return "<text x=\"" + px(x) + "\" y=\"" + px(y) + "\" text-anchor=\"" + anchor + "\" font-size=\"" + px(font) + "\"" +
         extra + ">" + markup + "</text>\n";
}

std::uint64_t fnv1a(const std::string& s) {
  std::uint64_t h = 14695981039346656037ull;
  for (unsigned char c : s) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

void replace_all(std::string& s, const std::string& from, const std::string& to) {
  for (std::size_t p = s.find(from); p != std::string::npos; p = s.find(from, p + to.size())) s.replace(p, from.size(), to);
}

/// Text for a '#' comment line: newlines become spaces.
std::string csv_comment(std::string text) {
  std::replace(text.begin(), text.end(), '\n', ' ');
  std::replace(text.begin(), text.end(), '\r', ' ');
  return text;
}

/// The axis range of data [lo, hi]: padded by kPad of the span (of the decades on a log axis) on
/// each side, but not across zero where the data stop at zero (bars, a pressure starting at rest).
std::pair<double, double> padded(double lo, double hi, bool log) {
  if (!std::isfinite(lo) || !std::isfinite(hi) || !(hi > lo)) return {lo, hi};
  if (log) {
    const double f = std::pow(hi / lo, kPad);
    return {lo / f, hi * f};
  }
  const double d = kPad * (hi - lo);
  return {lo >= 0.0 ? std::max(0.0, lo - d) : lo - d, hi <= 0.0 ? std::min(0.0, hi + d) : hi + d};
}

void check_sizes(std::size_t a, std::size_t b, const char* what) {
  if (a != b)
    throw std::invalid_argument(std::string("svg::Axes::") + what + ": the data vectors differ in length (" +
                                std::to_string(a) + " vs " + std::to_string(b) + ")");
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Ticks

Ticks linear_ticks(double lo, double hi, int target, bool widen, bool integer) {
  Ticks t;
  if (!std::isfinite(lo) || !std::isfinite(hi)) lo = 0.0, hi = 1.0;
  if (lo > hi) std::swap(lo, hi);
  if (hi - lo <= 1e-12 * std::max(1.0, std::abs(lo))) {
    const double d = lo == 0.0 ? 1.0 : 0.1 * std::abs(lo);
    lo -= d;
    hi += d;
  }
  target = std::max(1, target);
  // Heckbert's nice numbers, rounding the step up to 1, 2 or 5 times a power of ten.
  const double raw = (hi - lo) / target;
  int e = static_cast<int>(std::floor(std::log10(raw)));
  const double f = raw / pow10i(e);
  int nice = f <= 1.0 + 1e-9 ? 1 : f <= 2.0 + 1e-9 ? 2 : f <= 5.0 + 1e-9 ? 5 : 10;
  if (nice == 10) nice = 1, ++e;
  if (integer && e < 0) nice = 1, e = 0;  // whole numbers: a step of at least 1
  t.step = scaled(nice, e);
  if (widen) {
    lo = scaled(std::floor(lo / t.step + 1e-9) * nice, e);
    hi = scaled(std::ceil(hi / t.step - 1e-9) * nice, e);
  }
  t.lo = lo;
  t.hi = hi;
  const long long k0 = static_cast<long long>(std::ceil(lo / t.step - 1e-9));
  const long long k1 = static_cast<long long>(std::floor(hi / t.step + 1e-9));
  for (long long k = k0; k <= k1; ++k) t.major.push_back(scaled(static_cast<double>(k * nice), e));
  return t;
}

Ticks log_ticks(double lo, double hi, bool widen) {
  Ticks t;
  if (!(lo > 0.0) || !(hi > 0.0) || !std::isfinite(lo) || !std::isfinite(hi)) lo = 1.0, hi = 10.0;
  if (lo > hi) std::swap(lo, hi);
  if (hi / lo < 1.0 + 1e-9) lo /= 2.0, hi *= 2.0;
  const int e0 = static_cast<int>(std::floor(std::log10(lo) + 1e-9));
  const int e1 = static_cast<int>(std::ceil(std::log10(hi) - 1e-9));
  if (widen) lo = pow10i(e0), hi = pow10i(e1);
  t.lo = lo;
  t.hi = hi;
  const double span = std::log10(hi / lo);
  const bool mantissas = span <= 3.0 + 1e-9;
  const int every = span > 8.0 ? static_cast<int>(std::ceil(span / 8.0)) : 1;
  for (int e = e0; e <= e1; ++e)
    for (int m = 1; m <= 9; ++m) {
      const double v = scaled(m, e);
      if (!inside(v, lo, hi)) continue;
      const bool labelled = m == 1 ? (e % every == 0) : (mantissas && (m == 2 || m == 5));
      if (labelled)
        t.major.push_back(v);
      else if (span <= 8.0 + 1e-9)
        t.minor.push_back(v);
    }
  if (t.major.size() < 2) {  // a narrow range inside one decade: linear positions read better
    t.major.clear();
    t.minor.clear();
    for (double v : linear_ticks(lo, hi, 4, false).major)
      if (v > 0.0) t.major.push_back(v);
  }
  return t;
}

std::string tick_label(double v, double step) {
  char buf[48];
  if (step > 0.0 && (step < 1e-4 || std::abs(v) >= 1e6)) {
    std::snprintf(buf, sizeof buf, "%g", v);
  } else {
    const int decimals = step > 0.0 ? std::max(0, -static_cast<int>(std::floor(std::log10(step) + 1e-9))) : 6;
    std::snprintf(buf, sizeof buf, "%.*f", decimals, v);
  }
  std::string s = buf;
  if (s[0] == '-' && std::strtod(s.c_str(), nullptr) == 0.0) s.erase(0, 1);
  return s;
}

std::string escape(const std::string& text) { return xml_escape(text); }

std::string csv_field(const std::string& text) {
  if (text.find_first_of(",\"\n\r") == std::string::npos && (text.empty() || text[0] != '#')) return text;
  std::string q = "\"";
  for (char c : text) q += c == '"' ? std::string("\"\"") : std::string(1, c);
  return q + "\"";
}

std::string csv_number(double v) { return std::isfinite(v) ? json::num(v) : ""; }

std::string palette_color(std::size_t i) { return kPalette[i % kPaletteSize]; }

std::string diverging_color(double v) {
  // ColorBrewer RdBu (Brewer & Harrower), 9 classes from blue to red, interpolated linearly.
  static constexpr unsigned kStops[] = {0x2166AC, 0x4393C3, 0x92C5DE, 0xD1E5F0, 0xF7F7F7,
                                        0xFDDBC7, 0xF4A582, 0xD6604D, 0xB2182B};
  constexpr int n = 9;
  const double x = (std::clamp(std::isfinite(v) ? v : 0.0, -1.0, 1.0) + 1.0) * 0.5 * (n - 1);
  const int i = std::min(static_cast<int>(x), n - 2);
  const double w = x - i;
  char buf[8];
  unsigned rgb[3];
  for (int c = 0; c < 3; ++c) {
    const int sh = 16 - 8 * c;
    const double a = (kStops[i] >> sh) & 0xFF, b = (kStops[i + 1] >> sh) & 0xFF;
    rgb[c] = static_cast<unsigned>(std::lround((1.0 - w) * a + w * b));
  }
  std::snprintf(buf, sizeof buf, "#%02X%02X%02X", rgb[0], rgb[1], rgb[2]);
  return buf;
}

// ---------------------------------------------------------------------------------------------
// Scale

Scale::Scale(double lo, double hi, double px_lo, double px_hi, bool log)
    : lo_(log ? std::log10(lo) : lo), hi_(log ? std::log10(hi) : hi), px_lo_(px_lo), px_hi_(px_hi), log_(log) {}

double Scale::operator()(double v) const {
  if (log_) {
    if (!(v > 0.0)) return kNaN;
    v = std::log10(v);
  }
  return px_lo_ + (v - lo_) / (hi_ - lo_) * (px_hi_ - px_lo_);
}

// ---------------------------------------------------------------------------------------------
// Axes

Axes& Axes::title(const std::string& text) { return title_ = text, *this; }
Axes& Axes::xlabel(const std::string& text) { return xlabel_ = text, *this; }
Axes& Axes::ylabel(const std::string& text) { return ylabel_ = text, *this; }
Axes& Axes::y2label(const std::string& text) { return y2label_ = text, *this; }
Axes& Axes::xlog(bool on) { return xlog_ = on, *this; }
Axes& Axes::xinteger(bool on) { return xinteger_ = on, *this; }
Axes& Axes::legend(Legend where) { return legend_ = where, *this; }
Axes& Axes::note(const std::string& text) { return note_ = text, *this; }

Axes& Axes::xlim(double lo, double hi) {
  has_xlim_ = true;
  xlim_[0] = lo, xlim_[1] = hi;
  return *this;
}
Axes& Axes::ylim(double lo, double hi) {
  has_ylim_ = true;
  ylim_[0] = lo, ylim_[1] = hi;
  return *this;
}
Axes& Axes::y2lim(double lo, double hi) {
  has_y2lim_ = true;
  y2lim_[0] = lo, y2lim_[1] = hi;
  return *this;
}

Axes& Axes::add(Series s) {
  if (s.style.color.empty()) s.style.color = kPalette[colors_used_++ % kPaletteSize];
  series_.push_back(std::move(s));
  return *this;
}

Axes& Axes::line(const std::vector<double>& x, const std::vector<double>& y, const std::string& label, Style style) {
  check_sizes(x.size(), y.size(), "line");
  return add({Kind::Line, x, y, {}, label, std::move(style)});
}

Axes& Axes::scatter(const std::vector<double>& x, const std::vector<double>& y, const std::string& label, Style style) {
  check_sizes(x.size(), y.size(), "scatter");
  if (style.marker == Marker::None) style.marker = Marker::Circle;
  return add({Kind::Scatter, x, y, {}, label, std::move(style)});
}

Axes& Axes::range_bars(const std::vector<double>& x, const std::vector<double>& lo, const std::vector<double>& hi,
                       const std::string& label, Style style) {
  check_sizes(x.size(), lo.size(), "range_bars");
  check_sizes(x.size(), hi.size(), "range_bars");
  return add({Kind::Range, x, lo, hi, label, std::move(style)});
}

Axes& Axes::error_bars(const std::vector<double>& x, const std::vector<double>& y, const std::vector<double>& err,
                       const std::string& label, Style style) {
  check_sizes(x.size(), y.size(), "error_bars");
  check_sizes(x.size(), err.size(), "error_bars");
  std::vector<double> lo(y.size()), hi(y.size());
  for (std::size_t i = 0; i < y.size(); ++i) lo[i] = y[i] - std::abs(err[i]), hi[i] = y[i] + std::abs(err[i]);
  return range_bars(x, lo, hi, label, std::move(style));
}

Axes& Axes::grouped_bars(const std::vector<std::string>& categories, const std::vector<BarGroup>& groups) {
  for (const BarGroup& g : groups) {
    check_sizes(categories.size(), g.values.size(), "grouped_bars");
    if (!g.errors.empty()) check_sizes(categories.size(), g.errors.size(), "grouped_bars");
  }
  categories_ = categories;
  bars_ = groups;
  for (BarGroup& g : bars_)
    if (g.color.empty()) g.color = kPalette[colors_used_++ % kPaletteSize];
  return *this;
}

// ---------------------------------------------------------------------------------------------
// Figure

struct Figure::Layout {
  Rect area;
  Ticks x, y, y2;
  bool y2_on = false;
  bool categorical = false;
};

Figure::Figure(double width_px, double height_px, int rows, int cols)
    : width_(width_px), height_(height_px), rows_(std::max(1, rows)), cols_(std::max(1, cols)),
      axes_(static_cast<std::size_t>(rows_ * cols_)) {}

Figure& Figure::title(const std::string& text) { return title_ = text, *this; }
Figure& Figure::id(const std::string& prefix) { return id_ = prefix, *this; }

const Axes& Figure::at(int row, int col) const {
  if (row < 0 || row >= rows_ || col < 0 || col >= cols_)
    throw std::out_of_range("svg::Figure::axes(" + std::to_string(row) + ", " + std::to_string(col) + "): the figure has " +
                            std::to_string(rows_) + " x " + std::to_string(cols_) + " axes");
  return axes_[static_cast<std::size_t>(row * cols_ + col)];
}
Axes& Figure::axes(int row, int col) { return const_cast<Axes&>(at(row, col)); }
const Axes& Figure::axes(int row, int col) const { return at(row, col); }

Figure::Layout Figure::layout(int row, int col) const {
  const Axes& a = at(row, col);
  Layout L;
  L.categorical = !a.categories_.empty();
  L.y2_on = !a.y2label_.empty() || a.has_y2lim_ ||
            std::any_of(a.series_.begin(), a.series_.end(), [](const Axes::Series& s) { return s.style.axis == YAxis::Right; });

  const double k = text_scale();
  const double top0 = title_.empty() ? 0.0 : k * margins.figure_title;
  const double cw = width_ / cols_, ch = (height_ - top0) / rows_;
  L.area.x = col * cw + k * margins.left;
  L.area.y = top0 + row * ch + k * (margins.top + (a.title_.empty() ? 0.0 : margins.axes_title));
  L.area.width = std::max(1.0, cw - k * (margins.left + (L.y2_on ? margins.right_y2 : margins.right)));
  L.area.height = std::max(1.0, top0 + (row + 1) * ch - k * margins.bottom - L.area.y);

  // Data ranges.
  const bool xlog = a.xlog_ && !L.categorical;
  double x0 = INFINITY, x1 = -INFINITY, y0[2] = {INFINITY, INFINITY}, y1[2] = {-INFINITY, -INFINITY};
  auto grow_y = [&](int ax, double v) {
    if (std::isfinite(v)) y0[ax] = std::min(y0[ax], v), y1[ax] = std::max(y1[ax], v);
  };
  for (const Axes::Series& s : a.series_) {
    const int ax = s.style.axis == YAxis::Right ? 1 : 0;
    for (std::size_t i = 0; i < s.x.size(); ++i) {
      if (!std::isfinite(s.x[i]) || (xlog && !(s.x[i] > 0.0))) continue;
      x0 = std::min(x0, s.x[i]), x1 = std::max(x1, s.x[i]);
      grow_y(ax, s.y[i]);
      if (s.kind == Axes::Kind::Range) grow_y(ax, s.y_hi[i]);
    }
  }
  if (!a.bars_.empty()) {
    grow_y(0, 0.0);
    for (const BarGroup& g : a.bars_)
      for (std::size_t i = 0; i < g.values.size(); ++i) {
        const double e = g.errors.empty() ? 0.0 : std::abs(g.errors[i]);
        grow_y(0, g.values[i] + e);
        grow_y(0, g.values[i] - e);
      }
  }

  const int xt = std::clamp(static_cast<int>(std::lround(L.area.width / (80.0 * k))), 3, 8);
  const int yt = std::clamp(static_cast<int>(std::lround(L.area.height / (60.0 * k))), 3, 8);
  if (L.categorical) {
    const int n = static_cast<int>(a.categories_.size());
    L.x.lo = -0.5, L.x.hi = n - 0.5, L.x.step = 1.0;
    for (int i = 0; i < n; ++i) L.x.major.push_back(i);
  } else {
    const auto [lo, hi] = a.has_xlim_ ? std::pair(a.xlim_[0], a.xlim_[1]) : padded(x0, x1, xlog);
    L.x = xlog ? log_ticks(lo, hi, false) : linear_ticks(lo, hi, xt, false, a.xinteger_);
  }
  const auto [ylo, yhi] = a.has_ylim_ ? std::pair(a.ylim_[0], a.ylim_[1]) : padded(y0[0], y1[0], false);
  L.y = linear_ticks(ylo, yhi, yt, false);
  if (L.y2_on) {
    const auto [lo, hi] = a.has_y2lim_ ? std::pair(a.y2lim_[0], a.y2lim_[1]) : padded(y0[1], y1[1], false);
    L.y2 = linear_ticks(lo, hi, yt, false);
  }
  return L;
}

Rect Figure::plot_area(int row, int col) const { return layout(row, col).area; }

Scale Figure::x_scale(int row, int col) const {
  const Layout L = layout(row, col);
  return Scale(L.x.lo, L.x.hi, L.area.x, L.area.x + L.area.width, at(row, col).xlog_ && !L.categorical);
}

Scale Figure::y_scale(int row, int col, YAxis which) const {
  const Layout L = layout(row, col);
  const Ticks& t = which == YAxis::Right ? L.y2 : L.y;
  return Scale(t.lo, t.hi, L.area.y + L.area.height, L.area.y, false);
}

Ticks Figure::x_ticks(int row, int col) const { return layout(row, col).x; }
Ticks Figure::y_ticks(int row, int col, YAxis which) const {
  const Layout L = layout(row, col);
  return which == YAxis::Right ? L.y2 : L.y;
}

std::vector<std::array<double, 2>> Figure::ink_samples(const Axes& a, const Scale& X, const Scale& Y, const Scale& Y2) {
  // Pixel positions where the data put ink: every point, 8 points along every line segment and
  // range bar, a 5 x 5 grid over every bar. Enough to tell a crowded corner from an empty one.
  std::vector<std::array<double, 2>> ink;
  auto add = [&](double x, double y) {
    if (std::isfinite(x) && std::isfinite(y)) ink.push_back({x, y});
  };
  for (const Axes::Series& ser : a.series_) {
    const Scale& SY = ser.style.axis == YAxis::Right ? Y2 : Y;
    for (std::size_t i = 0; i < ser.x.size(); ++i) {
      const double x = X(ser.x[i]), y = SY(ser.y[i]);
      add(x, y);
      double x1 = x, y1 = y;  // the other end of what is drawn from this point: a bar's top, a segment's end
      if (ser.kind == Axes::Kind::Range)
        y1 = SY(ser.y_hi[i]);
      else if (ser.kind == Axes::Kind::Line && ser.style.line_width > 0.0 && i + 1 < ser.x.size())
        x1 = X(ser.x[i + 1]), y1 = SY(ser.y[i + 1]);
      else
        continue;
      for (int j = 1; j < 8; ++j) add(x + (x1 - x) * j / 8.0, y + (y1 - y) * j / 8.0);
    }
  }
  const int G = static_cast<int>(a.bars_.size());
  for (int g = 0; g < G; ++g)
    for (std::size_t i = 0; i < a.bars_[g].values.size(); ++i) {
      const double v = a.bars_[g].values[i], w = 0.8 / G;
      if (!std::isfinite(v)) continue;
      for (int u = 0; u < 5; ++u)
        for (int t = 0; t < 5; ++t)
          add(X(static_cast<double>(i) - 0.4 + (g + (u + 0.5) / 5.0) * w), Y(v * (t + 0.5) / 5.0));
    }
  return ink;
}

/// One axes being drawn: its data, layout, scales and text sizes.
struct Figure::Panel {
  const Axes& a;
  Layout L;
  double k, tick_font, label_font;
  double left, right, top, bottom;  ///< the plot area's edges (px)
  bool xlog;
  Scale X, Y, Y2;
  std::string clip;  ///< the id of the plot area's clip path
};

std::string Figure::render_axes(int row, int col) const {
  const Axes& a = at(row, col);
  const Layout L = layout(row, col);
  const Rect& R = L.area;
  const double k = text_scale();
  const double left = R.x, right = R.x + R.width, top = R.y, bottom = R.y + R.height;
  const bool xlog = a.xlog_ && !L.categorical;
  const Panel p{a,
                L,
                k,
                k * kTickFont,
                k * kLabelFont,
                left,
                right,
                top,
                bottom,
                xlog,
                Scale(L.x.lo, L.x.hi, left, right, xlog),
                Scale(L.y.lo, L.y.hi, bottom, top, false),
                Scale(L.y2_on ? L.y2.lo : 0.0, L.y2_on ? L.y2.hi : 1.0, bottom, top, false),
                std::string(kIdToken) + "-clip-" + std::to_string(row * cols_ + col)};
  std::string s = "<g>\n<defs><clipPath id=\"" + p.clip + "\"><rect x=\"" + px(left) + "\" y=\"" + px(top) + "\" width=\"" +
                  px(R.width) + "\" height=\"" + px(R.height) + "\"/></clipPath></defs>\n";
  s += draw_grid(p);
  s += draw_data(p);
  s += draw_markers(p);
  s += draw_frame_and_text(p);
  s += draw_legend(p);
  return s + "</g>\n";
}

std::string Figure::draw_grid(const Panel& p) {
  const Layout& L = p.L;
  const double left = p.left, right = p.right, top = p.top, bottom = p.bottom;
  const Scale &X = p.X, &Y = p.Y;
  std::string grid;  // std::string("M"): "M" + px(...) here draws GCC 12's false -Wrestrict (GCC bug 105329)
  if (!L.categorical)
    for (double v : L.x.major) grid += std::string("M") + px(X(v)) + " " + px(top) + "V" + px(bottom);
  for (double v : L.y.major) grid += std::string("M") + px(left) + " " + px(Y(v)) + "H" + px(right);
  if (grid.empty()) return "";
  return "<path d=\"" + grid + "\" fill=\"none\" stroke=\"#e6e6e6\" stroke-width=\"1\"/>\n";
}

std::string Figure::draw_data(const Panel& p) {
  const Axes& a = p.a;
  const Scale &X = p.X, &Y = p.Y, &Y2 = p.Y2;
  std::string s;
  // Data, clipped to the plot area: bars, range bars, lines.
  s += "<g clip-path=\"url(#" + p.clip + ")\">\n";
  const int G = static_cast<int>(a.bars_.size());
  for (int g = 0; g < G; ++g) {
    const BarGroup& b = a.bars_[g];
    const double w = 0.8 / G;
    std::string rects, whiskers;
    for (std::size_t i = 0; i < b.values.size(); ++i) {
      const double v = b.values[i];
      if (!std::isfinite(v)) continue;
      const double xl = X(static_cast<double>(i) - 0.4 + g * w), xr = X(static_cast<double>(i) - 0.4 + (g + 1) * w);
      const double yt = Y(std::max(v, 0.0)), yb = Y(std::min(v, 0.0));
      rects += "<rect x=\"" + px(xl) + "\" y=\"" + px(yt) + "\" width=\"" + px(xr - xl) + "\" height=\"" + px(yb - yt) + "\"/>";
      if (!b.errors.empty() && std::isfinite(b.errors[i])) {
        const double xc = 0.5 * (xl + xr), cap = std::min(4.0, 0.3 * (xr - xl));
        const double e = std::abs(b.errors[i]);
        whiskers += "M" + px(xc) + " " + px(Y(v - e)) + "V" + px(Y(v + e)) + "M" + px(xc - cap) + " " + px(Y(v - e)) + "H" +
                    px(xc + cap) + "M" + px(xc - cap) + " " + px(Y(v + e)) + "H" + px(xc + cap);
      }
    }
    s += "<g fill=\"" + escape(b.color) + "\">" + rects + "</g>\n";
    if (!whiskers.empty()) s += "<path d=\"" + whiskers + "\" fill=\"none\" stroke=\"" + kInk + "\" stroke-width=\"1\"/>\n";
  }
  for (const Axes::Series& ser : a.series_) {
    const Scale& SY = ser.style.axis == YAxis::Right ? Y2 : Y;
    if (ser.kind == Axes::Kind::Range) {
      std::string d;
      for (std::size_t i = 0; i < ser.x.size(); ++i) {
        const double xp = X(ser.x[i]), lo = SY(ser.y[i]), hi = SY(ser.y_hi[i]);
        if (!std::isfinite(xp) || !std::isfinite(lo) || !std::isfinite(hi)) continue;
        d += "M" + px(xp) + " " + px(lo) + "V" + px(hi) + "M" + px(xp - 4) + " " + px(lo) + "H" + px(xp + 4) + "M" +
             px(xp - 4) + " " + px(hi) + "H" + px(xp + 4);
      }
      Style st = ser.style;
      st.dash.clear();
      st.line_width = std::max(1.0, std::min(st.line_width, 1.5));
      if (!d.empty()) s += "<path d=\"" + d + "\"" + stroke_attrs(st) + "/>\n";
    } else if (ser.kind == Axes::Kind::Line && ser.style.line_width > 0.0) {
      std::string d;
      bool pen = false;
      for (std::size_t i = 0; i < ser.x.size(); ++i) {
        const double xp = X(ser.x[i]), yp = SY(ser.y[i]);
        if (!std::isfinite(xp) || !std::isfinite(yp)) {
          pen = false;
          continue;
        }
        d += (pen ? "L" : "M") + px(xp) + " " + px(yp);
        pen = true;
      }
      if (!d.empty()) s += "<path d=\"" + d + "\"" + stroke_attrs(ser.style) + "/>\n";
    }
  }
  s += "</g>\n";
  return s;
}

std::string Figure::draw_markers(const Panel& p) {
  const Axes& a = p.a;
  const Layout& L = p.L;
  const bool xlog = p.xlog;
  const Scale &X = p.X, &Y = p.Y, &Y2 = p.Y2;
  std::string s;
  // Markers are not clipped (a point on the frame stays whole) but points outside are left out.
  for (const Axes::Series& ser : a.series_) {
    if (ser.kind == Axes::Kind::Range || ser.style.marker == Marker::None) continue;
    const Scale& SY = ser.style.axis == YAxis::Right ? Y2 : Y;
    const Ticks& ty = ser.style.axis == YAxis::Right ? L.y2 : L.y;
    std::string m;
    for (std::size_t i = 0; i < ser.x.size(); ++i) {
      if (!std::isfinite(ser.x[i]) || !std::isfinite(ser.y[i]) || (xlog && !(ser.x[i] > 0.0))) continue;
      if (!inside(ser.x[i], L.x.lo, L.x.hi) || !inside(ser.y[i], ty.lo, ty.hi)) continue;
      m += marker_svg(ser.style.marker, X(ser.x[i]), SY(ser.y[i]), ser.style.marker_size);
    }
    if (!m.empty()) s += marker_group(ser.style) + m + "</g>\n";
  }
  return s;
}

std::string Figure::draw_frame_and_text(const Panel& p) const {
  const Axes& a = p.a;
  const Layout& L = p.L;
  const Rect& R = L.area;
  const double k = p.k, tick_font = p.tick_font, label_font = p.label_font;
  const double left = p.left, right = p.right, top = p.top, bottom = p.bottom;
  const bool xlog = p.xlog;
  const Scale &X = p.X, &Y = p.Y, &Y2 = p.Y2;
  std::string s;
  // Frame, ticks and tick labels.
  s += "<rect x=\"" + px(left) + "\" y=\"" + px(top) + "\" width=\"" + px(R.width) + "\" height=\"" + px(R.height) +
       "\" fill=\"none\" stroke=\"#333333\" stroke-width=\"1\"/>\n";
  std::string ticks, labels;
  std::size_t every = 1;  // categorical axis: label every k-th category when they would overlap
  if (L.categorical) {
    double widest = 0;
    for (const std::string& c : a.categories_) widest = std::max(widest, text_width(c, tick_font));
    every = static_cast<std::size_t>(std::max(1.0, std::ceil((widest + 6 * k) * a.categories_.size() / R.width)));
  }
  const std::string major = px(5 * k), minor = px(3 * k);
  for (double v : L.x.major) {
    ticks += "M" + px(X(v)) + " " + px(bottom) + "v" + major;
    std::string label;
    if (L.categorical) {
      const auto i = static_cast<std::size_t>(std::lround(v));
      if (i % every == 0) label = escape(a.categories_[i]);
    } else {
      label = xlog ? log_label(v, k * kExponentFont) : escape(tick_label(v, L.x.step));
    }
    if (!label.empty()) labels += text_el(X(v), bottom + 20 * k, "middle", tick_font, label);
  }
  for (double v : L.x.minor) ticks += "M" + px(X(v)) + " " + px(bottom) + "v" + minor;
  for (double v : L.y.major) {
    ticks += "M" + px(left) + " " + px(Y(v)) + "h-" + major;
    labels += text_el(left - 8 * k, Y(v) + 5 * k, "end", tick_font, escape(tick_label(v, L.y.step)));
  }
  if (L.y2_on)
    for (double v : L.y2.major) {
      ticks += "M" + px(right) + " " + px(Y2(v)) + "h" + major;
      labels += text_el(right + 8 * k, Y2(v) + 5 * k, "start", tick_font, escape(tick_label(v, L.y2.step)));
    }
  s += "<path d=\"" + ticks + "\" fill=\"none\" stroke=\"#333333\" stroke-width=\"1\"/>\n";
  s += "<g fill=\"" + std::string(kInk) + "\">\n" + labels;

  // Axis labels and title.
  if (!a.xlabel_.empty()) s += text_el(0.5 * (left + right), bottom + 46 * k, "middle", label_font, escape(a.xlabel_));
  if (!a.ylabel_.empty()) {
    const double x = left - k * (margins.left - 18), y = 0.5 * (top + bottom);
    s += "<text transform=\"translate(" + px(x) + "," + px(y) + ") rotate(-90)\" text-anchor=\"middle\" font-size=\"" +
         px(label_font) + "\">" + escape(a.ylabel_) + "</text>\n";
  }
  if (L.y2_on && !a.y2label_.empty()) {
    const double x = right + k * (margins.right_y2 - 18), y = 0.5 * (top + bottom);
    s += "<text transform=\"translate(" + px(x) + "," + px(y) + ") rotate(90)\" text-anchor=\"middle\" font-size=\"" +
         px(label_font) + "\">" + escape(a.y2label_) + "</text>\n";
  }
  if (!a.title_.empty()) s += text_el(0.5 * (left + right), top - 9 * k, "middle", k * kTitleFont, escape(a.title_));
  if (!a.note_.empty()) s += text_el(0.5 * (left + right), 0.5 * (top + bottom), "middle", label_font, escape(a.note_), " fill=\"#777777\"");
  s += "</g>\n";
  return s;
}

std::string Figure::draw_legend(const Panel& p) {
  const Axes& a = p.a;
  const double k = p.k, tick_font = p.tick_font;
  const double left = p.left, right = p.right, top = p.top, bottom = p.bottom;
  const Scale &X = p.X, &Y = p.Y, &Y2 = p.Y2;
  std::string s;
  // Legend: series, then bar groups, in the order they were added.
  struct Entry {
    std::string label;
    Style style;
    int kind;  // 0 line, 1 scatter, 2 range, 3 bar
  };
  std::vector<Entry> entries;
  for (const Axes::Series& ser : a.series_)
    if (!ser.label.empty() && ser.style.in_legend) entries.push_back({ser.label, ser.style, static_cast<int>(ser.kind)});
  for (const BarGroup& b : a.bars_)
    if (!b.label.empty()) {
      Style st;
      st.color = b.color;
      entries.push_back({b.label, st, 3});
    }
  if (a.legend_ != Legend::None && !entries.empty()) {
    const double row_h = 19 * k, pad = 7 * k, sample = 24 * k, gap = 6 * k, edge = 8 * k;
    double tw = 0;
    for (const Entry& e : entries) tw = std::max(tw, text_width(e.label, tick_font));
    const double bw = pad + sample + gap + tw + pad, bh = 2 * pad + row_h * entries.size() - 4 * k;
    auto corner = [&](Legend where) {
      const bool at_right = where == Legend::UpperRight || where == Legend::LowerRight;
      const bool at_top = where == Legend::UpperRight || where == Legend::UpperLeft;
      return Rect{at_right ? right - edge - bw : left + edge, at_top ? top + edge : bottom - edge - bh, bw, bh};
    };
    Legend where = a.legend_;
    if (where == Legend::Best) {
      const std::vector<std::array<double, 2>> ink = ink_samples(a, X, Y, Y2);
      std::size_t fewest = std::numeric_limits<std::size_t>::max();
      for (Legend c : {Legend::UpperRight, Legend::UpperLeft, Legend::LowerRight, Legend::LowerLeft}) {
        const Rect r = corner(c);
        const auto n = static_cast<std::size_t>(std::count_if(ink.begin(), ink.end(), [&](const std::array<double, 2>& pt) {
          return pt[0] >= r.x && pt[0] <= r.x + r.width && pt[1] >= r.y && pt[1] <= r.y + r.height;
        }));
        if (n < fewest) fewest = n, where = c;
      }
    }
    const Rect box = corner(where);
    const double bx = box.x, by = box.y;
    s += "<g>\n<rect x=\"" + px(bx) + "\" y=\"" + px(by) + "\" width=\"" + px(bw) + "\" height=\"" + px(bh) +
         "\" fill=\"#ffffff\" fill-opacity=\"0.85\" stroke=\"#bbbbbb\" stroke-width=\"0.8\"/>\n";
    for (std::size_t i = 0; i < entries.size(); ++i) {
      const Entry& e = entries[i];
      const double cy = by + pad + row_h * i + 7.5 * k, x0 = bx + pad, xm = x0 + 0.5 * sample;
      if (e.kind == 0 && e.style.line_width > 0)
        s += "<path d=\"M" + px(x0) + " " + px(cy) + "H" + px(x0 + sample) + "\"" + stroke_attrs(e.style) + "/>\n";
      if ((e.kind == 0 || e.kind == 1) && e.style.marker != Marker::None)
        s += marker_group(e.style) + marker_svg(e.style.marker, xm, cy, e.style.marker_size) + "</g>\n";
      if (e.kind == 2) {
        Style st = e.style;
        st.dash.clear();
        st.line_width = std::max(1.0, std::min(st.line_width, 1.5));
        const double h = 6 * k, w = 4 * k;
        s += "<path d=\"M" + px(xm) + " " + px(cy - h) + "V" + px(cy + h) + "M" + px(xm - w) + " " + px(cy - h) + "H" +
             px(xm + w) + "M" + px(xm - w) + " " + px(cy + h) + "H" + px(xm + w) + "\"" + stroke_attrs(st) + "/>\n";
      }
      if (e.kind == 3)
        s += "<rect x=\"" + px(xm - 5 * k) + "\" y=\"" + px(cy - 5 * k) + "\" width=\"" + px(10 * k) + "\" height=\"" +
             px(10 * k) + "\" fill=\"" + escape(e.style.color) + "\"/>\n";
      s += text_el(x0 + sample + gap, cy + 5 * k, "start", tick_font, escape(e.label), " fill=\"" + std::string(kInk) + "\"");
    }
    s += "</g>\n";
  }
  return s;
}

std::string Figure::svg_element() const {
  std::string body;
  if (!title_.empty())
    body += text_el(0.5 * width_, 22 * text_scale(), "middle", text_scale() * kFigureTitleFont, escape(title_),
                    " fill=\"" + std::string(kInk) + "\"");
  for (int r = 0; r < rows_; ++r)
    for (int c = 0; c < cols_; ++c) body += render_axes(r, c);
  std::string prefix = id_;
  if (prefix.empty()) {
    char buf[24];
    std::snprintf(buf, sizeof buf, "pf%016llx", static_cast<unsigned long long>(fnv1a(body)));
    prefix = buf;
  }
  replace_all(body, kIdToken, escape(prefix));
  return "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + px(width_) + "\" height=\"" + px(height_) +
         "\" viewBox=\"0 0 " + px(width_) + " " + px(height_) +
         "\" font-family=\"Helvetica, Arial, sans-serif\">\n<rect width=\"" + px(width_) + "\" height=\"" + px(height_) +
         "\" fill=\"#ffffff\"/>\n" + body + "</svg>\n";
}

std::string Figure::svg() const { return "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n" + svg_element(); }

std::string Figure::csv() const {
  std::string out = "# " + csv_comment(title_.empty() ? "figure" : title_) +
                    ": every plotted series, one row per point (pandas.read_csv(path, comment=\"#\"))\n";
  auto panel_name = [&](int i) {
    const Axes& a = axes_[static_cast<std::size_t>(i)];
    return a.title_.empty() ? std::to_string(i + 1) : a.title_;
  };
  for (int i = 0; i < rows_ * cols_; ++i) {
    const Axes& a = axes_[static_cast<std::size_t>(i)];
    out += "# panel " + csv_comment(panel_name(i)) + ": x = " + csv_comment(a.xlabel_) + "; y = " + csv_comment(a.ylabel_);
    if (!a.y2label_.empty()) out += "; right y = " + csv_comment(a.y2label_);
    out += "\n";
  }
  out += "panel,series,axis,x,y,y_low,y_high\n";
  for (int i = 0; i < rows_ * cols_; ++i) {
    const Axes& a = axes_[static_cast<std::size_t>(i)];
    const std::string panel = csv_field(panel_name(i));
    int unnamed = 0;
    for (const Axes::Series& ser : a.series_) {
      const std::string head = panel + "," + csv_field(ser.label.empty() ? "series " + std::to_string(++unnamed) : ser.label) +
                               (ser.style.axis == YAxis::Right ? ",right," : ",left,");
      for (std::size_t j = 0; j < ser.x.size(); ++j)
        out += head + csv_number(ser.x[j]) +
               (ser.kind == Axes::Kind::Range ? ",," + csv_number(ser.y[j]) + "," + csv_number(ser.y_hi[j])
                                              : "," + csv_number(ser.y[j]) + ",,") +
               "\n";
    }
    for (const BarGroup& b : a.bars_) {
      const std::string head = panel + "," + csv_field(b.label.empty() ? "series " + std::to_string(++unnamed) : b.label) + ",left,";
      for (std::size_t j = 0; j < b.values.size(); ++j) {
        const double e = b.errors.empty() ? kNaN : std::abs(b.errors[j]);
        out += head + csv_field(a.categories_[j]) + "," + csv_number(b.values[j]) + "," + csv_number(b.values[j] - e) + "," +
               csv_number(b.values[j] + e) + "\n";
      }
    }
  }
  return out;
}

void Figure::save(const std::string& path) const {
  write_file_atomic(path, svg());
  write_file_atomic(std::filesystem::path(path).replace_extension(".csv").string(), csv());
}

}  // namespace pneufem::svg
