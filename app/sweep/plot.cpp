#include "app/sweep/plot.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

namespace pneufem {

double final_nrmse(const SweepPoint& p) {
  return p.nrmse.empty() ? std::numeric_limits<double>::quiet_NaN() : p.nrmse.back();
}

namespace {

/// The swept range [lo, hi] padded by 4 % of its span (of its decades when log), as svg::Axes pads data.
std::pair<double, double> padded_range(const ParamSpec& p) {
  constexpr double kPad = 0.04;
  if (!(p.hi > p.lo)) return {p.lo, p.hi};
  if (p.log) {
    const double f = std::pow(p.hi / p.lo, kPad);
    return {p.lo / f, p.hi * f};
  }
  const double d = kPad * (p.hi - p.lo);
  return {p.lo - d, p.hi + d};
}

}  // namespace

svg::Figure sweep_figure(const std::vector<ParamSpec>& params, std::size_t j, const std::vector<SweepPoint>& points) {
  const ParamSpec& p = params.at(j);
  const bool have_nrmse = std::any_of(points.begin(), points.end(), [](const SweepPoint& q) { return !q.nrmse.empty(); });
  auto metric = [&](const SweepPoint& q) { return have_nrmse ? final_nrmse(q) : q.final_angle_deg; };
  std::vector<std::pair<double, double>> ok;
  std::vector<double> failed_x;
  for (const SweepPoint& q : points) {
    if (q.status == "ok" && std::isfinite(metric(q))) ok.emplace_back(q.values[j], metric(q));
    if (q.status == "failed") failed_x.push_back(q.values[j]);
  }
  std::sort(ok.begin(), ok.end());
  std::vector<double> x, y;
  for (const auto& [a, b] : ok) x.push_back(a), y.push_back(b);

  svg::Figure fig(svg::kColumnWidthPx, 320);
  svg::Axes& ax = fig.axes();
  ax.title((have_nrmse ? "final-trial NRMSE vs " : "final angle vs ") + p.key)
      .xlabel(p.key)
      .ylabel(have_nrmse ? "final-trial NRMSE" : "final bending angle (deg)")
      .xlog(p.log)
      .xinteger(p.integer);
  // The x range is the swept range, whatever the outcome of its points.
  const auto [xlo, xhi] = padded_range(p);
  ax.xlim(xlo, xhi);
  svg::Style ok_style;
  ok_style.color = svg::palette_color(0);
  ok_style.marker = svg::Marker::Circle;
  if (params.size() == 1)
    ax.line(x, y, "ok", ok_style);
  else
    ax.scatter(x, y, "ok (all other parameters)", ok_style);
  if (!failed_x.empty()) {
    svg::Style failed_style;
    failed_style.color = svg::palette_color(1);
    failed_style.marker = svg::Marker::Cross;
    failed_style.marker_size = 5.0;
    const double bottom = y.empty() ? 0.0 : *std::min_element(y.begin(), y.end());
    ax.scatter(failed_x, std::vector<double>(failed_x.size(), bottom), "failed", failed_style);
  }
  if (x.empty()) ax.note(failed_x.empty() ? "no finished points yet" : "no point succeeded");
  return fig;
}

}  // namespace pneufem
