#pragma once
// Synthetic recordings of the seed paper's staircase experiment with a known truth, for the
// measurement tests: pressure at `rate_Hz` following a commanded staircase through a first-order
// rise (tau_s) plus an overshoot bump, with Gaussian sensor noise; the angle at `fps` following the
// pressure through a static curve and its own lag, with tracking noise and optional outlier frames.
#include <cstddef>
#include <string>
#include <vector>

#include "analysis/measurements.h"

namespace pneufem::testing {

struct StaircaseSpec {
  std::vector<double> levels_kPa = {0, 5, 10, 15, 20, 25, 30, 35, 40, 45};  ///< first = initial rest
  double hold_s = 16.0;          ///< time from one command to the next (and the rest before the first)
  double command_phase_s = 0.00123;  ///< commands fall between samples: T_k = k hold + phase
  double rate_Hz = 400.0;
  double tau_s = 0.2;            ///< first-order rise of the controller
  // Overshoot bump a (s / s_o) e^(1 - s / s_o) added to the rise; a = 0.08, s_o = 0.5 s give a
  // peak overshoot of 5 % of the change about 1 s after the command, settled (< 0.2 %) by 3.5 s.
  double overshoot = 0.08;       ///< bump amplitude a, as a fraction of the change
  double overshoot_s = 0.5;      ///< bump time s_o
  double noise_kPa = 0.2;
  double fps = 30.0;
  double angle_noise_deg = 0.3;
  double angle_tau_s = 0.4;      ///< lag of the actuator behind the pressure
  std::vector<std::size_t> outlier_frames;  ///< frames that get +50 deg (tracking glitches)
};

struct StaircaseTruth {
  std::vector<double> command_s;  ///< onset of each step's rise (command_s[0] = 0: the record start)
  std::vector<double> level_kPa;
};

/// Noise-free pressure at time t (kPa).
double staircase_pressure(const StaircaseSpec& spec, double t);

/// Noise-free angle at time t (deg).
double staircase_angle(const StaircaseSpec& spec, double t);

/// One trial; `seed` makes the noise reproducible. `clean_angle` (optional) receives the angle
/// frames before the outliers were added.
TrialRecording make_staircase_trial(const StaircaseSpec& spec, int trial, unsigned seed, StaircaseTruth* truth = nullptr,
                                    Series* clean_angle = nullptr);

/// A fresh path in the temporary directory (unique per process and call), and a file writer.
std::string temp_path(const std::string& name);
void write_text(const std::string& path, const std::string& text);

}  // namespace pneufem::testing
