// Why a candidate is (or is not) the missing effect, in words (app/diagnose/detail.h): the
// residual's signature (growth over trials, creep inside holds, first trial vs later, lag after
// steps, offset at rest, proportional error) and the sentence about the feature each effect
// explains. Apart from the selection because it only describes a comparison; it decides nothing.
#include <algorithm>
#include <cmath>

#include "app/diagnose/detail.h"

namespace pneufem::diagnose_detail {

namespace {

/// A least-squares growth over the trials: slope x (n - 1) of y against its index, and the standard
/// error of that growth. The error of each point is the larger of `sigma_noise` (what the angle
/// tracking noise alone gives a point) and, with two or more degrees of freedom (four points), the
/// scatter of the points about the line: the trials' own variation (the regulator, the lag's
/// transients, a model error that changes with the trial) counts when it is larger than the noise.
struct Growth {
  double value = 0.0, se = 0.0;
};
Growth growth_over(const std::vector<double>& y, double sigma_noise) {
  Growth g;
  const std::size_t n = y.size();
  if (n < 2) return g;
  double mx = 0.5 * static_cast<double>(n - 1), my = 0.0;
  for (double v : y) my += v / static_cast<double>(n);
  double sxy = 0.0, sxx = 0.0;
  for (std::size_t i = 0; i < n; ++i) sxy += (static_cast<double>(i) - mx) * (y[i] - my), sxx += sq(static_cast<double>(i) - mx);
  const double slope = sxy / sxx;
  g.value = slope * static_cast<double>(n - 1);
  double sigma = sigma_noise;
  if (n >= 4) {
    double ss = 0.0;
    for (std::size_t i = 0; i < n; ++i) ss += sq(y[i] - my - slope * (static_cast<double>(i) - mx));
    sigma = std::max(sigma, std::sqrt(ss / static_cast<double>(n - 2)));
  }
  g.se = sigma / std::sqrt(sxx) * static_cast<double>(n - 1);
  return g;
}

/// Signature::top_growth_deg, rest_growth_deg, their difference and standard errors of `c` (see there).
constexpr double kTopHold = 0.95;  // a top hold: at the highest level (a commanded level, within 5 %)
void add_growth_split(const Comparison& c, double lvl_max, Signature& s) {
  std::vector<double> top, rest, diff;
  double var_top = 0.0, var_rest = 0.0;  // mean over the trials of the noise variance of a trial's mean
  for (std::size_t k = 1; k < c.trials.size(); ++k) {
    double t = 0.0, r = 0.0;
    long nt = 0, nr = 0;
    for (const StepComparison& st : c.trials[k].steps) {
      if (!std::isfinite(st.mean_residual_deg) || st.frames <= 0) continue;
      const double w = static_cast<double>(st.frames);
      if (st.level_kPa >= kTopHold * lvl_max) t -= st.mean_residual_deg * w, nt += st.frames;
      if (std::abs(st.level_kPa) < 0.05 * lvl_max) r -= st.mean_residual_deg * w, nr += st.frames;
    }
    if (nt == 0 || nr == 0) continue;
    top.push_back(t / static_cast<double>(nt));
    rest.push_back(r / static_cast<double>(nr));
    diff.push_back(top.back() - rest.back());
    const double noise = c.trials[k].noise_deg;
    var_top += sq(noise) / static_cast<double>(nt);
    var_rest += sq(noise) / static_cast<double>(nr);
  }
  if (top.size() < 2 || c.trials.size() < 3) return;
  var_top /= static_cast<double>(top.size()), var_rest /= static_cast<double>(top.size());
  const Growth gt = growth_over(top, std::sqrt(var_top)), gr = growth_over(rest, std::sqrt(var_rest)),
               gd = growth_over(diff, std::sqrt(var_top + var_rest));
  s.top_growth_deg = gt.value, s.top_growth_se_deg = gt.se;
  s.rest_growth_deg = gr.value, s.rest_growth_se_deg = gr.se;
  s.split_growth_deg = gd.value, s.split_growth_se_deg = gd.se;
  s.growth_trials = static_cast<int>(top.size());
}

}  // namespace

Signature signature_of(const Comparison& c) {
  Signature s;
  double top = 0.0, low = 0.0;
  int ntop = 0, nlow = 0;
  std::vector<double> mean_res;
  double lvl_max = 0.0;
  for (const TrialComparison& t : c.trials)
    for (const StepComparison& st : t.steps) lvl_max = std::max(lvl_max, st.level_kPa);
  std::vector<double> xs, ys;
  double rest = 0.0;
  int nrest = 0;
  for (std::size_t k = 0; k < c.trials.size(); ++k) {
    const TrialComparison& t = c.trials[k];
    s.trial_rmse.push_back(t.rmse_deg);
    s.noise_deg += t.noise_deg / static_cast<double>(c.trials.size());
    double cr = 0.0, mr = 0.0;
    int ncr = 0, nmr = 0;
    for (const StepComparison& st : t.steps) {
      const double d = st.spread_measured_deg - st.spread_model_deg;
      if (std::isfinite(d)) {
        (st.level_kPa >= 2.0 / 3.0 * lvl_max ? top : low) += d;
        ++(st.level_kPa >= 2.0 / 3.0 * lvl_max ? ntop : nlow);
        cr += d, ++ncr;
      }
      if (std::isfinite(st.mean_residual_deg)) mr += st.mean_residual_deg * st.frames, nmr += static_cast<int>(st.frames);
      if (std::isfinite(st.measured_mark_deg) && std::isfinite(st.model_mark_deg)) {
        xs.push_back(st.measured_mark_deg);
        ys.push_back(st.model_mark_deg - st.measured_mark_deg);
      }
      if (std::abs(st.level_kPa) < 0.05 * lvl_max && std::isfinite(st.mean_residual_deg)) rest += st.mean_residual_deg, ++nrest;
    }
    if (k == 0) s.creep_first_deg = ncr ? cr / ncr : 0.0;
    if (k + 1 == c.trials.size()) s.creep_last_deg = ncr ? cr / ncr : 0.0;
    mean_res.push_back(nmr ? mr / nmr : 0.0);
  }
  s.creep_top_deg = ntop ? top / ntop : 0.0;
  s.creep_low_deg = nlow ? low / nlow : 0.0;
  if (!s.trial_rmse.empty() && s.trial_rmse.front() > 0) s.growth = s.trial_rmse.back() / s.trial_rmse.front();
  if (mean_res.size() > 1) {
    double others = 0.0;
    for (std::size_t k = 1; k < mean_res.size(); ++k) others += mean_res[k];
    s.first_vs_rest = mean_res[0] - others / static_cast<double>(mean_res.size() - 1);
  }
  double e = 0.0, l = 0.0;
  long ne = 0, nl = 0;
  for (std::size_t i = 0; i < c.profile.t_s.size(); ++i) {
    if (!std::isfinite(c.profile.mean_deg[i])) continue;
    if (c.profile.t_s[i] < 0.5) e += c.profile.mean_deg[i] * c.profile.count[i], ne += c.profile.count[i];
    if (c.profile.t_s[i] > 2.5) l += c.profile.mean_deg[i] * c.profile.count[i], nl += c.profile.count[i];
  }
  s.early_deg = ne ? e / ne : 0.0;
  s.late_deg = nl ? l / nl : 0.0;
  s.rest_deg = nrest ? rest / nrest : 0.0;
  if (lvl_max > 0.0) add_growth_split(c, lvl_max, s);
  if (xs.size() > 2) {
    double mx = 0, my = 0;
    for (std::size_t i = 0; i < xs.size(); ++i) mx += xs[i], my += ys[i];
    mx /= xs.size(), my /= ys.size();
    double sxy = 0, sxx = 0, syy = 0;
    for (std::size_t i = 0; i < xs.size(); ++i)
      sxy += (xs[i] - mx) * (ys[i] - my), sxx += sq(xs[i] - mx), syy += sq(ys[i] - my);
    s.proportional = sxx > 0 && syy > 0 ? sxy / std::sqrt(sxx * syy) : 0.0;
  }
  return s;
}

namespace {

/// Which way a quoted difference goes. A difference within `flat_within` is no trend.
enum class Trend { up, down, flat };
Trend trend_of(double difference, double flat_within) {
  if (difference > flat_within) return Trend::up;
  if (difference < -flat_within) return Trend::down;
  return Trend::flat;
}

/// The largest difference (deg) called flat: the angle tracking noise per frame — a difference a
/// reader could not see on a plot of the angle — and at least half the last digit the sentences
/// print (%.2f), so a difference printed as +0.00 is never called a trend.
double flat_deg(const Signature& s) { return std::max(s.noise_deg, 0.005); }

/// "(angle noise 0.05 deg)", the number a "flat" is judged by.
std::string noise_text(const Signature& s) { return "angle noise " + fmt("%.2f", s.noise_deg) + " deg"; }

/// Growth of the error over the trials (rms of trial 1 and of the last trial).
std::string growth_sentence(const Signature& s) {
  if (s.trial_rmse.empty()) return "no trial to compare";
  const double first = s.trial_rmse.front(), last = s.trial_rmse.back();
  if (s.trial_rmse.size() < 2) return "one trial: no growth over the trials to see (rms " + fmt("%.2f", first) + " deg)";
  const std::string nums = "rms " + fmt("%.2f", first) + " -> " + fmt("%.2f", last) + " deg";
  switch (trend_of(last - first, flat_deg(s))) {
    case Trend::up: return "the error grows from trial 1 to the last trial (" + nums + ")";
    case Trend::down: return "the error falls from trial 1 to the last trial (" + nums + ")";
    case Trend::flat: break;
  }
  return "the error stays flat from trial 1 to the last trial, within the angle noise (" + nums + ", " + noise_text(s) + ")";
}

/// Creep in the top holds: measured minus modelled rise of the angle over a hold.
std::string top_creep_sentence(const Signature& s) {
  const std::string nums = fmt("%+.2f", s.creep_top_deg) + " deg over a hold against the model, vs " +
                           fmt("%+.2f", s.creep_low_deg) + " at the lower steps";
  switch (trend_of(s.creep_top_deg, flat_deg(s))) {
    case Trend::up: return "during the top holds the measured angle keeps rising beyond the model (" + nums + ")";
    case Trend::down: return "during the top holds the measured angle rises less than the model (" + nums + ")";
    case Trend::flat: break;
  }
  return "during the top holds the measured angle rises as the model does, within the angle noise (" + nums + ", " +
         noise_text(s) + ")";
}

/// "more than" / "less than" / "as much as" (within the angle noise, which the sentence then
/// quotes) the model, for a measured-minus-model creep.
std::string creep_comparison(double measured_minus_model, const Signature& s) {
  switch (trend_of(measured_minus_model, flat_deg(s))) {
    case Trend::up: return "more than";
    case Trend::down: return "less than";
    case Trend::flat: break;
  }
  return "as much as";
}

/// Creep inside the holds of trial 1 and of the last trial, measured minus modelled.
std::string hold_creep_sentence(const Signature& s) {
  const std::string first = creep_comparison(s.creep_first_deg, s), last = creep_comparison(s.creep_last_deg, s);
  const std::string a = fmt("%+.2f", s.creep_first_deg) + " deg", b = fmt("%+.2f", s.creep_last_deg) + " deg";
  if (s.trial_rmse.size() < 2)
    return "inside the holds the measured angle creeps " + first + " the model (" + a + " over a hold" +
           (first.starts_with("as much") ? ", " + noise_text(s) : "") + ")";
  if (first == last)
    return "inside the holds the measured angle creeps " + first + " the model (" + a + " over a hold in trial 1, " + b +
           " in the last trial" + (first.starts_with("as much") ? ", " + noise_text(s) : "") + ")";
  return "inside the holds the measured angle creeps " + first + " the model in trial 1 (" + a + " over a hold) and " + last +
         " it in the last trial (" + b + "; " + noise_text(s) + ")";
}

/// Trial 1 against the later trials (mean residual model - measured).
std::string first_trial_sentence(const Signature& s) {
  if (s.trial_rmse.size() < 2) return "one trial: no later trial to compare trial 1 with";
  const std::string nums = "mean residual (model - measured) of trial 1 " + fmt("%+.2f", s.first_vs_rest) + " deg relative to them";
  switch (trend_of(s.first_vs_rest, flat_deg(s))) {
    case Trend::up:
      return "the later trials bend further than modelled, relative to trial 1 (" + nums +
             "), the signature of softening set by the first peak load";
    case Trend::down:
      return "trial 1 bends further than modelled, relative to the later trials (" + nums +
             "), the opposite of softening set by the first peak load";
    case Trend::flat: break;
  }
  return "trial 1 and the later trials have the same mean residual within the angle noise (" + nums + ", " + noise_text(s) +
         "): no sign of softening set by the first peak load";
}

/// Correlation of the error at the marks with the measured angle there.
std::string proportional_sentence(const Signature& s) {
  // |r| >= 0.5: the angle accounts for at least a quarter of the error's variance across the marks.
  constexpr double kStrongCorrelation = 0.5;
  const std::string nums = "correlation of the error at the marks (model - measured) with the angle " + fmt("%+.2f", s.proportional);
  if (s.proportional >= kStrongCorrelation) return "the error rises with the angle (" + nums + ")";
  if (s.proportional <= -kStrongCorrelation) return "the error falls with the angle (" + nums + ")";
  return "the error barely follows the angle (" + nums + ", below 0.5 in size)";
}

/// Error right after the pressure steps against the error after the mark.
std::string step_lag_sentence(const Signature& s) {
  const std::string nums = "mean residual " + fmt("%+.2f", s.early_deg) + " deg in the first 0.5 s vs " + fmt("%+.2f", s.late_deg) +
                           " deg after the mark";
  switch (trend_of(std::abs(s.early_deg) - std::abs(s.late_deg), flat_deg(s))) {
    case Trend::up: return "the error concentrates right after each pressure step (" + nums + ")";
    case Trend::down: return "the error is smaller right after the pressure steps than after the mark (" + nums + ")";
    case Trend::flat: break;
  }
  return "the error is no larger right after the pressure steps than after the mark, within the angle noise (" + nums + ", " +
         noise_text(s) + ")";
}

/// Offset of the model at rest (steps at zero pressure).
std::string rest_sentence(const Signature& s) {
  const std::string nums = "mean residual " + fmt("%+.2f", s.rest_deg) + " deg at 0 kPa";
  switch (trend_of(s.rest_deg, flat_deg(s))) {
    case Trend::up: return "at rest the model's angle lies above the measured one (" + nums + ")";
    case Trend::down: return "at rest the model's angle lies below the measured one (" + nums + ")";
    case Trend::flat: break;
  }
  return "at rest the model matches the measured angle within the angle noise (" + nums + ", " + noise_text(s) + ")";
}

}  // namespace

bool growth_significant(double growth_deg, double se_deg) {
  return std::abs(growth_deg) >= kGrowthSigmas * se_deg && std::abs(growth_deg) >= 0.005;
}

GrowthSplit growth_split_of(const Signature& s) {
  GrowthSplit g;
  g.trials = s.growth_trials;
  g.top_deg = s.top_growth_deg, g.rest_deg = s.rest_growth_deg, g.difference_deg = s.split_growth_deg;
  g.top_se_deg = s.top_growth_se_deg, g.rest_se_deg = s.rest_growth_se_deg, g.difference_se_deg = s.split_growth_se_deg;
  g.significant = s.growth_trials >= 2 && growth_significant(s.split_growth_deg, s.split_growth_se_deg);
  return g;
}

std::string growth_split_text(const Signature& s) {
  if (s.growth_trials < 2) return "";
  const double d = s.split_growth_deg, se = s.split_growth_se_deg;
  std::string verdict;
  if (!growth_significant(d, se))
    verdict = "not significant: the top holds and the rests grow alike";
  else if (d > 0.0)
    verdict = "significant: the top holds grow more than the rests, a permanent softening's (fatigue's) signature";
  else
    verdict = "significant: the rests grow more than the top holds, a slower recovery than modelled (creep)";
  const std::string sigmas = se > 0.0 ? fmt("%.1f", std::abs(d) / se) + " standard errors, " : std::string();
  return "over the " + std::to_string(s.growth_trials) + " trials after the first the residual (measured - model) grows by " +
         fmt("%+.2f", s.top_growth_deg) + " deg at the top holds and " + fmt("%+.2f", s.rest_growth_deg) +
         " deg at rest (top minus rest " + fmt("%+.2f", d) + " +- " + fmt("%.2f", se) + " deg: " + sigmas + verdict + ")";
}

std::string evidence(const std::string& effect, const Signature& s) {
  const std::string split = growth_split_text(s);
  if (effect == "fatigue" || effect == "fatigue_saturating" || effect == "fatigue_uniform")
    return growth_sentence(s) + ", and " + top_creep_sentence(s) + (split.empty() ? "" : "; " + split);
  if (effect == "viscoelastic" || effect == "viscoelastic_instantaneous" || effect == "viscoelastic_broad")
    return hold_creep_sentence(s) + (split.empty() ? "" : "; " + split);
  if (effect == "mullins") return first_trial_sentence(s);
  if (effect == "stiffness") return proportional_sentence(s);
  if (effect == "pressure_lag") return step_lag_sentence(s);
  if (effect == "gravity") return rest_sentence(s);
  return "its calibrated constants reshape the residual";
}

}  // namespace pneufem::diagnose_detail
