// Why a candidate is (or is not) the missing effect, in words (app/diagnose/detail.h): the
// residual's signature (growth over trials, creep inside holds, first trial vs later, lag after
// steps, offset at rest, proportional error) and the sentence about the feature each effect
// explains. Apart from the selection because it only describes a comparison; it decides nothing.
#include <algorithm>
#include <cmath>

#include "app/diagnose/detail.h"

namespace pneufem::diagnose_detail {

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

std::string evidence(const std::string& effect, const Signature& s) {
  const std::string growth = "the error grows from trial 1 to the last trial (rms " + fmt("%.2f", s.trial_rmse.front()) +
                             " -> " + fmt("%.2f", s.trial_rmse.back()) + " deg)";
  const std::string creep = "the measured angle keeps rising during the top holds (" + fmt("%+.2f", s.creep_top_deg) +
                            " deg more than modelled over a hold, vs " + fmt("%+.2f", s.creep_low_deg) + " at the lower steps)";
  if (effect == "fatigue") return growth + ", and " + creep;
  if (effect == "viscoelastic")
    return "inside the holds the measured angle creeps more than the model (" + fmt("%+.2f", s.creep_first_deg) +
           " deg in trial 1, " + fmt("%+.2f", s.creep_last_deg) + " deg in the last trial)";
  if (effect == "mullins")
    return "trial 1 differs from the later trials (mean residual " + fmt("%+.2f", s.first_vs_rest) +
           " deg relative to them), the signature of softening set by the first peak load";
  if (effect == "stiffness")
    return "the error scales with the angle (correlation of the step error with the angle " + fmt("%+.2f", s.proportional) +
           ") with little time structure";
  if (effect == "pressure_lag")
    return "the error concentrates right after each pressure step (mean residual " + fmt("%+.2f", s.early_deg) +
           " deg in the first 0.5 s vs " + fmt("%+.2f", s.late_deg) + " deg after the mark)";
  if (effect == "gravity")
    return "the model misses an angle at rest and low pressure (mean residual " + fmt("%+.2f", s.rest_deg) +
           " deg at 0 kPa)";
  return "its calibrated constants reshape the residual";
}

}  // namespace pneufem::diagnose_detail
