#pragma once
// Model vs measurement, frame by frame and step by step (pure functions; no engine, no scenes).
//
// Inputs: a Recording (pressure + angle per trial, analysis/measurements.h) and, per trial in the
// same order, the model's angle as a Series (typically sampled at the measured frame times;
// otherwise it is interpolated linearly at them). Residual = model - measured (deg).
//
// Outliers: the measured angle of each trial is passed through the Hampel filter
// (analysis/hampel.h, flagged frames DROPPED, not replaced); a dropped frame is left out of every
// metric, for the model as well. The angle ranges that normalise the NRMSEs are taken over the
// kept frames, so one tracking glitch cannot inflate them.
//
// Steps come from the pressure record (analysis/steps.h): nothing about the protocol is assumed.
// Per step k of a trial (t_start, t_end = next step's start, level):
//  * mark = t_start + mark_s (the seed paper's 2.5 s mark); angles at the mark by linear
//    interpolation between the kept frames around it; NaN for every mark quantity when the step
//    is shorter than mark_s or has no frames there;
//  * end of the hold = the last kept frame at or before t_end (never interpolated across the next
//    step's rise);
//  * abs_error = |model - measured| at the mark; spread = angle(end) - angle(mark), measured and
//    model (the paper's "non-plateau" creep);
//  * settled part = [mark, end]: least-squares slopes (deg/s) of measured, model and residual;
//  * steady (measured) when |slope * (end - mark)| < max(steady_k sigma, steady_floor_deg),
//    sigma being the trial's angle noise: the drift over the hold is not visible above the noise
//    (the LS slope's own scatter over n frames, sigma sqrt(12 / n), is far below sigma for the
//    hundreds of frames of a hold, so a flagged drift is real); steady_model likewise;
//  * mean residual over the kept frames of [t_start, t_end) (the step x trial residual map).
// Per trial: nrmse_mark = RMSE over the marks / (max - min measured mark angle) (the paper's
// metric); rmse and nrmse over all kept frames (normalised by the trial's measured range).
// Pooled: rmse over all kept frames of all trials, nrmse = rmse / (max - min measured over all
// trials), rss (deg^2) and n frames (for an AIC: n ln(rss / n) + 2 k).
// Residual time structure: mean residual in bins of bin_s of the time since the step start, over
// all steps; and the same over the early trials (first half, by order) and the late ones.
#include <string>
#include <vector>

#include "analysis/hampel.h"
#include "analysis/measurements.h"
#include "analysis/steps.h"

namespace pneufem {

struct CompareOptions {
  double mark_s = 2.5;            ///< the paper's mark after each step start
  HampelOptions hampel;           ///< outlier frames of the measured angle (dropped)
  StepOptions steps;              ///< step detection in the pressure
  double steady_k = 3.0;          ///< steady-state threshold in angle-noise sigmas
  double steady_floor_deg = 0.05; ///< ... and its floor (noise-free records)
  double bin_s = 0.25;            ///< bin width of the residual vs time-in-step profile
};

struct StepComparison {
  double t_start_s = 0.0, t_end_s = 0.0, level_kPa = 0.0;
  double measured_mark_deg = 0.0, model_mark_deg = 0.0, abs_error_deg = 0.0;
  double measured_end_deg = 0.0, model_end_deg = 0.0;
  double spread_measured_deg = 0.0, spread_model_deg = 0.0;
  double slope_measured_deg_s = 0.0, slope_model_deg_s = 0.0, slope_residual_deg_s = 0.0;
  bool steady = false, steady_model = false;
  double mean_residual_deg = 0.0;  ///< over the step's kept frames (NaN without frames)
  long frames = 0;
};

struct TrialComparison {
  int trial = 0;
  std::vector<StepComparison> steps;
  double nrmse_mark = 0.0;     ///< NaN with fewer than 2 marks or a zero mark range
  double rmse_deg = 0.0, nrmse = 0.0, range_deg = 0.0, rss_deg2 = 0.0;
  long frames = 0;             ///< kept frames compared
  long outliers = 0;           ///< frames dropped by the Hampel filter
  double noise_deg = 0.0;      ///< angle tracking noise (see angle_noise_deg)
};

/// Mean residual vs time since the step start: bin i covers [i bin_s, (i + 1) bin_s).
struct ResidualProfile {
  std::vector<double> t_s;       ///< bin centres
  std::vector<double> mean_deg;  ///< NaN for empty bins
  std::vector<long> count;
};

/// One kept frame: trial index (into Recording::trials), time, both angles.
struct ComparedFrame {
  int trial_index = 0;
  double t_s = 0.0, measured_deg = 0.0, model_deg = 0.0;
};

struct Comparison {
  std::vector<TrialComparison> trials;
  double rmse_deg = 0.0, nrmse = 0.0, range_deg = 0.0, rss_deg2 = 0.0;
  long n = 0;
  double noise_floor_nrmse = 0.0;
  std::vector<std::vector<double>> residual_map_deg;  ///< [trial][step] mean residual
  ResidualProfile profile, profile_early_trials, profile_late_trials;
  double residual_before_mark_deg = 0.0, residual_after_mark_deg = 0.0;  ///< mean residual, all steps
  std::vector<ComparedFrame> frames;
  std::vector<std::string> warnings;
};

/// Compares `model_angle_deg[k]` with rec.trials[k] (see above). Throws InputError when the
/// sizes differ, a trial has no kept angle frames or the measured angle range is zero.
Comparison compare_recording(const Recording& rec, const std::vector<Series>& model_angle_deg,
                             const CompareOptions& opt = {});

/// Angle tracking noise of a series: 1.4826 MAD(second differences) / sqrt(6) (a second
/// difference of white noise has variance 6 sigma^2; differencing twice removes the smooth
/// response, the median ignores the few differences spanning a step or a glitch). Assumes
/// roughly uniform frame spacing. 0 for fewer than 5 samples.
double angle_noise_deg(const Series& angle_deg);

/// The best NRMSE a perfect model could reach: the pooled angle noise (frame-weighted RMS of the
/// per-trial noise of the Hampel-cleaned angle) / the measured range over all trials.
double noise_floor_nrmse(const Recording& rec, const HampelOptions& hampel = {});

/// Least-squares slope of y(t); NaN with fewer than 3 points or no spread in t.
double ls_slope(const std::vector<double>& t, const std::vector<double>& y);

/// Least-squares projection of a residual e onto a sensitivity vector s (e.g. d angle / d scale
/// of one region, at the compared frames): the parameter change that best cancels the residual,
/// delta = -(s.e)/(s.s), and the fraction of the residual's sum of squares it removes,
/// (s.e)^2 / ((s.s)(e.e)) in [0, 1]. Zero vectors give delta = 0, fraction = 0.
struct Projection {
  double delta = 0.0, fraction = 0.0;
};
Projection project_residual(const std::vector<double>& residual, const std::vector<double>& sensitivity);

}  // namespace pneufem
