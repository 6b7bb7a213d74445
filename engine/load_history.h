#pragma once
// Cavity-pressure histories: one piecewise-linear p(t) per trial, plus the times at which the
// results are reported. Built by scenes/ from the staircase protocol or a measured CSV.
#include <string>
#include <vector>

namespace pneufem {

struct TrialLoad {
  std::vector<double> time_s;       ///< breakpoints, strictly increasing, first = 0
  std::vector<double> pressure_Pa;  ///< pressure at each breakpoint (linear in between)
  std::vector<double> output_s;     ///< report times (within [0, duration])
  /// Step (plateau) intervals [start, end) for metrics: the paper's 2.5 s mark is start + 2.5.
  std::vector<double> step_start_s, step_end_s;
  std::vector<double> step_level_Pa;
  double mark_s = 2.5;  ///< the paper's mark: metrics sample each step at start + mark_s
  double duration() const { return time_s.empty() ? 0.0 : time_s.back(); }
  double pressure(double t) const;
};

struct LoadHistory {
  std::vector<TrialLoad> trials;
  double rest_between_trials_s = 0.0;  ///< unloaded time between trials (material recovery)
  std::string description;
};

/// The most reports (reported states, over all trials) one run may make. Each is a stop of the
/// solver, a row of states.csv and angles.csv and, with output.vtu = "all", a VTU file: a million is
/// hundreds of MB of output and days of solving, while the paper's ten trials make 200 and the
/// densest example protocol a few thousand. Above it a protocol is a mistake (output_every_s in
/// the wrong unit), which used to end in bad_alloc or a loop that never ends.
inline constexpr double kMaxReports = 1e6;

/// The most pressure levels of a staircase: each is at least one Newton solve; the paper's has 10.
/// More (a step_kPa in the wrong unit) would only be noise, and their count must fit an int.
inline constexpr double kMaxStaircaseLevels = 1e4;

/// How big a staircase would be, computed before building it (doubles: the count of a mistaken
/// protocol may not fit an int).
struct StaircaseSize {
  double levels = 0.0;   ///< 0, dp, ..., p_max
  double reports = 0.0;  ///< over all trials, an upper estimate
};
StaircaseSize staircase_size(double p_max_Pa, double dp_Pa, double hold_s, int trials, double output_every_s);

/// The paper's staircase: levels 0, dp, ..., p_max, each held `hold_s` (the pressure reaches a
/// level within `ramp_s`), `trials` repetitions; reports at start + mark_s and at the end of
/// each hold (plus every `output_every_s` if > 0). Throws InputError naming the load key for a
/// value out of range and for more than kMaxStaircaseLevels levels or kMaxReports reports.
LoadHistory staircase(double p_max_Pa, double dp_Pa, double hold_s, double ramp_s, int trials,
                      double mark_s, double rest_s, double output_every_s = 0.0);

/// Ramer-Douglas-Peucker: flags (1) the fewest samples of (t, v) whose linear interpolation stays
/// within `tol` (vertical deviation) of every sample; the first and last are always kept.
/// Iterative, so a 10^5-sample pressure record cannot overflow the stack.
std::vector<char> rdp_keep(const std::vector<double>& t, const std::vector<double>& v, double tol);

}  // namespace pneufem
