#pragma once
// Pressure steps found in a measured pressure record, without assuming the protocol: levels,
// hold times, the number of steps and the sampling rate all come from the data; steps may go up
// or down, and the initial rest (0 kPa) is a step like any other.
//
// Definitions (per trial):
//  * a step is a plateau of the pressure plus the transition that leads into it;
//  * t_start_s: the time the pressure departs from the previous level towards the new one (the
//    controller's command time); the first step starts at the first sample; not snapped to a
//    sample (a continuous estimate, see below);
//  * t_end_s: the next step's t_start_s; for the last step the last sample, or the departure of
//    a final change that reaches no plateau (e.g. the record stops while venting);
//  * level_kPa: the median pressure over the second half of the step's plateau (settled: the
//    controller's overshoot has decayed; the median ignores noise and spikes).
//
// Method (thresholds derived from the data, time constants in StepOptions):
//  1. noise: sigma = 1.4826 MAD(first differences) / sqrt(2) (robust: steps are a few samples
//     among thousands), reported only;
//  2. M = running median over w = window_s (odd number of samples, >= 5): removes spikes and
//     keeps edges sharp (a median, unlike a mean, does not smear a step);
//  3. change statistic D(i) = median(p over the w samples after i) - median(over the w before);
//     on a plateau D is noise, at a step it reaches the step size. Threshold
//        T = max(k_noise * 1.4826 * MAD(D), min_change_fraction * (max M - min M))
//     i.e. k_noise robust standard deviations of D itself (this follows correlated sensor noise
//     that first differences miss; at k = 6 a false trigger on a 10^5-sample plateau is
//     essentially impossible for Gaussian noise, and the mild overshoot decay, a few % of a step
//     over ~1 s, changes D by far less), with a floor relative to the pressure span for
//     (near-)noise-free records, where MAD(D) = 0 would make every wiggle a step;
//  4. plateaus are the runs with |D| <= T; runs shorter than min_hold_s are transients
//     (overshoot ringing, a valve glitch) and are absorbed; neighbouring plateaus whose levels
//     differ by less than T are merged (the excursion between them was a disturbance);
//  5. departure: between plateaus A and B the record p is fitted, by least squares, with a hinge
//        p = L_A                                   for t <= t0,
//        p = L_A + A (1 - exp(-(t - t0) / tau))    for t >  t0,
//     over the transition up to fit_fraction of the level change (before any overshoot), t0 and
//     tau free (A by linear least squares). The family contains the linear ramp (tau -> inf,
//     choked inflow) and the first-order rise; extrapolating the fitted rise back to the old
//     level finds the departure without waiting for the signal to leave the noise band (a
//     3-sigma threshold crossing would lag by 3 sigma / slope, ~25 ms for 0.2 kPa noise on a
//     5 kPa step with tau = 0.2 s). Its statistical precision is close to the Cramer-Rao bound
//     (~1.8 ms 1-sigma for that example at 400 Hz); a rise that starts with zero slope (strongly
//     second-order) is placed slightly late.
// Transitions slower than about T per window (e.g. a ramp of 5 kPa over several seconds) are not
// recognised as steps; such a plateau whose smoothed pressure spans more than 3 T produces a
// warning.
#include <string>
#include <vector>

#include "analysis/measurements.h"

namespace pneufem {

struct Step {
  double t_start_s = 0.0;
  double t_end_s = 0.0;
  double level_kPa = 0.0;
};

struct StepOptions {
  double window_s = 0.1;               ///< running-median window w (each side of the statistic D)
  double k_noise = 6.0;                ///< threshold T in robust standard deviations of D
  double min_change_fraction = 0.02;   ///< floor of T as a fraction of the smoothed pressure span
  double min_hold_s = 0.5;             ///< plateaus shorter than this are transients
  double fit_fraction = 0.9;           ///< departure fit uses the rise up to this fraction of the change
};

struct StepDetection {
  std::vector<Step> steps;
  double rate_Hz = 0.0;        ///< median sampling rate of the record
  double noise_kPa = 0.0;      ///< white-noise standard deviation estimate
  double threshold_kPa = 0.0;  ///< T
  std::vector<std::string> warnings;
};

struct TrialSteps {
  int trial = 0;
  StepDetection detection;
};

/// Steps of one pressure record (see above). Throws InputError when the series is malformed
/// (sizes differ, times not increasing, values not finite) or the options are invalid.
StepDetection detect_steps(const Series& pressure_kPa, const StepOptions& opt = {});

/// Steps of every trial that has pressure samples (trials without are skipped with a warning in
/// the returned detection). Warnings are prefixed with "<source>: trial N: ".
std::vector<TrialSteps> detect_steps(const Recording& rec, const StepOptions& opt = {});

/// Linear interpolation of s at t; NaN outside [t_s.front(), t_s.back()] or for an empty series.
double value_at(const Series& s, double t_s);

/// Median of the samples with t0_s <= t <= t1_s (mean of the middle two for an even count);
/// NaN when there are none.
double median_in(const Series& s, double t0_s, double t1_s);

}  // namespace pneufem
