#include "app/compare/report.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "analysis/hampel.h"
#include "core/atomic_file.h"
#include "viz/svg_plot.h"

namespace pneufem {

namespace {

using svg::escape;

std::string fmt(const char* f, double v) {
  if (!std::isfinite(v)) return "–";
  char buf[64];
  std::snprintf(buf, sizeof buf, f, v);
  return buf;
}

/// Every n-th sample so a plotted line has at most `max_points` points (400 Hz pressure).
Series decimate(const Series& s, std::size_t max_points) {
  if (s.t_s.size() <= max_points) return s;
  const std::size_t stride = (s.t_s.size() + max_points - 1) / max_points;
  Series out;
  for (std::size_t i = 0; i < s.t_s.size(); i += stride) {
    out.t_s.push_back(s.t_s[i]);
    out.value.push_back(s.value[i]);
  }
  return out;
}

std::vector<double> field(const std::vector<StepComparison>& st, double StepComparison::*f) {
  std::vector<double> v;
  for (const StepComparison& s : st) v.push_back(s.*f);
  return v;
}

ReportFigure make(const std::string& name, const std::string& title, const std::string& caption,
                  const std::string& section, svg::Figure& fig) {
  fig.id(name);
  return {name, title, caption, section, fig.svg(), fig.csv()};
}

/// The SVG element of a complete document (drops the XML declaration for inlining).
std::string inline_svg(const std::string& doc) {
  const std::size_t p = doc.find("<svg");
  return p == std::string::npos ? doc : doc.substr(p);
}

}  // namespace

std::string heatmap_svg(const std::vector<std::vector<double>>& values, const std::vector<std::string>& rows,
                        const std::vector<std::string>& cols, const std::string& title, const std::string& unit,
                        const std::string& col_axis) {
  // Sizes for print as the svg::Figure ones (viz/svg_plot.h): 14 px text in 480 px per journal
  // column. One column (480 px) while the cells are at least 48 px wide (up to 7 steps), else two
  // (960 px: the paper's ten steps), the cells filling it up to 64 / 96 px; cells too narrow for
  // their numbers (under 40 px, beyond 21 steps) show colour only (the numbers are in the CSV and
  // the cells' tooltips), and their column labels thin out.
  const double ch = 30, left = 84, right = 20, top = 52, bottom = 100;
  const double ncols = static_cast<double>(std::max<std::size_t>(cols.size(), 1));
  const int columns = (svg::kColumnWidthPx - left - right) / ncols >= 48 ? 1 : 2;
  const double width = columns * svg::kColumnWidthPx;
  const double cw = std::min(columns == 1 ? 64.0 : 96.0, (width - left - right) / ncols);
  const bool cell_numbers = cw >= 40;
  const std::size_t label_stride = static_cast<std::size_t>(std::ceil(44.0 / cw));
  const double height = top + ch * static_cast<double>(std::max<std::size_t>(rows.size(), 1)) + bottom;
  double vmax = 0;
  for (const auto& r : values)
    for (double v : r)
      if (std::isfinite(v)) vmax = std::max(vmax, std::abs(v));
  const double scale = vmax > 0 ? vmax : 1.0;
  std::string s = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  s += "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" + fmt("%.0f", width) + "\" height=\"" + fmt("%.0f", height) +
       "\" viewBox=\"0 0 " + fmt("%.0f", width) + " " + fmt("%.0f", height) +
       "\" font-family=\"Helvetica, Arial, sans-serif\" font-size=\"14\">\n";
  s += "<rect width=\"100%\" height=\"100%\" fill=\"white\"/>\n";
  s += "<text x=\"" + fmt("%.1f", width / 2) + "\" y=\"22\" text-anchor=\"middle\" font-size=\"16\">" + escape(title) +
       "</text>\n";
  for (std::size_t i = 0; i < rows.size(); ++i) {
    const double y = top + ch * static_cast<double>(i);
    s += "<text x=\"" + fmt("%.1f", left - 6) + "\" y=\"" + fmt("%.1f", y + ch / 2 + 5) + "\" text-anchor=\"end\">" +
         escape(rows[i]) + "</text>\n";
    for (std::size_t j = 0; j < cols.size(); ++j) {
      const double x = left + cw * static_cast<double>(j);
      const double v = i < values.size() && j < values[i].size() ? values[i][j] : std::nan("");
      const std::string fill = std::isfinite(v) ? svg::diverging_color(v / scale) : "#DDDDDD";
      // Dark cells (the ends of the map) get white numbers.
      const std::string ink = std::isfinite(v) && std::abs(v / scale) > 0.6 ? " fill=\"#FFFFFF\"" : "";
      s += "<rect x=\"" + fmt("%.1f", x) + "\" y=\"" + fmt("%.1f", y) + "\" width=\"" + fmt("%.1f", cw - 1) +
           "\" height=\"" + fmt("%.1f", ch - 1) + "\" fill=\"" + fill + "\"><title>" + escape(rows[i] + ", " + cols[j]) +
           ": " + fmt("%.3f", v) + " " + escape(unit) + "</title></rect>\n";
      if (cell_numbers)
        s += "<text x=\"" + fmt("%.1f", x + cw / 2) + "\" y=\"" + fmt("%.1f", y + ch / 2 + 5) +
             "\" text-anchor=\"middle\"" + ink + ">" + fmt("%.2f", v) + "</text>\n";
    }
  }
  for (std::size_t j = 0; j < cols.size(); j += label_stride)
    s += "<text x=\"" + fmt("%.1f", left + cw * (static_cast<double>(j) + 0.5)) + "\" y=\"" +
         fmt("%.1f", top + ch * static_cast<double>(rows.size()) + 17) + "\" text-anchor=\"middle\">" + escape(cols[j]) +
         "</text>\n";
  const double grid_right = left + cw * static_cast<double>(std::max<std::size_t>(cols.size(), 1));
  if (!col_axis.empty())
    s += "<text x=\"" + fmt("%.1f", 0.5 * (left + grid_right)) + "\" y=\"" +
         fmt("%.1f", top + ch * static_cast<double>(rows.size()) + 40) + "\" text-anchor=\"middle\" font-size=\"15\">" +
         escape(col_axis) + "</text>\n";
  s += "<text x=\"" + fmt("%.1f", 12) + "\" y=\"" + fmt("%.1f", height - 30) +
       "\">blue: model below the measurement, red: above;</text>\n";
  s += "<text x=\"" + fmt("%.1f", 12) + "\" y=\"" + fmt("%.1f", height - 11) + "\">full colour: " + fmt("%.3g", scale) +
       " " + escape(unit) + "</text>\n";
  return s + "</svg>\n";
}

std::string heatmap_csv(const std::vector<std::vector<double>>& values, const std::vector<std::string>& rows,
                        const std::vector<std::string>& cols, const std::string& row_name, const std::string& col_name,
                        const std::string& value_name) {
  std::string s = row_name + "," + col_name + "," + value_name + "\n";
  for (std::size_t i = 0; i < rows.size(); ++i)
    for (std::size_t j = 0; j < cols.size(); ++j) {
      const double v = i < values.size() && j < values[i].size() ? values[i][j] : std::nan("");
      s += svg::csv_field(rows[i]) + "," + svg::csv_field(cols[j]) + "," + svg::csv_number(v) + "\n";
    }
  return s;
}

std::string model_vs_measured_csv(const Comparison& c) {
  std::string s = "trial,time_s,measured_deg,model_deg,residual_deg\n";
  for (const ComparedFrame& f : c.frames)
    s += std::to_string(c.trials.at(static_cast<std::size_t>(f.trial_index)).trial) + "," + svg::csv_number(f.t_s) + "," +
         svg::csv_number(f.measured_deg) + "," + svg::csv_number(f.model_deg) + "," +
         svg::csv_number(f.model_deg - f.measured_deg) + "\n";
  return s;
}

void write_report_figures(const std::string& dir, const std::vector<ReportFigure>& figs, const Comparison& c) {
  const std::filesystem::path d(dir);
  for (const ReportFigure& f : figs) {
    write_file_atomic((d / (f.name + ".svg")).string(), f.svg);
    write_file_atomic((d / (f.name + ".csv")).string(), f.csv);
  }
  write_file_atomic((d / "model_vs_measured.csv").string(), model_vs_measured_csv(c));
}

namespace {

// One colour per trial, in every figure: measured and model of a trial alike (viz/svg_plot.h).
svg::Style trial_style(std::size_t k) {
  svg::Style st;
  st.color = svg::palette_color(k);
  return st;
}

// 1. Pressure and angle against time, per trial.
std::vector<ReportFigure> trial_figures(const Recording& rec, const CompareRunResult& r) {
  std::vector<ReportFigure> out;
  const Comparison& c = r.comparison;
  for (std::size_t k = 0; k < rec.trials.size(); ++k) {
    const TrialRecording& tr = rec.trials[k];
    svg::Figure fig(svg::kColumnWidthPx, 320);
    svg::Axes& ax = fig.axes();
    ax.xlabel("time (s)").ylabel("bending angle (deg)").y2label("pressure (kPa)");
    const Series p = decimate(tr.pressure_kPa, 2000);
    svg::Style ps;
    ps.color = "#999999";
    ps.line_width = 1.0;
    ps.axis = svg::YAxis::Right;
    ax.line(p.t_s, p.value, "pressure (measured)", ps);
    svg::Style ms = trial_style(k);
    ms.marker = svg::Marker::Circle;
    ms.marker_size = 1.5;
    ms.line_width = 0;
    // Outlier frames (dropped from every metric) are left out here too, so the axis shows the
    // response rather than a tracking glitch tens of degrees away.
    const Series a = decimate(hampel_filter(tr.angle_deg).series, 3000);
    ax.line(a.t_s, a.value, "angle (measured)", ms);
    const Series m = decimate(r.drive.trials[k].angle_deg, 3000);
    ax.line(m.t_s, m.value, "angle (model)", trial_style(k));
    fig.title("Trial " + std::to_string(tr.trial) + ": NRMSE " + fmt("%.4f", c.trials[k].nrmse) + ", " +
              std::to_string(c.trials[k].outliers) + " outlier(s) hidden");
    out.push_back(make("fig_trial_" + std::to_string(tr.trial), "Trial " + std::to_string(tr.trial) + ": time series",
                       "Measured pressure (grey, right axis), measured angle (dots) and the model driven by that "
                       "pressure (line, in the dots' colour).",
                       "figures", fig));
  }
  return out;
}

// 2. Angle vs pressure at the marks, with the spread to the end of the hold.
ReportFigure angle_pressure_figure(const Comparison& c) {
  svg::Figure fig(svg::kColumnWidthPx, 360);
  svg::Axes& ax = fig.axes();
  ax.xlabel("pressure step level (kPa)").ylabel("bending angle at the mark (deg)");
  for (std::size_t k = 0; k < c.trials.size(); ++k) {
    const TrialComparison& t = c.trials[k];
    const std::string trial = "trial " + std::to_string(t.trial);
    const std::vector<double> lv = field(t.steps, &StepComparison::level_kPa);
    const std::vector<double> mm = field(t.steps, &StepComparison::measured_mark_deg);
    const std::vector<double> me = field(t.steps, &StepComparison::measured_end_deg);
    const std::vector<double> pm = field(t.steps, &StepComparison::model_mark_deg);
    svg::Style dots = trial_style(k);
    dots.marker = svg::Marker::Circle;
    dots.line_width = 0;
    ax.line(lv, mm, trial + " measured", dots);
    std::vector<double> lo(mm.size()), hi(mm.size());
    for (std::size_t i = 0; i < mm.size(); ++i) lo[i] = std::min(mm[i], me[i]), hi[i] = std::max(mm[i], me[i]);
    svg::Style bars = trial_style(k);
    bars.line_width = 1.0;
    bars.in_legend = false;
    ax.range_bars(lv, lo, hi, trial + " spread to the end of the hold", bars);
    svg::Style line = trial_style(k);
    line.dash = "5 3";
    line.in_legend = false;
    ax.line(lv, pm, trial + " model", line);
  }
  return make("fig_angle_pressure", "Angle vs pressure",
              "Measured angle at the 2.5 s mark of each step (dots) with the spread to the end of the hold "
              "(bars), and the model at the marks (dashed), each trial in its own colour.",
              "figures", fig);
}

// 3. NRMSE per trial.
ReportFigure nrmse_figure(const Comparison& c) {
  svg::Figure fig(svg::kColumnWidthPx, 320);
  svg::Axes& ax = fig.axes();
  ax.xlabel("trial").ylabel("NRMSE").xinteger();
  std::vector<double> x, full, mark, floor;
  for (const TrialComparison& t : c.trials) {
    x.push_back(t.trial);
    full.push_back(t.nrmse);
    mark.push_back(t.nrmse_mark);
    floor.push_back(c.noise_floor_nrmse);
  }
  svg::Style a, b, f;
  a.marker = svg::Marker::Circle;
  b.marker = svg::Marker::Square;
  f.dash = "4 3";
  f.color = "#999999";
  ax.line(x, full, "full time series", a).line(x, mark, "at the 2.5 s marks (paper)", b).line(x, floor, "noise floor", f);
  return make("fig_nrmse", "NRMSE per trial",
              "NRMSE of each trial over all frames and at the marks; the dashed line is the best a perfect "
              "model could reach given the tracking noise.",
              "figures", fig);
}

/// The step axis' labels: the first trial's step levels (kPa), "step k" beyond them.
std::vector<std::string> step_labels(const Comparison& c) {
  std::size_t nsteps = 0;
  for (const TrialComparison& t : c.trials) nsteps = std::max(nsteps, t.steps.size());
  std::vector<std::string> cats;
  for (std::size_t k = 0; k < nsteps; ++k) {
    std::string lab = "step " + std::to_string(k + 1);
    if (!c.trials.empty() && k < c.trials.front().steps.size()) {
      const double v = std::round(c.trials.front().steps[k].level_kPa * 10.0) / 10.0;
      // Whole kPa without decimals, so ten steps fit a column's width; no "-0" for a rest level
      // of -0.0008 kPa.
      lab = fmt(v == std::round(v) ? "%.0f" : "%.1f", v == 0.0 ? 0.0 : v);
    }
    cats.push_back(lab);
  }
  return cats;
}

// 4. Absolute error per step, grouped by trial.
ReportFigure abs_error_figure(const Comparison& c, const std::vector<std::string>& cats) {
  const std::size_t nsteps = cats.size();
  svg::Figure fig(svg::kColumnWidthPx, 320);
  svg::Axes& ax = fig.axes();
  ax.xlabel("pressure step (kPa)").ylabel("absolute error at the mark (deg)");
  std::vector<svg::BarGroup> groups;
  for (std::size_t k = 0; k < c.trials.size(); ++k) {
    svg::BarGroup g;
    g.label = "trial " + std::to_string(c.trials[k].trial);
    g.values = field(c.trials[k].steps, &StepComparison::abs_error_deg);
    g.values.resize(nsteps, std::nan(""));
    g.color = svg::palette_color(k);
    groups.push_back(g);
  }
  ax.grouped_bars(cats, groups);
  return make("fig_abs_error", "Absolute error per step",
              "|model - measured| at the 2.5 s mark of each step, grouped by trial.", "figures", fig);
}

// 5. Error and spread per step.
ReportFigure error_spread_figure(const Comparison& c) {
  svg::Figure fig(2 * svg::kColumnWidthPx, 320, 1, 2);
  svg::Axes& e = fig.axes(0, 0);
  svg::Axes& sp = fig.axes(0, 1);
  e.title("absolute error at the mark").xlabel("pressure (kPa)").ylabel("deg");
  sp.title("spread: end of hold - mark").xlabel("pressure (kPa)").ylabel("deg");
  for (std::size_t k = 0; k < c.trials.size(); ++k) {
    const TrialComparison& t = c.trials[k];
    const std::string trial = "trial " + std::to_string(t.trial);
    const std::vector<double> lv = field(t.steps, &StepComparison::level_kPa);
    svg::Style m = trial_style(k);
    m.marker = svg::Marker::Circle;
    e.line(lv, field(t.steps, &StepComparison::abs_error_deg), trial, m);
    sp.line(lv, field(t.steps, &StepComparison::spread_measured_deg), trial + " measured", m);
    svg::Style d = trial_style(k);
    d.dash = "5 3";
    sp.line(lv, field(t.steps, &StepComparison::spread_model_deg), trial + " model", d);
  }
  return make("fig_error_spread", "Error and spread per step",
              "Left: absolute error at the mark. Right: creep after the mark, measured (solid) and model "
              "(dashed), each trial in its own colour — a model without time dependence has zero spread.",
              "figures", fig);
}

// 6. Residual map (step x trial).
ReportFigure residual_map_figure(const Comparison& c, const std::vector<std::string>& cats) {
  std::vector<std::string> rows, trials;
  for (const TrialComparison& t : c.trials) {
    rows.push_back("trial " + std::to_string(t.trial));
    trials.push_back(std::to_string(t.trial));
  }
  return {"fig_residual_map", "Residual map",
          "Mean residual (model - measured) over each step of each trial. A pattern along a row is a "
          "trial-to-trial drift (fatigue, softening); along a column a pressure-dependent error (stiffness "
          "curve).",
          "fails", heatmap_svg(c.residual_map_deg, rows, cats, "mean residual per step (deg)", "deg", "pressure step (kPa)"),
          heatmap_csv(c.residual_map_deg, trials, cats, "trial", "step_kPa", "mean_residual_deg")};
}

// 7. Residual vs time since the step start.
ReportFigure residual_profile_figure(const Comparison& c) {
  svg::Figure fig(svg::kColumnWidthPx, 320);
  svg::Axes& ax = fig.axes();
  ax.xlabel("time since the step start (s)").ylabel("mean residual (deg)");
  svg::Style a, e, l;
  a.color = "#000000";
  e.color = "#0072B2";
  e.dash = "5 3";
  l.color = "#D55E00";
  l.dash = "2 2";
  ax.line(c.profile.t_s, c.profile.mean_deg, "all steps", a)
      .line(c.profile_early_trials.t_s, c.profile_early_trials.mean_deg, "early trials", e)
      .line(c.profile_late_trials.t_s, c.profile_late_trials.mean_deg, "late trials", l);
  return make("fig_residual_profile", "Residual vs time in step",
              "Mean residual against the time since each step started: a transient after the start is "
              "lag or rate dependence the model lacks; a slope after the mark is creep; a constant offset "
              "is static stiffness.",
              "fails", fig);
}

// 8. Region sensitivity.
ReportFigure regions_figure(const std::vector<RegionSensitivity>& regions) {
  svg::Figure fig(svg::kColumnWidthPx, 320);
  svg::Axes& ax = fig.axes();
  ax.xlabel("region").ylabel("fraction of residual removed");
  std::vector<std::string> names;
  svg::BarGroup g;
  g.label = "variance fraction";
  for (const RegionSensitivity& s : regions) {
    names.push_back(s.region);
    g.values.push_back(s.variance_fraction);
  }
  ax.grouped_bars(names, {g}).legend(svg::Legend::None);
  return make("fig_regions", "Region sensitivity",
              "Share of the residual's sum of squares that rescaling one region's stiffness (best scale, "
              "linearised) would remove. Similar shares mean the regions cannot be told apart by this "
              "record; a best scale far from 1 (or negative) means that region alone cannot explain it.",
              "regions", fig);
}

// 9. History of the study: one bar per run, labelled "#i label" (the x axis is the run order).
ReportFigure history_figure(const std::vector<HistoryEntry>& history) {
  svg::Figure fig(std::max(svg::kColumnWidthPx, 70.0 * static_cast<double>(history.size())), 320);
  svg::Axes& ax = fig.axes();
  ax.xlabel("run (in order)").ylabel("pooled NRMSE").legend(svg::Legend::None);
  std::vector<std::string> names;
  svg::BarGroup g;
  g.label = "pooled NRMSE";
  for (std::size_t i = 0; i < history.size(); ++i) {
    names.push_back("#" + std::to_string(i + 1) + " " + history[i].label);
    g.values.push_back(history[i].nrmse);
  }
  ax.grouped_bars(names, {g});
  return make("fig_history", "Study history",
              "Pooled NRMSE of every compared model variant, in the order they were run (details in the "
              "table below).",
              "history", fig);
}

}  // namespace

std::vector<ReportFigure> compare_figures(const Recording& rec, const CompareRunResult& r,
                                          const std::vector<HistoryEntry>& history) {
  const Comparison& c = r.comparison;
  std::vector<ReportFigure> out = trial_figures(rec, r);
  out.push_back(angle_pressure_figure(c));
  out.push_back(nrmse_figure(c));
  const std::vector<std::string> cats = step_labels(c);
  out.push_back(abs_error_figure(c, cats));
  out.push_back(error_spread_figure(c));
  out.push_back(residual_map_figure(c, cats));
  out.push_back(residual_profile_figure(c));
  if (!r.regions.empty()) out.push_back(regions_figure(r.regions));
  out.push_back(history_figure(history));
  return out;
}

namespace {

/// The report's figures of one section (figure, inline SVG, caption).
std::string section_figures(const std::vector<ReportFigure>& figs, const std::string& section) {
  std::string s;
  for (const ReportFigure& f : figs)
    if (f.section == section)
      s += "<figure id=\"" + escape(f.name) + "\">\n" + inline_svg(f.svg) + "<figcaption><b>" + escape(f.title) +
           ".</b> " + escape(f.caption) + "</figcaption>\n</figure>\n";
  return s;
}

/// "Summary": the pooled metrics, one row per trial, and the warnings (folded).
std::string summary_section(const CompareRunResult& r) {
  const Comparison& c = r.comparison;
  std::string h = "<h2>Summary</h2>\n<table>\n<tr><th>pooled NRMSE</th><th>noise floor NRMSE</th><th>RMSE (deg)</th>"
       "<th>measured range (deg)</th><th>frames n</th><th>RSS (deg&#178;)</th></tr>\n<tr><td>" +
       fmt("%.4f", c.nrmse) + "</td><td>" + fmt("%.4f", c.noise_floor_nrmse) + "</td><td>" + fmt("%.3f", c.rmse_deg) +
       "</td><td>" + fmt("%.2f", c.range_deg) + "</td><td>" + std::to_string(c.n) + "</td><td>" + fmt("%.4g", c.rss_deg2) +
       "</td></tr>\n</table>\n";
  h += "<table>\n<tr><th>trial</th><th>NRMSE</th><th>NRMSE at marks (paper)</th><th>RMSE (deg)</th><th>steps</th>"
       "<th>outlier frames</th><th>angle noise (deg)</th></tr>\n";
  for (const TrialComparison& t : c.trials)
    h += "<tr><td>" + std::to_string(t.trial) + "</td><td>" + fmt("%.4f", t.nrmse) + "</td><td>" +
         fmt("%.4f", t.nrmse_mark) + "</td><td>" + fmt("%.3f", t.rmse_deg) + "</td><td>" +
         std::to_string(t.steps.size()) + "</td><td>" + std::to_string(t.outliers) + "</td><td>" +
         fmt("%.3f", t.noise_deg) + "</td></tr>\n";
  h += "</table>\n";
  if (!r.warnings.empty()) {
    h += "<details><summary>" + std::to_string(r.warnings.size()) + " warning(s)</summary><ul>\n";
    for (const std::string& w : r.warnings) h += "<li>" + escape(w) + "</li>\n";
    h += "</ul></details>\n";
  }
  return h;
}

/// "Where it fails": the five worst steps by |mean residual|, the worst trial, the residual before
/// and after the mark, the section's figures and the VTU files of the worst states.
std::string where_it_fails_section(const CompareRunResult& r, const std::vector<ReportFigure>& figs) {
  const Comparison& c = r.comparison;
  std::string h = "<h2>Where it fails</h2>\n";
  struct Cell {
    double abs_mean;
    std::size_t trial, step;
  };
  std::vector<Cell> cells;
  for (std::size_t k = 0; k < c.trials.size(); ++k)
    for (std::size_t j = 0; j < c.trials[k].steps.size(); ++j)
      if (std::isfinite(c.trials[k].steps[j].mean_residual_deg))
        cells.push_back({std::abs(c.trials[k].steps[j].mean_residual_deg), k, j});
  std::stable_sort(cells.begin(), cells.end(), [](const Cell& a, const Cell& b) { return a.abs_mean > b.abs_mean; });
  h += "<p>Worst steps (largest |mean residual|):</p>\n<table>\n<tr><th>trial</th><th>step</th><th>level (kPa)</th>"
       "<th>mean residual (deg)</th><th>abs error at mark (deg)</th><th>spread measured / model (deg)</th>"
       "<th>steady</th></tr>\n";
  for (std::size_t i = 0; i < std::min<std::size_t>(cells.size(), 5); ++i) {
    const StepComparison& s = c.trials[cells[i].trial].steps[cells[i].step];
    h += "<tr><td>" + std::to_string(c.trials[cells[i].trial].trial) + "</td><td>" + std::to_string(cells[i].step + 1) +
         "</td><td>" + fmt("%.2f", s.level_kPa) + "</td><td>" + fmt("%.3f", s.mean_residual_deg) + "</td><td>" +
         fmt("%.3f", s.abs_error_deg) + "</td><td>" + fmt("%.3f", s.spread_measured_deg) + " / " +
         fmt("%.3f", s.spread_model_deg) + "</td><td>" + (s.steady ? "yes" : "no") + "</td></tr>\n";
  }
  h += "</table>\n";
  if (!c.trials.empty()) {
    const auto worst = std::max_element(c.trials.begin(), c.trials.end(), [](const TrialComparison& a,
                                                                           const TrialComparison& b) {
      return !(a.nrmse >= b.nrmse);
    });
    h += "<p>Worst trial: " + std::to_string(worst->trial) + " (NRMSE " + fmt("%.4f", worst->nrmse) + ").</p>\n";
  }
  h += "<p>Mean residual before the 2.5 s mark (transient): " + fmt("%.3f", c.residual_before_mark_deg) +
       " deg; after it (settled): " + fmt("%.3f", c.residual_after_mark_deg) + " deg.</p>\n";
  h += section_figures(figs, "fails");
  if (!r.drive.worst.empty()) {
    h += "<p>Fields at the worst states (ParaView: Warp By Vector with displacement_m):</p>\n<ul>\n";
    for (const WorstState& w : r.drive.worst)
      h += "<li><code>vtu/" + escape(std::filesystem::path(w.file).filename().string()) + "</code>: trial " +
           std::to_string(w.trial) + ", t = " + fmt("%.2f", w.time_s) + " s, model " + fmt("%.2f", w.model_deg) +
           " deg vs measured " + fmt("%.2f", w.measured_deg) + " deg</li>\n";
    h += "</ul>\n";
  }
  return h;
}

/// "Region sensitivity": per region the best stiffness scale and the residual it removes (or how
/// to compute it).
std::string regions_section(const CompareRunResult& r, const std::vector<ReportFigure>& figs) {
  std::string h = "<h2>Region sensitivity</h2>\n";
  if (r.regions.empty()) {
    h += "<p>Not computed (run with <code>--regions</code>: one extra simulation per region).</p>\n";
  } else {
    h += "<table>\n<tr><th>region</th><th>elements</th><th>best stiffness scale</th><th>fraction of residual "
         "removed</th><th>NRMSE at scale 0.9</th></tr>\n";
    for (const RegionSensitivity& s : r.regions)
      h += "<tr><td>" + escape(s.region) + "</td><td>" + std::to_string(s.elements) + "</td><td>" +
           fmt("%.3f", s.best_scale) + "</td><td>" + fmt("%.3f", s.variance_fraction) + "</td><td>" +
           fmt("%.4f", s.nrmse) + "</td></tr>\n";
    h += "</table>\n" + section_figures(figs, "regions");
  }
  return h;
}

/// "History": the figure and one row per earlier comparison in this --out.
std::string history_section(const std::vector<HistoryEntry>& history, const std::vector<ReportFigure>& figs) {
  std::string h = "<h2>History</h2>\n" + section_figures(figs, "history");
  h += "<table>\n<tr><th>#</th><th>time (UTC)</th><th>label</th><th>scene hash</th><th>source</th><th>pooled "
       "NRMSE</th></tr>\n";
  for (std::size_t i = 0; i < history.size(); ++i)
    h += "<tr><td>" + std::to_string(i + 1) + "</td><td>" + escape(history[i].time_utc) + "</td><td>" +
         escape(history[i].label) + "</td><td><code>" + escape(history[i].scene_hash) + "</code></td><td>" +
         escape(history[i].source) + "</td><td>" + fmt("%.4f", history[i].nrmse) + "</td></tr>\n";
  return h + "</table>\n";
}

}  // namespace

std::string compare_report_html(const Recording& rec, const CompareRunResult& r, const std::vector<ReportFigure>& figs,
                                const std::vector<HistoryEntry>& history, const std::string& label,
                                const std::string& data_file) {
  std::string h = "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<title>pneufem compare: " +
                  escape(label) + "</title>\n<style>\n"
                  "body{font-family:Helvetica,Arial,sans-serif;max-width:1000px;margin:2em auto;color:#222}\n"
                  "table{border-collapse:collapse;margin:0.5em 0}td,th{border:1px solid #ccc;padding:2px 8px;"
                  "text-align:right}th{background:#f3f3f3}figure{margin:1em 0}figcaption{color:#555;font-size:0.9em}\n"
                  "</style>\n</head>\n<body>\n";
  h += "<h1>Model vs measurement: " + escape(label) + "</h1>\n";
  h += "<p>Data: <code>" + escape(data_file) + "</code> (" + std::to_string(rec.trials.size()) +
       " trials). The model was driven by the measured pressure of every trial (" + std::to_string(r.drive.states) +
       " solved states, pressure tolerance " + fmt("%.3g", r.drive.tolerance_kPa) + " kPa).</p>\n";
  h += summary_section(r);
  h += "<h2>Figures</h2>\n" + section_figures(figs, "figures");
  h += where_it_fails_section(r, figs);
  h += regions_section(r, figs);
  h += history_section(history, figs);
  h += "</body>\n</html>\n";
  return h;
}

}  // namespace pneufem
