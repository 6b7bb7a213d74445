#pragma once
// Figures and the offline HTML report of `pneufem compare` (app/compare/command.h). Figures follow the
// seed paper's Results: pressure and angle against time per trial (model overlaid), angle vs
// pressure with the 2.5 s -> end-of-hold spread as bars, NRMSE per trial, absolute error per
// step grouped by trial, error and spread per step; plus the diagnostics the paper lacks: the
// step x trial residual map (heat map), the residual against time since the step start, the
// region sensitivities and the study history (the error of each model variant, in order).
// All SVG is deterministic (viz/svg_plot.h; the heat map is drawn here as coloured rects), sized
// for print at a journal's column width, with each trial in one colour (measured and model alike);
// every figure's series are also written as CSV next to it, and the per-frame model-vs-measured
// series as model_vs_measured.csv, to redraw them elsewhere (matplotlib, a spreadsheet).
#include <string>
#include <vector>

#include "app/compare/history.h"
#include "app/compare/result.h"

namespace pneufem {

struct ReportFigure {
  std::string name;     ///< file stem, e.g. "fig_trial_1"
  std::string title;
  std::string caption;  ///< what to read from it
  std::string section;  ///< "figures", "fails", "regions" or "history"
  std::string svg;      ///< complete SVG document
  std::string csv;      ///< the plotted series (svg::Figure::csv, or heatmap_csv)
};

/// Every figure of the report (`history` includes the current run as its last entry).
std::vector<ReportFigure> compare_figures(const Recording& rec, const CompareRunResult& r,
                                          const std::vector<HistoryEntry>& history);

/// Heat map of values[row][col] on a diverging blue-white-red scale symmetric about 0 (ColorBrewer
/// RdBu, svg::diverging_color; NaN cells grey), with row/column labels, the columns' axis title
/// and the value printed in each cell.
std::string heatmap_svg(const std::vector<std::vector<double>>& values, const std::vector<std::string>& row_labels,
                        const std::vector<std::string>& col_labels, const std::string& title, const std::string& unit,
                        const std::string& col_axis = "");

/// The heat map's values as CSV: one row per cell, columns row_name, col_name, value_name (empty
/// for NaN cells).
std::string heatmap_csv(const std::vector<std::vector<double>>& values, const std::vector<std::string>& row_labels,
                        const std::vector<std::string>& col_labels, const std::string& row_name,
                        const std::string& col_name, const std::string& value_name);

/// The compared frames as CSV: trial, time_s, measured_deg, model_deg, residual_deg (model -
/// measured), one row per frame kept by the comparison (outliers dropped).
std::string model_vs_measured_csv(const Comparison& c);

/// Writes every figure into `dir` as NAME.svg and NAME.csv, and model_vs_measured.csv; each file
/// atomically.
void write_report_figures(const std::string& dir, const std::vector<ReportFigure>& figs, const Comparison& c);

/// The self-contained report page (figures inlined, no scripts or external resources).
std::string compare_report_html(const Recording& rec, const CompareRunResult& r, const std::vector<ReportFigure>& figs,
                                const std::vector<HistoryEntry>& history, const std::string& label,
                                const std::string& data_file);

}  // namespace pneufem
