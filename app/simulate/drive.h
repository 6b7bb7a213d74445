#pragma once
// Simulating a recording: the model is driven by the MEASURED inlet pressure of every trial (not
// by the scene's own [load] section, which is ignored and replaced — the scene keeps its meaning
// for everything else: mesh, materials, solver, rest between trials), and its bending angle is
// returned at the recording's own frame times, ready to be compared frame by frame.
//
// Pressure path (per trial):
//  1. running median over window_s (odd sample count >= 5): removes sensor noise and valve
//     spikes but keeps edges (on any monotone stretch — a ramp, a plateau corner — the median IS
//     the centre sample, so a noise-free staircase passes through unchanged);
//  2. Ramer-Douglas-Peucker simplification to within `pressure_tolerance_kPa` (vertical
//     deviation): each kept sample becomes one breakpoint of a piecewise-linear history, i.e. one
//     static state, so 400 Hz of noise does not become thousands of states. Auto tolerance:
//     max(3 sigma, 0.05 kPa), sigma = 1.4826 MAD(first differences)/sqrt(2) of the raw record
//     (3 sigma of the raw noise is above what survives the median, so noise breakpoints are
//     rare; 0.05 kPa is ~0.1 % of a 45 kPa staircase and bounds the pressure error of a
//     noise-free record); the breakpoints' values are then fitted by least squares to all the
//     filtered samples (a plateau takes the mean of its samples, not the value of one of them:
//     near the limit point 0.05 kPa is 0.25° of angle);
//  3. extra states so that the solved states are at most max_report_gap_s apart wherever the
//     pressure changes (ramps) and, for models with history (creep, damage: Assembler state
//     non-empty), everywhere, so relaxation inside holds is resolved; for elastic models a hold
//     at constant pressure has a constant angle and needs no extra states.
// A scene with a chamber-pressure lag (load.pressure_lag_s, load.pressure_lag2_s,
// scenes/pressure_lag.h) filters the measured inlet pressure through it, as it would its own load.
// Trial times are the recording's (times before 0 are allowed: the trial clock is shifted for
// the engine and shifted back). All trials run in order through ONE quasi-static run, so
// internal variables carry over; between trials the pressure is released to 0 and held for the
// scene's load.rest_s.
//
// The model angle at a frame time is the linear interpolation between the two solved states
// around it (frames before the first / after the last state of the trial take that state's
// angle). Physics failures propagate as PhysicsError; bad input (a trial without pressure)
// throws InputError naming the data file and trial. Results do not depend on `threads`.
//
// Model. A scene with solver.model = "reduced" is driven through the reduced-order model
// (app/simulate/reduced.h): its offline part is traced for the measured load's peak and cached in
// DriveOptions::cache_dir. With `reduced_check` every report is checked against the full residual
// as `simulate` does; a reduced run whose estimated angle error exceeds solver.reduced_check_deg,
// or that fails, is replaced by the full FEM, and DriveResult::model says so. Without the check
// (calibration loops, which only need angles) the reduced run's angles are used as they are.
#include <functional>
#include <string>
#include <vector>

#include "analysis/measurements.h"
#include "engine/load_history.h"
#include "engine/mesh.h"
#include "scenes/scene.h"

namespace pneufem {

struct DriveOptions {
  double pressure_tolerance_kPa = 0.0;  ///< RDP tolerance; 0 = auto (see above)
  double median_window_s = 0.05;        ///< running-median window of the pressure (20 samples at 400 Hz)
  double max_report_gap_s = 0.25;       ///< solved states at least this dense (see above)
  int threads = 0;                      ///< 0 = all cores
  bool progress = false;                ///< progress line on stderr, redrawn in place (a terminal)
  /// Not on a terminal: a progress line every this many seconds of wall time (0 = none; core/progress.h).
  double progress_log_every_s = 0.0;
  std::string progress_label = "compare";  ///< the progress line's first word
  std::string vtu_dir;                  ///< "" = no files; else VTU of the `vtu_worst` worst states
  int vtu_worst = 3;                    ///< states with the largest |model - measured| angle
  /// On a PhysicsError (e.g. the actuator past its limit point): false = rethrow; true = return
  /// the frames solved so far (later frames NaN) with DriveResult::failure set.
  bool partial_on_failure = false;
  /// Reduced model only: the cache of its offline part ("" = computed each call) and whether the
  /// reports are checked (one whole-mesh replay; false = no VTU of worst states either).
  std::string cache_dir;
  bool reduced_check = true;
  /// Reduced model only: replace a run that fails or whose check exceeds the tolerance by the full
  /// FEM (false: a failure propagates as PhysicsError, an estimate above the tolerance is only
  /// recorded; for callers that never want the FEM's cost, e.g. diagnose's refinement).
  bool reduced_fallback = true;
  /// Applied to every pressure of the load after the lag (inlet Pa -> chamber Pa; empty = none):
  /// diagnose drives a coarser calibration mesh with the pressure at which it bends as the scene's
  /// mesh does (app/diagnose/evaluator.h).
  std::function<double(double)> chamber_pressure;
  /// Reduced model only: the peak pressure (Pa) its offline part is built for, when above the load's
  /// own (0 = elastic_reference_peak_Pa of the scene's protocol and the recording). The offline part
  /// is cached by this peak, so recordings of one protocol, whose noisy peaks differ, share it.
  double reduced_peak_Pa = 0.0;
};

/// The peak pressure (Pa) the elastic FEM work of a recording is done for (the reduced model's
/// offline part in compare and diagnose, diagnose's static curves), and so the pressure its cache
/// entries are keyed by: the reduced model's path is traced to 1.8 x it (softened models reach
/// angles the elastic one reaches only above the peak), the static curves and the calibration
/// mesh's pressure map span [0, it]. It must cover every recorded pressure AND be the same for
/// every recording of one protocol, whose measured peaks differ by the controller's overshoot and
/// the sensor noise (keyed by the exact measured peak, a second recording of the same protocol
/// never found the first one's entries; issue 28). So:
///  * a recording whose peak lies within [0.8, 1.1] x the scene's commanded peak follows the
///    scene's protocol: 1.1 x the commanded peak (10 % headroom: synth's controller overshoots a
///    10 kPa step by ~7 %, 0.7 kPa, and the sensor noise is ~0.1 kPa), the same for all of them;
///  * any other recording (its own protocol, not the scene's): its peak rounded UP to a grid of
///    half its leading power of ten (5 kPa for peaks of 10-100 kPa), so noisy peaks share a key
///    unless they straddle a grid line. Why not always the grid: a protocol peak on a grid line
///    (45 kPa -> 50 kPa) would put half of its noisy recordings on either side of it.
/// `scene_peak_Pa` <= 0 (no protocol in the scene) means the second rule.
double elastic_reference_peak_Pa(double scene_peak_Pa, double recorded_peak_Pa);

struct TrialTrace {
  int trial = 0;
  Series angle_deg;  ///< model angle at every measured angle time of this trial (same t_s)
  Series states_angle_deg, states_pressure_kPa;  ///< the solved states (for plots)
};

/// One written VTU of a worst state.
struct WorstState {
  int trial = 0;
  double time_s = 0.0, model_deg = 0.0, measured_deg = 0.0;
  std::string file;  ///< path of the VTU
};

struct DriveResult {
  std::vector<TrialTrace> trials;  ///< in the recording's order
  long states = 0;                 ///< equilibria solved
  double wall_s = 0.0;
  std::string scene_text;          ///< resolved scene (TOML), with a header saying the load was replaced
  double tolerance_kPa = 0.0;      ///< the RDP tolerance used (auto or given)
  std::vector<WorstState> worst;   ///< VTU files written (empty without vtu_dir)
  MeshStats mesh;                  ///< statistics of the model's mesh (regions: elements_per_region)
  std::string failure;             ///< why the run stopped early ("" = it completed; partial_on_failure)
  double failure_time_s = -1.0;    ///< recording time of the last solved state of the failed trial
  /// Which model made the angles: "full", "reduced", or "full (fallback: <why>)".
  std::string model = "full";
  double reduced_offline_s = 0.0;   ///< reduced model: wall time of its offline part (trace + basis, or reading them)
  std::string reduced_basis_source; ///< reduced model: "computed" or "cache <file>"
  double reduced_worst_check_deg = -1.0;  ///< reduced model, checked: largest estimated angle error over the reports
  int reduced_enrichments = 0;      ///< reduced model: basis enrichments made (solver.reduced_enrich_rounds)
};

DriveResult simulate_recording(const Scene& scene, const Recording& rec, const DriveOptions& opt);

/// A recording of angles alone (Recording::pressure_recorded false: video of a commanded protocol,
/// as in the seed paper): fills every trial's pressure series with the scene's inlet load
/// (scenes/build_model.h inlet_load: [load] before any chamber lag, which the drive then applies
/// as to a measured inlet), sampled at 200 Hz and at the protocol's breakpoints over
/// [min(0, first frame), max(end of the protocol's trial, last frame)]; the recording's k-th trial
/// takes the protocol's k-th (its last for later ones). The protocol's time 0 is the recording's
/// time_s = 0. Notes go to rec.warnings (also frames more than 1 s after the protocol's trial ends,
/// which see its last level held). A recording with pressure is left alone.
void fill_commanded_pressure(Recording& rec, const Scene& scene);

/// Steps 1-2 above for one pressure series (kPa): the kept breakpoints. `tolerance_kPa` <= 0
/// means auto; the tolerance used is stored in *used_kPa when given.
Series simplify_pressure(const Series& pressure_kPa, double tolerance_kPa, double median_window_s,
                         double* used_kPa = nullptr);

/// The load history the model is driven with (steps 1-3); `t_offset_s[k]` is the recording time
/// of engine time 0 of trial k. `rate_dependent` adds the hold states of step 3.
LoadHistory measured_load(const Recording& rec, const DriveOptions& opt, double rest_s, bool rate_dependent,
                          std::vector<double>& t_offset_s, double* used_tolerance_kPa = nullptr);

}  // namespace pneufem
