#include "analysis/model_vs_measured.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include "analysis/robust.h"
#include "core/errors.h"

namespace pneufem {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

/// Index of the last element of sorted t that is <= x, or -1.
std::ptrdiff_t last_at_or_before(const std::vector<double>& t, double x) {
  return static_cast<std::ptrdiff_t>(std::upper_bound(t.begin(), t.end(), x) - t.begin()) - 1;
}

/// Accumulates binned residual means.
struct Binner {
  double bin_s;
  std::vector<double> sum;
  std::vector<long> count;
  void add(double dt, double r) {
    if (!(dt >= 0)) return;
    const std::size_t i = static_cast<std::size_t>(dt / bin_s);
    if (i >= sum.size()) {
      sum.resize(i + 1, 0.0);
      count.resize(i + 1, 0);
    }
    sum[i] += r;
    ++count[i];
  }
  ResidualProfile profile() const {
    ResidualProfile p;
    for (std::size_t i = 0; i < sum.size(); ++i) {
      p.t_s.push_back((static_cast<double>(i) + 0.5) * bin_s);
      p.mean_deg.push_back(count[i] > 0 ? sum[i] / static_cast<double>(count[i]) : kNaN);
      p.count.push_back(count[i]);
    }
    return p;
  }
};

struct Range {
  double lo = std::numeric_limits<double>::infinity(), hi = -std::numeric_limits<double>::infinity();
  void add(double v) {
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  double span() const { return hi >= lo ? hi - lo : 0.0; }
};

}  // namespace

double ls_slope(const std::vector<double>& t, const std::vector<double>& y) {
  const std::size_t n = t.size();
  if (n < 3 || y.size() != n) return kNaN;
  double tm = 0, ym = 0;
  for (std::size_t i = 0; i < n; ++i) {
    tm += t[i];
    ym += y[i];
  }
  tm /= static_cast<double>(n);
  ym /= static_cast<double>(n);
  double stt = 0, sty = 0;
  for (std::size_t i = 0; i < n; ++i) {
    stt += (t[i] - tm) * (t[i] - tm);
    sty += (t[i] - tm) * (y[i] - ym);
  }
  return stt > 0 ? sty / stt : kNaN;
}

double angle_noise_deg(const Series& a) {
  const std::size_t n = a.value.size();
  if (n < 5) return 0.0;
  std::vector<double> d2;
  d2.reserve(n - 2);
  for (std::size_t i = 2; i < n; ++i) d2.push_back(a.value[i] - 2.0 * a.value[i - 1] + a.value[i - 2]);
  return robust::kMadToSigma * robust::mad(d2) / std::sqrt(6.0);
}

double noise_floor_nrmse(const Recording& rec, const HampelOptions& hampel) {
  double var_sum = 0.0;
  long n = 0;
  Range r;
  for (const TrialRecording& tr : rec.trials) {
    const Series clean = hampel_filter(tr.angle_deg, hampel).series;
    if (clean.value.empty()) continue;
    const double s = angle_noise_deg(clean);
    var_sum += s * s * static_cast<double>(clean.value.size());
    n += static_cast<long>(clean.value.size());
    for (double v : clean.value) r.add(v);
  }
  if (n == 0 || r.span() <= 0) return kNaN;
  return std::sqrt(var_sum / static_cast<double>(n)) / r.span();
}

Projection project_residual(const std::vector<double>& e, const std::vector<double>& s) {
  if (e.size() != s.size()) throw InputError("project_residual: residual and sensitivity differ in length");
  double se = 0, ss = 0, ee = 0;
  for (std::size_t i = 0; i < e.size(); ++i) {
    se += s[i] * e[i];
    ss += s[i] * s[i];
    ee += e[i] * e[i];
  }
  Projection p;
  if (ss <= 0 || ee <= 0) return p;
  p.delta = -se / ss;
  p.fraction = std::min(1.0, se * se / (ss * ee));
  return p;
}

namespace {
/// A recording in another convention than the model's shows as a measured angle proportional to
/// the model's with the wrong factor: -1 (the camera or the tracking counts the bend the other way;
/// pneufem's angle is positive towards the inextensible layer) or 1/57.3 (radians in a column named
/// degrees). The least-squares factor measured ~ s model over the kept frames says which; nothing
/// else makes it negative or ~0.017 when the model moves by more than a degree. A warning, not an
/// error: the comparison is still written.
void convention_hints(Comparison& c) {
  double mm = 0.0, md = 0.0, lo = INFINITY, hi = -INFINITY;
  for (const ComparedFrame& f : c.frames) {
    if (!std::isfinite(f.model_deg)) continue;
    mm += f.model_deg * f.model_deg;
    md += f.model_deg * f.measured_deg;
    lo = std::min(lo, f.model_deg);
    hi = std::max(hi, f.model_deg);
  }
  if (!(hi - lo > 1.0) || !(mm > 0.0)) return;
  const double s = md / mm, per_rad = 180.0 / 3.14159265358979323846;
  char fit[64];
  std::snprintf(fit, sizeof fit, "%.3g", s);
  if (s < -0.3)
    c.warnings.push_back(std::string("the measured angle runs opposite to the model's (least-squares fit measured = ") +
                         fit + " x model): the recording probably counts the bend the other way; pneufem's angle is "
                               "positive towards the inextensible (fabric) layer: negate angle_deg");
  else if (std::abs(s * per_rad - 1.0) < 0.3)
    c.warnings.push_back(std::string("the measured angle is ") + fit +
                         " x the model's, about 1/57.3: it is probably in radians; name the column angle_rad (it is "
                         "then converted on reading)");
}
}  // namespace

namespace {

/// The residual sums that pool over every trial's steps: the binned profiles (all trials, the
/// early half, the late half) and the mean residual before and after each step's mark.
struct PooledResiduals {
  Binner all, early, late;
  double before_sum = 0, after_sum = 0;
  long before_n = 0, after_n = 0;
  explicit PooledResiduals(double bin_s) : all{bin_s, {}, {}}, early{bin_s, {}, {}}, late{bin_s, {}, {}} {}
};

/// The frame-by-frame comparison of one trial: the model at the kept frames `mod`, the trial's
/// RSS, frame count, range, RMSE and NRMSE, the compared frames appended to `out.frames`, and the
/// warnings for frames outside the model's span and for outliers.
void compare_trial_frames(const Recording& rec, std::size_t k, const Series& meas, const std::vector<double>& mod,
                          TrialComparison& tc, Range& pooled_range, Comparison& out) {
  const TrialRecording& tr = rec.trials[k];
  Range range;
  long skipped = 0;
  for (std::size_t i = 0; i < meas.t_s.size(); ++i) {
    range.add(meas.value[i]);
    pooled_range.add(meas.value[i]);
    if (!std::isfinite(mod[i])) {
      ++skipped;
      continue;
    }
    const double r = mod[i] - meas.value[i];
    tc.rss_deg2 += r * r;
    ++tc.frames;
    out.frames.push_back({static_cast<int>(k), meas.t_s[i], meas.value[i], mod[i]});
  }
  if (skipped > 0)
    out.warnings.push_back(rec.source + ": trial " + std::to_string(tr.trial) + ": " + std::to_string(skipped) +
                           " frame(s) outside the model's time span were not compared");
  if (tc.outliers > 0)
    out.warnings.push_back(rec.source + ": trial " + std::to_string(tr.trial) + ": " + std::to_string(tc.outliers) +
                           " outlier frame(s) dropped (Hampel filter)");
  tc.range_deg = range.span();
  tc.rmse_deg = tc.frames > 0 ? std::sqrt(tc.rss_deg2 / static_cast<double>(tc.frames)) : kNaN;
  tc.nrmse = tc.range_deg > 0 ? tc.rmse_deg / tc.range_deg : kNaN;
}

/// One detected step of a trial against the model: the mark (opt.mark_s after the step's start)
/// and end values, the step's mean residual and the slopes after the mark, and whether measured
/// and model are steady there. The step's frames are [t_start, t_end) (the last step includes its
/// end); their residuals are added to `pooled`.
StepComparison compare_step(const Step& st, bool last, const Series& meas, const std::vector<double>& mod,
                            const Series& model, double noise_deg, bool is_early, const CompareOptions& opt,
                            PooledResiduals& pooled) {
  StepComparison sc;
  sc.t_start_s = st.t_start_s;
  sc.t_end_s = st.t_end_s;
  sc.level_kPa = st.level_kPa;
  const double t_mark = st.t_start_s + opt.mark_s;
  const std::ptrdiff_t i_end = last_at_or_before(meas.t_s, st.t_end_s);
  const bool has_mark = t_mark <= st.t_end_s && i_end >= 0 && meas.t_s.front() <= t_mark &&
                        meas.t_s[static_cast<std::size_t>(i_end)] >= t_mark;
  sc.measured_mark_deg = has_mark ? value_at(meas, t_mark) : kNaN;
  sc.model_mark_deg = has_mark ? value_at(model, t_mark) : kNaN;
  sc.abs_error_deg = std::abs(sc.model_mark_deg - sc.measured_mark_deg);
  if (has_mark) {
    sc.measured_end_deg = meas.value[static_cast<std::size_t>(i_end)];
    sc.model_end_deg = mod[static_cast<std::size_t>(i_end)];
  } else {
    sc.measured_end_deg = sc.model_end_deg = kNaN;
  }
  sc.spread_measured_deg = sc.measured_end_deg - sc.measured_mark_deg;
  sc.spread_model_deg = sc.model_end_deg - sc.model_mark_deg;
  std::vector<double> st_t, st_m, st_p, st_r;
  double rsum = 0;
  for (std::size_t i = 0; i < meas.t_s.size(); ++i) {
    const double t = meas.t_s[i];
    if (t < st.t_start_s || t > st.t_end_s || (t == st.t_end_s && !last) || !std::isfinite(mod[i])) continue;
    const double r = mod[i] - meas.value[i];
    rsum += r;
    ++sc.frames;
    pooled.all.add(t - st.t_start_s, r);
    (is_early ? pooled.early : pooled.late).add(t - st.t_start_s, r);
    if (t < t_mark) {
      pooled.before_sum += r;
      ++pooled.before_n;
    } else {
      pooled.after_sum += r;
      ++pooled.after_n;
      st_t.push_back(t);
      st_m.push_back(meas.value[i]);
      st_p.push_back(mod[i]);
      st_r.push_back(r);
    }
  }
  sc.mean_residual_deg = sc.frames > 0 ? rsum / static_cast<double>(sc.frames) : kNaN;
  sc.slope_measured_deg_s = ls_slope(st_t, st_m);
  sc.slope_model_deg_s = ls_slope(st_t, st_p);
  sc.slope_residual_deg_s = ls_slope(st_t, st_r);
  const double settled_s = st_t.empty() ? 0.0 : st_t.back() - st_t.front();
  const double threshold_deg = std::max(opt.steady_k * noise_deg, opt.steady_floor_deg);
  sc.steady = std::abs(sc.slope_measured_deg_s * settled_s) < threshold_deg;
  sc.steady_model = std::abs(sc.slope_model_deg_s * settled_s) < threshold_deg;
  return sc;
}

/// Trial k of the recording against its model trace: the frames (compare_trial_frames), then each
/// detected step (compare_step), the trial's NRMSE at the marks, and its row of the residual map.
void compare_trial(const Recording& rec, std::size_t k, const Series& model, const std::vector<TrialSteps>& all_steps,
                   const CompareOptions& opt, PooledResiduals& pooled, Range& pooled_range, Comparison& out) {
  const TrialRecording& tr = rec.trials[k];
  const HampelResult hr = hampel_filter(tr.angle_deg, opt.hampel);
  const Series& meas = hr.series;
  if (meas.t_s.empty())
    throw InputError(rec.source + ": trial " + std::to_string(tr.trial) +
                     " has no angle frames to compare; give its angle_deg record or leave the trial out");
  // Model at the kept frames.
  std::vector<double> mod(meas.t_s.size());
  for (std::size_t i = 0; i < meas.t_s.size(); ++i) mod[i] = value_at(model, meas.t_s[i]);
  TrialComparison tc;
  tc.trial = tr.trial;
  tc.outliers = static_cast<long>(hr.flagged.size());
  tc.noise_deg = angle_noise_deg(meas);
  compare_trial_frames(rec, k, meas, mod, tc, pooled_range, out);

  // Steps of this trial.
  const StepDetection* det = nullptr;
  for (const TrialSteps& ts : all_steps)
    if (ts.trial == tr.trial) det = &ts.detection;
  if (det) out.warnings.insert(out.warnings.end(), det->warnings.begin(), det->warnings.end());
  const bool is_early = k < rec.trials.size() / 2;  // with an odd count the middle trial counts as late
  double mark_ss = 0;
  long marks = 0;
  Range mark_range;
  std::vector<double> map_row;
  const std::vector<Step> no_steps;
  const std::vector<Step>& steps = det ? det->steps : no_steps;
  for (std::size_t si = 0; si < steps.size(); ++si) {
    StepComparison sc =
        compare_step(steps[si], si + 1 == steps.size(), meas, mod, model, tc.noise_deg, is_early, opt, pooled);
    if (std::isfinite(sc.abs_error_deg)) {
      mark_ss += sc.abs_error_deg * sc.abs_error_deg;
      ++marks;
      mark_range.add(sc.measured_mark_deg);
    }
    map_row.push_back(sc.mean_residual_deg);
    tc.steps.push_back(sc);
  }
  tc.nrmse_mark = (marks >= 2 && mark_range.span() > 0)
                      ? std::sqrt(mark_ss / static_cast<double>(marks)) / mark_range.span()
                      : kNaN;
  out.residual_map_deg.push_back(map_row);
  out.rss_deg2 += tc.rss_deg2;
  out.n += tc.frames;
  out.trials.push_back(std::move(tc));
}

}  // namespace

Comparison compare_recording(const Recording& rec, const std::vector<Series>& model, const CompareOptions& opt) {
  if (model.size() != rec.trials.size())
    throw InputError("compare: " + std::to_string(model.size()) + " model traces for " +
                     std::to_string(rec.trials.size()) + " trials of " + rec.source);
  if (!(opt.mark_s >= 0) || !(opt.bin_s > 0) || !(opt.steady_k >= 0) || !(opt.steady_floor_deg >= 0))
    throw InputError("compare: mark_s, steady_k, steady_floor_deg must be >= 0 and bin_s > 0");
  Comparison out;
  const std::vector<TrialSteps> all_steps = detect_steps(rec, opt.steps);
  PooledResiduals pooled(opt.bin_s);
  Range pooled_range;
  for (std::size_t k = 0; k < rec.trials.size(); ++k)
    compare_trial(rec, k, model[k], all_steps, opt, pooled, pooled_range, out);
  out.range_deg = pooled_range.span();
  if (out.n == 0 || out.range_deg <= 0)
    throw InputError(rec.source + ": the measured angle does not vary (range 0) or no frame could be compared; "
                     "an NRMSE needs a moving actuator");
  out.rmse_deg = std::sqrt(out.rss_deg2 / static_cast<double>(out.n));
  out.nrmse = out.rmse_deg / out.range_deg;
  out.noise_floor_nrmse = noise_floor_nrmse(rec, opt.hampel);
  out.profile = pooled.all.profile();
  out.profile_early_trials = pooled.early.profile();
  out.profile_late_trials = pooled.late.profile();
  out.residual_before_mark_deg =
      pooled.before_n > 0 ? pooled.before_sum / static_cast<double>(pooled.before_n) : kNaN;
  out.residual_after_mark_deg = pooled.after_n > 0 ? pooled.after_sum / static_cast<double>(pooled.after_n) : kNaN;
  convention_hints(out);
  return out;
}

}  // namespace pneufem
