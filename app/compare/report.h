#pragma once
// Figures and the offline HTML report of `pneufem compare` (app/compare/command.h). Figures follow the
// seed paper's Results: pressure and angle against time per trial (model overlaid), angle vs
// pressure with the 2.5 s -> end-of-hold spread as bars, NRMSE per trial, absolute error per
// step grouped by trial, error and spread per step; plus the diagnostics the paper lacks: the
// step x trial residual map (heat map), the residual against time since the step start, the
// region sensitivities and the study history (the error of each model variant, in order).
// All SVG is deterministic (viz/svg_plot.h; the heat map is drawn here as coloured rects).
#include <string>
#include <vector>

#include "app/compare/command.h"

namespace pneufem {

struct ReportFigure {
  std::string name;     ///< file stem, e.g. "fig_trial_1"
  std::string title;
  std::string caption;  ///< what to read from it
  std::string section;  ///< "figures", "fails", "regions" or "history"
  std::string svg;      ///< complete SVG document
};

/// Every figure of the report (`history` includes the current run as its last entry).
std::vector<ReportFigure> compare_figures(const Recording& rec, const CompareRunResult& r,
                                          const std::vector<HistoryEntry>& history);

/// Heat map of values[row][col] on a diverging blue-white-red scale symmetric about 0 (NaN
/// cells grey), with row/column labels and the value printed in each cell.
std::string heatmap_svg(const std::vector<std::vector<double>>& values, const std::vector<std::string>& row_labels,
                        const std::vector<std::string>& col_labels, const std::string& title, const std::string& unit);

/// The self-contained report page (figures inlined, no scripts or external resources).
std::string compare_report_html(const Recording& rec, const CompareRunResult& r, const std::vector<ReportFigure>& figs,
                                const std::vector<HistoryEntry>& history, const std::string& label,
                                const std::string& data_file);

}  // namespace pneufem
