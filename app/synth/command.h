#pragma once
// `pneufem synth`: measurement-like data from a scene with hidden effects, sampled like the seed
// paper's rig (inlet pressure sensor at 400 Hz, DeepLabCut angle from 30 fps video), to test
// `compare` and `diagnose` against a known truth.
//
// Pipeline:
//  1. scene = SCENE.toml + --set, then the hidden candidate effects (app/diagnose/effect_catalog.h) at their
//     truth values, then --set again (so a user's --set overrides a hidden effect's value);
//  2. commanded inlet: the scene's staircase (scenes/build_model.h inlet_load, as every command
//     builds it) as ideal steps at each step start (load.ramp_s is ignored: the controller model
//     supplies the rise); the true inlet pressure is the closed-form
//     response of a second-order controller,
//        p_in(t) = sum_k dL_k S(t - t_k),  S(s) = 1 - exp(-zeta w s) (cos(w_d s) + zeta/sqrt(1-zeta^2) sin(w_d s)),
//     w = 2 pi f_n, w_d = w sqrt(1 - zeta^2) (zeta = 0.65, f_n = 1 Hz: 6.8 % overshoot, 10-90 % rise
//     1.96/w = 0.31 s, settled to 2 % in 4/(zeta w) = 0.98 s);
//  3. the model is driven by that inlet: a piecewise-linear fit within inlet_tolerance_kPa (the
//     400 Hz samples simplified by Ramer-Douglas-Peucker; sampling the smooth response every 2.5 ms
//     adds < h^2/8 max|p''| = 2e-4 kPa per 5 kPa step), through load.pressure_lag_s (and
//     load.pressure_lag2_s) if set, and solved quasi-statically through all trials with a report at
//     every breakpoint and at least every report_every_s (so creep within a hold is resolved);
//  4. the model angle is interpolated linearly between solved states at the frame times; noise:
//     white Gaussian on both streams, plus outlier frames (tracking failures) jumping by
//     +-U(outlier_min_deg, outlier_max_deg).
// Deterministic for a seed: each (trial, stream) draws from its own mt19937_64 seeded through
// std::seed_seq{seed, trial, stream}, with a portable Box-Muller transform; the model is
// deterministic for any thread count.
//
// Outputs (atomic): OUT.csv (canonical measurements, analysis/measurements.h), OUT.truth.csv (the
// noise-free inlet pressure and model angle at the frame times, same format) and OUT.truth.json
// (hidden effects with values and scene keys, noise settings, seed, version, resolved scene).
#include <cstdint>
#include <string>
#include <vector>

#include "analysis/measurements.h"
#include "engine/load_history.h"

namespace pneufem {

struct SynthOptions {
  std::string scene_path;              ///< "" = the built-in default scene
  std::vector<std::string> sets;       ///< --set key=value
  std::vector<std::string> hidden;     ///< candidate names; empty or {"none"} = the control dataset
  std::string out_csv;                 ///< OUT.csv; OUT.truth.csv and OUT.truth.json beside it
  std::uint64_t seed = 1;
  int threads = 0;                     ///< 0 = all cores (results do not depend on it)
  double pressure_rate_Hz = 400.0;     ///< seed paper: pressure sensor at 400 Hz
  double angle_rate_Hz = 30.0;         ///< seed paper: 30 fps video
  double controller_hz = 1.0;          ///< natural frequency f_n of the inlet controller
  double controller_damping = 0.65;    ///< damping ratio zeta, 0 < zeta < 1
  double pressure_noise_kPa = 0.1;     ///< white noise of the pressure sensor (1 sigma)
  double angle_noise_deg = 0.3;        ///< white noise of the angle tracking (1 sigma)
  double outlier_fraction = 0.005;     ///< fraction of frames with a tracking failure
  double outlier_min_deg = 10.0, outlier_max_deg = 40.0;
  double report_every_s = 0.25;        ///< densest spacing of solved states during holds
  double inlet_tolerance_kPa = 0.05;   ///< piecewise-linear fit of the inlet driving the model: half the
                                       ///< sensor's 1-sigma noise, 1 % of a 5 kPa step
  bool progress = false;               ///< a progress line redrawn in place (a terminal; core/progress.h)
  double progress_log_every_s = 0.0;   ///< else a progress line every this many seconds (0 = none)
  std::string command_line;
};

struct SynthResult {
  Recording data;                      ///< what OUT.csv holds
  Recording truth;                     ///< what OUT.truth.csv holds
  std::vector<std::string> hidden_sets;///< the scene overrides of the hidden effects
  long states = 0;                     ///< solved states
  int outliers = 0;                    ///< outlier frames drawn
  double wall_s = 0.0;
};

/// Validates the options (InputError naming the option), runs the model and writes the outputs.
SynthResult run_synth(const SynthOptions& options);

/// Splits "a,b" into names; "none" = no effect. Throws InputError for unknown or repeated names
/// (listing the candidates).
std::vector<std::string> parse_hidden(const std::string& spec);

/// The commanded inlet of one staircase trial as ideal steps: the step starts where the level
/// changes and the jumps (kPa), from the trial's step metadata (load.ramp_s is not used: the
/// controller supplies the rise).
struct CommandedSteps {
  std::vector<double> t_s;
  std::vector<double> jump_kPa;
};
CommandedSteps commanded_steps(const TrialLoad& trial);

/// Closed-form inlet pressure (kPa) at time t of a second-order controller tracking steps of
/// size step_kPa[k] commanded at t_cmd_s[k] from rest at 0 (see the header comment).
double controller_pressure_kPa(const std::vector<double>& t_cmd_s, const std::vector<double>& step_kPa, double f_n_Hz,
                               double zeta, double t);

}  // namespace pneufem
