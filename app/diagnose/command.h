#pragma once
// `pneufem diagnose`: which physical effect is the model missing?
//
// 1. The recording (analysis/measurements.h) is compared with the scene's model (the baseline):
//    residual = model - measured at every kept frame (outlier frames dropped, analysis/model_vs_measured.h).
// 2. Every candidate effect of the catalog (app/diagnose/effect_catalog.h: stiffness, viscoelastic,
//    viscoelastic_instantaneous, viscoelastic_broad, mullins, fatigue, fatigue_saturating, pressure_lag, gravity and any
//    registered material effect) is added to the scene and its few bounded parameters are
//    calibrated (NLopt BOBYQA in [0, 1]-scaled, log where
//    the catalog says so, after a coarse start grid) to minimise the residual sum of squares.
// 3. Candidates are ranked by the error they leave. An information criterion makes extra
//    parameters earn their place: AIC = n_eff ln(RSS / n_eff) + 2 k, where n_eff is the number of
//    frames corrected for the residual's autocorrelation (AR(1): n (1 - rho) / (1 + rho)): 30 fps
//    frames of a smooth model error are not independent, and counting them as such would make
//    any parameter "significant". A candidate is significant when delta AIC <= aic_threshold
//    (-10: "essentially no support" for the worse model, Burnham & Anderson) AND it removes at
//    least min_removed of the baseline's error above the noise floor (in squared NRMSE), so a
//    statistically detectable but physically negligible gain is not reported as a missing effect;
//    and its NRMSE gain must be at least min_gain_of_floor x the noise floor (near the floor the
//    excess is tiny and fitting noise can remove much of it).
// 4. Greedy forward selection: the best significant candidate is added (with its calibrated
//    constants) and the remaining candidates are tried again on top of it, up to max_effects,
//    unless the residual is already at the noise floor (within min_gain_of_floor: the third test
//    of 3. could then only pass by fitting noise; the discrepancy principle of inverse problems).
//    From round 2 on the tests are applied beyond a static misfit (fit_static_discrepancy below;
//    history effects calibrated with it profiled out) and a constant at the edge of its range
//    disqualifies: what the first effect leaves of a recording made by other means is mostly a
//    misfit of the elastic response, and effects fitted to it are stand-ins. Such a history effect
//    is then re-fitted jointly with the earlier effects' constants (local search, raw error). In round 1 a history
//    effect that fails the raw tests is calibrated again that way and may pass beyond the misfit.
//    --trust-elastic-model restores the raw tests in later rounds.
// 5. Every candidate gets a plain-words reason built from the residual's signature (growth over
//    trials, creep inside holds, first-trial vs later, lag after steps, offset at rest,
//    proportional error) and the error it removes; a significant one with two or more constants
//    also the range over which they trade off (trade_lo/trade_hi: the fit within 25 % of its RSS
//    along its flattest direction), since a rate law's two constants are often fixed by the data
//    only in combination.
//
// Calibration runs the reduced path model (engine/path_model.h: 1-dof Ritz model on the elastic
// FEM path of the same mesh, using the scene's own material code), hundreds of times faster than
// the FEM; `verify` re-runs the baseline and the fitted scene through the full FEM
// (app/simulate/drive.h) and reports those NRMSEs too.
//
// Outputs in out_dir: diagnosis.json (schema in the README), fitted.toml (the scene plus the
// selected effects; `pneufem compare fitted.toml --data FILE` shows the drop), diagnosis.csv
// (one row per candidate and round), calibration.csv (every reduced-model evaluation of every
// calibration: parameters, RSS or the error that made it fail), one line in history.jsonl per
// model variant (the baseline and the model after each round, with the NRMSE and RMSE per trial)
// and report.md (the diagnosis for a person: recording, scene, the error per trial before and
// after, every round's candidates, tests and choice, and the evidence in words).
#include <string>
#include <vector>

#include "analysis/measurements.h"
#include "analysis/model_vs_measured.h"
#include "app/diagnose/effect_catalog.h"
#include "app/diagnose/options_and_results.h"
#include "scenes/scene.h"

namespace pneufem {

/// True when one of the candidate's trade-off ranges spans more than a factor of 2: the recording
/// then fixes a combination of its constants more than each one (`why` and the console say so).
bool constants_trade_off(const CandidateResult& c);

/// The constants of the selected effects as the console prints them, one line per effect: the
/// final values (re-fitted jointly by a later round, or refined with the FEM, when that happened)
/// and, for values straight from their own calibration, the trade-off ranges. "" = none selected.
std::string selected_constants_text(const DiagnosisResult& r);

/// The constants of `before` (the intervals after a round) that `now` (after a later round, whose
/// joint re-fit may have moved the earlier effects' constants) puts outside their interval: one
/// sentence each, for DiagnosisResult::interval_notes. None when `before` was not computed.
std::vector<std::string> moved_outside_intervals(const RoundIntervals& before, const RoundIntervals& now);

/// The combinations of effects among those the selection calibrated (every candidate of every round
/// on top of the effects selected before that round) that passed the tests of their round and fit
/// within EquivalentModel::rss_tol of the final model's RSS (its pooled NRMSE squared, on the same
/// frames), other than the final model and the models it was built through (each of those was
/// tested against the next by the selection). Fewest constants first, then best fit. None when
/// nothing was selected. A simpler combination in the list means that the recording does not ask
/// for the final model's extra constants; one of the same size, that it does not tell which effect.
std::vector<EquivalentModel> equivalent_models(const DiagnosisResult& r);

/// One equivalent model in words (console, report.md).
std::string equivalent_model_text(const EquivalentModel& m, const DiagnosisResult& r);

/// The calibration mesh size diagnose uses for `requested_mm` (DiagnoseOptions::calibration_h_mm):
/// itself when >= 0; for < 0 (auto) 3x the scene's element size when its built-in mesh has more
/// than 50k dof, else 0 (the scene's mesh; for a large deck with a note suggesting a coarser one).
/// What was chosen and why goes to `notes`.
double resolve_calibration_h(const Scene& scene, double requested_mm, std::vector<std::string>& notes);

/// Runs the diagnosis of `scene` against the recording in options.data_path and writes the
/// outputs. Throws InputError for bad data/options, PhysicsError when the baseline cannot be run.
DiagnosisResult run_diagnosis(const Scene& scene, const DiagnoseOptions& options);

/// Names of the parameters of `c` whose calibrated `values` lie within 1 % of the calibrated range
/// (in the calibration coordinate, log or linear) of either bound. A constant pushed to the edge of
/// its physical range is the mark of an effect standing in for a misfit of another kind (measured:
/// a recording made on a finer mesh than the model's, diagnosed on the coarse one, selects Mullins
/// with r = 1.1, its lower bound, in round 2). The rig angle is exempt: 0 and 180 deg are real rigs;
/// so is a lower bound where the effect reduces to a simpler one (CandidateParameter::reduces_at_lo:
/// pressure_lag's tau2 = 0 is the first-order lag).
std::vector<std::string> params_at_bounds(const CandidateEffect& c, const std::vector<double>& values);

/// A static model-form discrepancy (the delta(x) of Kennedy & O'Hagan 2001, here a cubic in the
/// model's own angle) fitted to the residual model - measured of `frames` by least squares:
/// delta = a0 + a1 x + a2 x^2 + a3 x^3, x = model angle / its largest magnitude, one function for
/// every trial and time. A misfit of the elastic response (the mesh, the geometry, the hyperelastic
/// law, the stiffness, the weight) moves the angle as a smooth function of the state, and the state
/// of a staircase is, to first order, the model angle; history effects (creep within a hold,
/// softening after the first trial, growth over trials, lag after a step) do not: at one model
/// angle they differ between holds, trials or times. An effect selected after another must explain
/// error that this fit cannot (app/diagnose/command.cpp), else it is a stand-in for a static misfit.
struct StaticFit {
  double rss_deg2 = 0.0;                   ///< residual sum of squares after the fit (deg^2)
  std::vector<double> residual_deg;        ///< model - measured - delta, per frame
  std::vector<double> coefficients_deg;    ///< a0 ... a3
};
StaticFit fit_static_discrepancy(const std::vector<ComparedFrame>& frames);

/// AR(1) effective sample size of a residual sequence (segments = trials): n (1 - rho)/(1 + rho),
/// rho the lag-1 autocorrelation within segments, clamped to [min(n, 10), n].
double effective_sample_size(const std::vector<double>& residual, const std::vector<int>& segment);

}  // namespace pneufem
