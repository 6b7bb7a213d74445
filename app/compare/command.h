#pragma once
// `pneufem compare`: a scene against a researcher's recording. Simulates every trial driven by
// its measured pressure (app/simulate/drive.h), compares the angles (analysis/model_vs_measured.h) and writes, into
// the output directory (each file atomically, and only after the data were read, the model was
// solved and the metrics computed, so bad input or a failed simulation leaves nothing
// half-written):
//
//   metrics.json   schema below
//   metrics.csv    one row per trial x step: trial,step,t_start_s,t_end_s,level_kPa,
//                  measured_mark_deg,model_mark_deg,abs_error_deg,spread_measured_deg,
//                  spread_model_deg,slope_measured_deg_s,slope_model_deg_s,slope_residual_deg_s,
//                  steady,steady_model,mean_residual_deg,frames      (NaN written as empty)
//   fig_*.svg      the report's figures (see app/compare/report.h)
//   report.html    one self-contained offline page (inline SVG, no scripts)
//   scene.toml     the resolved scene, headed by a note that [load] was replaced
//   history.jsonl  one line appended per run (see HistoryEntry)
//   vtu/worst_N.vtu  fields at the states of the largest |model - measured| angle
//
// metrics.json: {
//   "pneufem_version", "command_line", "label", "data_file", "scene_hash",
//   "nrmse"              pooled over all frames of all trials: rmse_deg / range_deg,
//   "rmse_deg", "range_deg", "rss_deg2", "n"   (n frames: AIC = n ln(rss/n) + 2 k),
//   "noise_floor_nrmse"  best NRMSE a perfect model could reach (tracking noise / range),
//   "trial_nrmse": [..]  per trial, same order as "trials",
//   "trials": [{ "trial", "nrmse_mark" (paper: RMSE at the 2.5 s marks / range of measured marks),
//                "nrmse", "rmse_deg", "range_deg", "frames", "outliers", "noise_deg",
//                per step: "levels_kPa", "t_start_s", "abs_error_deg", "measured_mark_deg",
//                "model_mark_deg", "spread_measured_deg", "spread_model_deg",
//                "slope_measured_deg_s", "slope_model_deg_s", "slope_residual_deg_s",
//                "steady", "steady_model", "mean_residual_deg" }],
//   "residual_map_deg": [[per step] per trial],
//   "residual_profile": { "bin_s", "t_s", "all_deg", "early_trials_deg", "late_trials_deg",
//                         "before_mark_deg", "after_mark_deg" },
//   "regions": null or [{ "region", "elements", "best_scale", "variance_fraction", "nrmse" }]
//              sorted by variance_fraction, descending,
//   "worst_states": [{ "trial", "time_s", "model_deg", "measured_deg", "file" }],
//   "simulation": { "status", "failure", "states", "pressure_tolerance_kPa", "wall_s",
//                   "model": "full" | "reduced" | "full (fallback: <why>)",
//                   with the reduced model also "reduced_offline_s", "reduced_basis",
//                   "reduced_worst_check_deg" }, "wall_s",
//   "warnings": [..], "mesh": {..}, "scene": {..resolved..} }
// NaN (a step without a mark) is written as null.
//
// Region sensitivity (--regions): for each region tag present in the mesh, the model is solved
// again with regions.<tag>.stiffness_scale = 0.9; the angle change per unit scale at the compared
// frames is that region's sensitivity vector s, and the residual e = model - measured is
// projected onto it (analysis/model_vs_measured.h, project_residual): best_scale = 1 + delta is the scale
// that best cancels the residual by that region alone (linearised), variance_fraction the share
// of the residual sum of squares it removes. Regions ranked by that share say where a stiffness
// error would explain the disagreement. One extra simulation per region.
#include <string>
#include <vector>

#include "analysis/model_vs_measured.h"
#include "app/compare/history.h"
#include "app/compare/result.h"
#include "app/simulate/drive.h"
#include "scenes/scene.h"

namespace pneufem {

struct CompareRunOptions {
  std::string data_path;     ///< canonical CSV (analysis/measurements.h)
  std::string dlc_map_path;  ///< "" or a DeepLabCut map (app/compare/dlc_map.h): angles from tracks
  std::string out_dir;
  std::string label;         ///< history label; "" = the scene file's name (or "default")
  bool regions = false;      ///< region sensitivity (one simulation per region)
  double region_scale = 0.9; ///< stiffness scale of the perturbed region
  int threads = 0;
  bool progress = false;             ///< a progress line redrawn in place (a terminal)
  double progress_log_every_s = 0.0; ///< else a progress line every this many seconds (0 = none)
  std::string command_line;
  CompareOptions compare;
  /// The reduced model's cached offline part (solver.model = "reduced"; app/simulate/drive.h);
  /// "" = computed on every run.
  std::string cache_dir;
};

/// Runs the comparison and writes the directory (see above). InputError for bad data or scene.
/// When the model run stops early (PhysicsError), the frames solved before are compared and
/// written, with drive.failure set and "status": "incomplete" in metrics.json; the run is not
/// added to the study history.
CompareRunResult run_compare(const Scene& scene, const CompareRunOptions& opt);

}  // namespace pneufem
