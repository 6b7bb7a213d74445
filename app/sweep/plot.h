#pragma once
// The plot of a sweep (`pneufem sweep` writes one per parameter: sweep_<key>.svg and its .csv):
// the final trial's NRMSE (or, without a recording, the final angle) against one parameter.
// Sized for a journal's single column (svg::kColumnWidthPx); the x axis spans the swept range,
// padded as the data are (so the end points are not on the frame) and not widened to whole
// ticks; the y axis spans the points' values (not from 0).
#include <cstddef>
#include <vector>

#include "app/sweep/point.h"
#include "viz/svg_plot.h"

namespace pneufem {

/// The final-trial NRMSE of a point (NaN without metrics).
double final_nrmse(const SweepPoint& p);

/// The figure of parameter `j`: finished points ("ok") as dots (joined when there is one parameter),
/// failed points as crosses at the bottom of the points' range; a note when no point finished.
svg::Figure sweep_figure(const std::vector<ParamSpec>& params, std::size_t j, const std::vector<SweepPoint>& points);

}  // namespace pneufem
