#pragma once
// The options and the results of `pneufem diagnose` (app/diagnose/command.h runs it): plain types,
// no logic. A header of their own so that the diagnosis's internals (app/diagnose/detail.h) can
// use them without including the command, which includes them (issue 34: no loop between files).
#include <string>
#include <vector>

namespace pneufem {

struct DiagnoseOptions {
  std::string data_path;
  std::string out_dir;
  std::vector<std::string> candidates;  ///< names to try (empty = the whole catalog)
  /// Greedy forward selection depth: the rounds go on while an effect passes the tests, at most this
  /// many (each round calibrates every candidate left: its cost is that of round 1 again).
  int max_effects = 4;
  int max_evaluations = 60;             ///< reduced-model runs per candidate calibration
  double aic_threshold = -10.0;
  double min_removed = 0.25;            ///< fraction of the excess squared NRMSE a candidate must remove
  double min_gain_of_floor = 0.1;       ///< ... and NRMSE gain of at least this times the noise floor
  /// An effect without history (stiffness, gravity: a change of the static angle curve) is named only
  /// when it changes the model's angle by at least this much (RMS over the recording, in units of the
  /// NRMSE, i.e. of the measured angle range). A smaller static misfit is within what an elastic
  /// model is expected to be accurate to (a 1-3 % stiffness error, a coarse mesh, a geometry
  /// tolerance; the seed paper called a 4 % trial-1 NRMSE a match): calibrate the elastic constants
  /// on a static test instead. Not applied under trust_elastic_model.
  double min_static_change = 0.05;
  /// Skip later rounds once the residual is within min_gain_of_floor of the noise floor (no effect
  /// could then be significant without fitting below the floor); false = run every round.
  bool stop_at_noise_floor = true;
  /// From round 2 on a candidate must also explain error beyond a static misfit of the angle curve
  /// (fit_static_discrepancy); true = the elastic response is known to be right (a converged mesh of
  /// the measured geometry, a calibrated material), so a static remainder may be named as an effect.
  bool trust_elastic_model = false;
  /// After the rounds, when the residual's top holds grow over the trials significantly beyond its
  /// rests and no fatigue form is selected: the fatigue forms tried on the RSS weighed with that
  /// growth's evidence (app/diagnose/command.cpp, growth_round). false: --no-growth-round.
  bool growth_round = true;
  int rom_points = 2000;                ///< material points of the reduced model
  bool verify = false;                  ///< re-run baseline and fitted scene with the full FEM
  /// Space-mapping refinements of the selected constants (app/diagnose/fem.cpp): N refinements cost
  /// N + 1 runs of the accurate model. The path model that selects and calibrates is a 1-dof model
  /// whose damage constants can be biased up to ~2x; the refinement moves them to the accurate
  /// model's. Not on by default: with the reduced model it is only as good as that model is on the
  /// recording, and measured on tests/data/hidden it fixed Mullins's constants (full-FEM NRMSE
  /// 0.046 -> 0.011, floor 0.0095) but moved fatigue's off the FEM's valley (0.009 -> 0.046), where
  /// the controller's overshoot takes the walls near the limit and the reduced model is 0.66 deg
  /// off (docs/verification.md).
  int refine = 0;
  /// The accurate model of the refinement: the reduced-order model (engine/rom.h) of the calibration
  /// scene, driven by the same chamber-pressure map as the path model (minutes: one offline part per
  /// actuator, cached in cache_dir, then one reduced run per refinement), or the full FEM of the
  /// scene (hours on the default mesh).
  enum class RefineModel { Reduced, Full };
  RefineModel refine_model = RefineModel::Reduced;
  /// Full-FEM runs for a final local calibration of each selected effect's constants directly on the
  /// FEM (bounded derivative-free search from the reduced-model or refined constants); 0 = none.
  int fem_calibration_runs = 0;
  /// > 0: calibrate on the built-in mesher at this element size (mm) instead of the scene's mesh,
  /// with an elastic mesh correction from one static sweep of each mesh (see PathModelEvaluator in
  /// app/diagnose/evaluator.h); the FEM runs and fitted.toml keep the scene's mesh. 0 = the scene's mesh;
  /// < 0 = auto: 3x the scene's element size for a built-in mesh of more than 50k dof, else the
  /// scene's mesh (a note on stderr says which).
  double calibration_h_mm = -1.0;
  int threads = 0;
  bool progress = false;
  /// After every round's selection, the joint intervals of the selected constants (RoundIntervals):
  /// 1 + 2k + k(k - 1)/2 runs of the path model for the Hessian and 2k to 8k for the ends, for k
  /// constants in all (measured: 11 for one effect's two, 30 for two effects' four),
  /// run in parallel; false = skip them.
  bool intervals = true;
  /// Tests only: fail (throw) right after this round, as a late failure would (0 = never). The
  /// failure path then writes what was done (run_diagnosis).
  int fail_after_round = 0;
  /// Cache directory for the actuator's elastic FEM results (app/simulate/result_cache.h); "" = none.
  std::string cache_dir;
  std::string command_line;
};

/// One reduced-model evaluation of a calibration (written to calibration.csv: the landscape the
/// optimiser saw, so a user can tell a flat objective from failed evaluations).
struct CalibrationPoint {
  std::vector<double> params;
  double rss_deg2 = 0.0;  ///< +inf when the evaluation failed
  std::string error;      ///< why it failed (empty when it did not)
};

struct CandidateResult {
  std::string effect;
  int round = 1;                        ///< 1 = on the baseline, 2 = on top of the first selection, ...
  std::vector<std::string> param_names; ///< "<name>_<unit>"-free names, as in the catalog
  std::vector<double> params;
  std::vector<std::string> sets;        ///< scene overrides that add it with these values
  double nrmse = 0.0;                   ///< pooled full time-series NRMSE with the effect
  std::vector<double> nrmse_per_trial;
  double rss_deg2 = 0.0;
  double delta_aic = 0.0;               ///< vs the model of this round without it
  double removed = 0.0;                 ///< fraction of the excess squared error removed
  bool significant = false;
  int evaluations = 0;
  double wall_s = 0.0;                  ///< calibration wall time (s)
  std::vector<CalibrationPoint> trace;  ///< every evaluation, in order
  std::string why;
  std::string error;                    ///< non-empty when the calibration failed
  std::vector<std::string> at_bound;    ///< parameters calibrated at the edge of their range (params_at_bounds)
  /// Significant candidates with two or more constants: the range of each constant along the
  /// direction in which the fit worsens slowest, while its RSS stays within (1 + trade_rss_tol) of
  /// the best (app/diagnose/detail.h, trade_off). Empty when not computed.
  std::vector<double> trade_lo, trade_hi;
  double trade_rss_tol = 0.0;
  /// The same three tests after a static correction of both models (fit_static_discrepancy): what
  /// the effect explains beyond a smooth misfit of the angle curve. Rounds >= 2 require it.
  double nrmse_beyond_static = 0.0;
  double delta_aic_beyond_static = 0.0;
  double removed_beyond_static = 0.0;
  bool beyond_static = false;
  /// Effects without history: how much the calibrated effect changes the model's angle, RMS over the
  /// recording in units of the NRMSE (min_static_change); -1 for history effects.
  double static_change_nrmse = -1.0;
  /// Its constants were calibrated with the static misfit profiled out (fit_static_discrepancy):
  /// always for history effects from round 2 on; in round 1 when only that calibration passes.
  bool profiled = false;
  /// From round 2 on, for a history effect: the constants of the effects selected before it,
  /// re-fitted jointly with its own (in selection order; empty = not re-fitted). Selected, they
  /// replace the earlier values in the model and in fitted.toml.
  std::vector<double> refit_selected;
};

/// A selected constant after a round: its value and the range over which it can move, the other
/// selected constants re-adjusting, while the fit stays within RoundIntervals::rss_tol of its RSS
/// (app/diagnose/detail.h, joint_intervals: the profile of the RSS on a quadratic model, each end
/// checked on the model). `identified` is false when that range reaches both ends of the
/// constant's calibration range: the recording does not fix it.
struct ConstantInterval {
  std::string effect, name;
  double value = 0.0, lo = 0.0, hi = 0.0;
  bool identified = true;
};

/// The intervals of every constant selected up to a round, computed jointly after its selection.
struct RoundIntervals {
  int round = 0;
  double rss_tol = 0.0;      ///< the fit may worsen by this fraction of its RSS inside the intervals
  int evaluations = 0;       ///< reduced-model runs they took
  bool computed = false;     ///< false: the RSS's Hessian could not be formed (a failed run at its stencil)
  std::vector<ConstantInterval> constants;  ///< in selection order
};

/// The reduced model after a round's selection (the effects selected so far, with the constants
/// they had then): one line of history.jsonl and one column of report.md each.
struct ModelAfterRound {
  std::vector<std::string> effects;     ///< selected so far, in order
  std::vector<std::string> sets;        ///< the scene overrides that add them
  double nrmse = 0.0;                   ///< pooled
  std::vector<double> nrmse_per_trial;
  std::vector<double> rmse_deg_per_trial;
};

/// Model equivalence across rounds: a combination of effects the selection calibrated (the effects
/// selected before some round plus one candidate of that round) that fits the recording as well as
/// the final model (its RSS within EquivalentModel::rss_tol of the final one's) although it is not
/// the final model nor one of the models it was built through. The recording then does not tell the
/// two combinations apart: e.g. long-term creep alone against stiffness + instantaneous creep.
struct EquivalentModel {
  std::vector<std::string> effects;   ///< the combination, in the order it was built
  int round = 0;                      ///< the round whose candidate completed it
  int parameters = 0;                 ///< its constants in all (the final model's: DiagnosisResult::final_parameters)
  double nrmse = 0.0;                 ///< pooled, raw
  std::vector<std::string> at_bound;  ///< its last effect's constants at the edge of their range
  static constexpr double rss_tol = 0.25;  ///< the trade-off's and the per-round equivalence's tolerance
};

/// What one round of the selection cost (the rounds go on while an effect passes the tests, up to
/// DiagnoseOptions::max_effects, so each round's cost is stated): its candidates, the path-model runs
/// of their calibrations, re-fits and trade-offs plus the joint intervals after it, and its wall time.
struct RoundCost {
  int round = 0;
  int candidates = 0;
  long runs = 0;
  double wall_s = 0.0;
};

/// Where the angle grows over the trials (issue 35: creep against fatigue): the growth from trial 2 to
/// the last of the mean residual measured - model at the top holds and at rest (Signature in
/// app/diagnose/detail.h). A creep that recovers slower than the rests grows both; a permanent
/// softening grows the top and barely the rest. `trials` 0: not computed (fewer than three trials,
/// or no rest or top steps).
struct GrowthSplit {
  int trials = 0;  ///< trials after the first it is taken over
  double top_deg = 0.0, rest_deg = 0.0;
  /// The growth of top - rest (top_deg - rest_deg) and the standard errors (Signature in detail.h):
  /// `significant` when |difference| >= 3 standard errors (and >= 0.005 deg): positive, the top holds
  /// grow beyond the rests (a fatigue's signature), negative, the rests beyond the top (a creep's
  /// recovery slower than modelled).
  double difference_deg = 0.0;
  double top_se_deg = 0.0, rest_se_deg = 0.0, difference_se_deg = 0.0;
  bool significant = false;
};

struct DiagnosisResult {
  double baseline_nrmse = 0.0;
  std::vector<double> baseline_nrmse_per_trial;
  std::vector<double> baseline_rmse_deg_per_trial;
  double noise_floor_nrmse = 0.0;
  GrowthSplit baseline_growth;              ///< of the baseline's residual
  GrowthSplit final_growth;                 ///< of the final model's residual
  std::string growth_note;                  ///< what a significant final_growth says, in words ("" = not significant)
  std::vector<CandidateResult> candidates;  ///< round 1 best first, then later rounds
  std::vector<std::string> selected;
  std::string missing_effect;               ///< "" = none significant
  /// The first selected effect that depends on the load history (creep, damage, lag: the catalog's
  /// `history`), "" = none: under a large static misfit `missing_effect` can be the misfit (as
  /// stiffness) with the history effect second; this names the latter directly.
  std::string missing_history_effect;
  std::string stopped;                      ///< why the forward selection stopped early ("" = it did not)
  /// Model equivalence: per round with a selection, the other candidates that passed the same tests
  /// and fit as well (their RSS, beyond a static misfit from round 2 on, within 25 % of the chosen
  /// one's: below the reduced model's own error, so the recording cannot tell them apart), in words.
  std::vector<std::string> equivalents;
  /// Forms swapped after a round (try_other_forms): "round R: B replaced A (...)", in words. Greedy
  /// selection picks a form of an effect (one-term or broad creep; fatigue with or without
  /// saturation) against the model of its round; with the effects selected after it another form
  /// can fit better, and then takes its place.
  std::vector<std::string> form_changes;
  /// Model equivalence of the whole selection (equivalent_models): other combinations of effects that
  /// fit as well as the final model, fewest constants first; and the final model's constant count.
  std::vector<EquivalentModel> equivalent_models;
  int final_parameters = 0;
  /// The final model's constants, per selected effect in selection order (the selection's own
  /// record: after every joint re-fit and form change). selected_constants_text prints these; the
  /// candidates' rows hold the values of their round, which a later swap of forms can leave stale.
  std::vector<std::vector<double>> final_constants;
  /// Constants with honest uncertainty: after each round, the joint intervals of all constants
  /// selected so far (DiagnoseOptions::intervals), and in words every constant that a later round's
  /// joint re-fit moved outside the interval it had after the round before.
  std::vector<RoundIntervals> intervals;
  std::vector<std::string> interval_notes;
  double final_nrmse = 0.0;                 ///< reduced model with the selected effects
  std::vector<double> final_nrmse_per_trial;      ///< ... per trial (the baseline's when none is selected)
  std::vector<double> final_rmse_deg_per_trial;
  std::vector<ModelAfterRound> after_round;       ///< one per selected effect, in order; the last is the final model
  std::vector<RoundCost> round_costs;             ///< one per round run (also the last, which may select nothing)
  /// The final residual after a static correction (fit_static_discrepancy), and the share of the
  /// final error above the noise floor that it removes (in squared NRMSE; 0 when at the floor):
  /// near 1, what is left is a misfit of the elastic response, not a missing history effect.
  double final_nrmse_beyond_static = 0.0;
  double static_share = 0.0;
  std::string static_note;                  ///< what the static share says, in words ("" = nothing left)
  double verified_baseline_nrmse = -1.0;    ///< full FEM (verify), -1 when not run
  double verified_fitted_nrmse = -1.0;
  /// Why a full-FEM run of --verify / --refine failed ("" = none failed). The diagnosis itself is
  /// still written: the reduced-model result does not depend on it.
  std::string fem_error;
  std::vector<std::vector<double>> refined_params;  ///< per selected effect, after refinement
  /// The model that refined them ("" = no refinement completed a run; "reduced", "full") and the
  /// error of the refined constants by that model, pooled and per trial.
  std::string refined_model;
  double refined_nrmse = -1.0;
  std::vector<double> refined_nrmse_per_trial;
  std::string fitted_toml;
  /// Why the diagnosis failed ("" = it did not). A failed diagnosis writes what it had done (the
  /// rounds so far, the history, fitted.toml of the effects selected so far) with
  /// diagnosis.json's "status" saying that it failed and why, and then throws again.
  std::string failure;
  double wall_s = 0.0;
  /// Wall time of the elastic FEM work before the calibrations (path trace, scene-mesh sweep;
  /// near 0 when read from --cache).
  double elastic_wall_s = 0.0;
  long rom_runs = 0;
};

}  // namespace pneufem
