#pragma once
// The study history of a compare/diagnose output directory: history.jsonl, one JSON line per run
// ({"time_utc", "label", "scene_hash", "nrmse", "trial_nrmse", ["trial_rmse_deg",] "source"}), which the report plots
// as the error of each model variant in order. `pneufem compare` and `pneufem diagnose` append to it.
#include <string>
#include <vector>

#include "scenes/scene.h"

namespace pneufem {

/// One line of history.jsonl: {"time_utc", "label", "scene_hash", "nrmse", "trial_nrmse", "source"}.
struct HistoryEntry {
  std::string time_utc;   ///< ISO 8601, e.g. 2026-11-22T06:10:00Z
  std::string label;
  std::string scene_hash; ///< scene_hash() of the resolved scene
  double nrmse = 0.0;     ///< pooled
  std::vector<double> trial_nrmse;
  std::vector<double> trial_rmse_deg;  ///< per trial, deg; written only when given (diagnose gives it)
  std::string source = "compare";  ///< which command wrote it ("compare", "diagnose", ...)
};

/// Appends one line to dir/history.jsonl (the whole file is rewritten atomically, so a crash
/// leaves either the old or the new history). Creates dir if needed.
void append_history(const std::string& dir, const HistoryEntry& entry);

/// Reads dir/history.jsonl (missing file = empty); lines that cannot be read are skipped.
std::vector<HistoryEntry> read_history(const std::string& dir);

/// FNV-1a 64-bit hash (16 hex digits) of the resolved scene text: equal scenes, equal hash.
std::string scene_hash(const Scene& scene);

/// Current UTC time, ISO 8601 to the second.
std::string utc_now();

}  // namespace pneufem
