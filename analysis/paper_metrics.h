#pragma once
// The seed paper's comparison metrics between an angle record and a reference record (the ideal
// elastic model, or a measurement), per trial over the staircase steps:
//   * the angle at the "mark" (2.5 s after each step starts) and at the end of the step;
//   * NRMSE over the steps of the mark angles: RMSE / (max - min of the reference mark angles);
//   * absolute error per step at the mark, |a - ref|;
//   * spread per step: angle at the end of the step minus angle at the mark (non-plateau creep).
#include <string>
#include <vector>

namespace pneufem {

/// Angles of one trial sampled at each step's mark and end (degrees), and the step levels.
struct StepAngles {
  int trial = 1;
  std::vector<double> level_kPa;
  std::vector<double> at_mark_deg;
  std::vector<double> at_end_deg;
};

struct TrialMetrics {
  int trial = 1;
  double nrmse = 0.0;
  std::vector<double> abs_error_deg;
  std::vector<double> spread_deg;
  std::vector<double> mark_deg;      ///< the compared record at the marks
  std::vector<double> reference_deg; ///< the reference at the marks
  /// The trial was skipped by cycle jumping: its angles are extrapolated (engine/cycle_jump.h).
  bool extrapolated = false;
};

/// Metrics of `a` against `reference` (same number of steps). Throws InputError when the step
/// counts differ or the reference range is zero.
TrialMetrics paper_metrics(const StepAngles& a, const StepAngles& reference);

/// JSON document {"trials": [...], "levels_kPa": [...]} (the format metrics.json uses); an
/// extrapolated trial carries "extrapolated": true (the field is absent for solved trials).
std::string metrics_json(const std::vector<TrialMetrics>& trials, const std::vector<double>& levels_kPa);

}  // namespace pneufem
