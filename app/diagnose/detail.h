#pragma once
// What the files of `pneufem diagnose` (app/diagnose/command.h) share; internal to them:
//   command.cpp             run_diagnosis: the baseline, the rounds of forward selection and their
//                           significance tests, then the FEM stages and the outputs below;
//   evaluator.h/.cpp        PathModelEvaluator, the reduced-model replay of the recording;
//   calibrate.cpp           parameter scaling, interpolation nodes and the calibration of a
//                           candidate's constants (grid, then golden section or BOBYQA);
//   evidence.cpp            the residual's signature and the plain-words reason per candidate;
//   fem.cpp                 the full-FEM stages: space-mapping refinement (--refine), FEM
//                           calibration (--fem-calibrate) and verification (--verify);
//   output.cpp              diagnosis.json, fitted.toml, diagnosis.csv, calibration.csv, history;
//   report.cpp              report.md, the diagnosis for a person.
// Beside them: effect_catalog (the candidates; `pneufem synth` hides the same ones),
// elastic_curve (static angle curves and the interpolation nodes of the catalog's constants) and
// cli (the command line).
#include <cstdio>
#include <functional>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "analysis/measurements.h"
#include "analysis/model_vs_measured.h"
#include "app/diagnose/effect_catalog.h"
#include "app/diagnose/options_and_results.h"
#include "scenes/scene.h"

namespace pneufem::diagnose_detail {

class PathModelEvaluator;

/// The selected effects with their calibrated constants, in the order they were selected.
using ChosenEffects = std::vector<std::pair<const CandidateEffect*, std::vector<double>>>;

inline double sq(double v) { return v * v; }

inline std::string fmt(const char* f, double a) {
  char b[96];
  std::snprintf(b, sizeof b, f, a);
  return b;
}

// ---- calibration (calibrate.cpp)

double rss_of(const std::vector<double>& model, const std::vector<ComparedFrame>& frames);

std::vector<double> initial_values(const CandidateEffect& c);

/// Value of a catalog parameter at the scaled coordinate x in [0, 1].
double unscale(const CandidateParameter& p, double x);
double scale(const CandidateParameter& p, double v);

/// Parameter values of the interpolation nodes (app/diagnose/elastic_curve.h): the rig angle's five angles
/// (deg), or Chebyshev-Lobatto nodes of the calibration coordinate (log or linear over the bounds).
std::vector<double> interpolation_nodes(ParameterInterpolation how, const CandidateParameter& p);

struct Calibration {
  std::vector<double> values;
  double rss = std::numeric_limits<double>::infinity();
  int evaluations = 0;
  std::string error;
  std::vector<CalibrationPoint> trace;
};

/// Minimises rss(values) over the candidate's box: a coarse grid (5 points per parameter for
/// one parameter, 3 per parameter above), then golden-section search (one parameter) or BOBYQA
/// (several) from the best grid point, until the trust region is 1e-4 of the calibration scale,
/// a step gains less than 1e-4 in log RSS (for BOBYQA confirmed by a restart from the best point,
/// which gains no more either), or `budget` runs are spent. Two constants that trade
/// off leave a narrow valley that BOBYQA walks down in small steps: the default budget (60,
/// DiagnoseOptions) is sized for that walk (Calibrate.WalksDownALogSpaceValleyWithinTheDefaultBudget).
/// The optimiser sees log(rss), which has the same minimiser: near a limit point the RSS of
/// neighbouring constants spans six decades (a softened model that snaps through is off by tens
/// of degrees), and BOBYQA's quadratic models of the raw RSS are then dominated by those points.
/// A failed evaluation (no equilibrium) is recorded as +infinity but scores as one decade worse
/// than the worst finite RSS seen, so it repels the search without breaking the model.
Calibration calibrate(const CandidateEffect& c, const std::function<double(const std::vector<double>&)>& rss,
                      int budget, const std::vector<double>* start = nullptr);

/// How far a calibration's constants can move together without worsening the fit much: the
/// range of each constant along the direction in which the RSS rises slowest (the smallest
/// curvature of a finite-difference Hessian in the calibration scale), walked both ways from the
/// best point while the RSS stays within (1 + rss_tol) of the best. Two constants of a rate law
/// often trade off (a lower fatigue threshold with a slower rate; a larger Prony gamma with a
/// shorter tau): the recording then fixes a combination, not each constant, and the calibrated
/// point is wherever along that valley the model's own error puts it.
struct TradeOff {
  std::vector<double> lo, hi;  ///< per parameter (catalog units); empty when not computed
  double rss_tol = 0.0;
  int evaluations = 0;
};

/// The trade-off of `values` (the calibrated point, RSS `rss_best`) for a candidate with two or
/// more parameters (empty for one). Walk resolution: steps double from 0.05 in the calibration
/// scale, then two bisections, so each end is found to within a quarter of its last step.
TradeOff trade_off(const CandidateEffect& c, const std::function<double(const std::vector<double>&)>& rss,
                   const std::vector<double>& values, double rss_best, double rss_tol);

/// Joint intervals of several constants (the selected effects' together): for each constant, the
/// range over which it can move, the others re-adjusting, while the RSS stays within
/// (1 + rss_tol) of the best. The profile of the RSS (Venzon & Moolgavkar 1988, the profile-
/// likelihood interval of a least-squares fit) is taken on a quadratic model: H the finite-
/// difference Hessian in the calibration scale (as trade_off's), the half-width of constant i is
/// d_i = sqrt(2 dRSS (H^-1)_ii), and along the profile path x0 + t H^-1 e_i / (H^-1)_ii the
/// other constants follow. Each end is then checked on the real RSS and, where the rise there is
/// not within [0.5, 2] dRSS (a valley flatter or steeper than its curvature at the best point),
/// moved by up to three secant steps in log-log. Directions of curvature below what moving across two calibration ranges would
/// cost (2 dRSS / 4; also negative ones: the best point is then not a minimum along them) count as
/// flat: the constants that lean on them reach both ends of their range, and such a constant is
/// not identified by the data. `rss_batch` evaluates many points (catalog units), so the caller
/// can run them in parallel; a failed evaluation is +infinity.
struct JointInterval {
  double lo = 0.0, hi = 0.0;   ///< catalog units, inside the calibration range
  bool identified = true;      ///< false: the interval reaches both ends of the range
  /// (RSS at the end - best) / dRSS after the check, per side (1 = exactly on the contour; NaN
  /// where the end is a bound of the range that the contour lies beyond).
  double rise_lo = 0.0, rise_hi = 0.0;
};
struct JointIntervals {
  std::vector<JointInterval> c;  ///< per constant; empty when the Hessian could not be formed
  double rss_best = 0.0;         ///< the RSS at the centre evaluation
  double rss_tol = 0.0;
  int evaluations = 0;
};
JointIntervals joint_intervals(const std::vector<CandidateParameter>& params,
                               const std::function<std::vector<double>(const std::vector<std::vector<double>>&)>& rss_batch,
                               const std::vector<double>& values, double rss_tol);

// ---- evidence (evidence.cpp)

/// Residual signature of a comparison: numbers the reasons are made of.
struct Signature {
  std::vector<double> trial_rmse;     ///< per trial
  double growth = 1.0;                ///< rmse of the last trial / first
  double noise_deg = 0.0;             ///< angle tracking noise per frame (mean over the trials)
  double creep_top_deg = 0.0;         ///< mean (measured - model) spread at the top third of the levels
  double creep_low_deg = 0.0;         ///< ... at the other levels
  double creep_first_deg = 0.0, creep_last_deg = 0.0;  ///< mean spread difference, first / last trial
  double first_vs_rest = 0.0;         ///< mean residual of trial 1 minus that of the others
  double early_deg = 0.0, late_deg = 0.0;  ///< mean residual in the first 0.5 s of steps / after the mark
  double rest_deg = 0.0;              ///< mean residual on steps at (near) zero pressure
  double proportional = 0.0;          ///< correlation of mark residual with the measured mark angle
  /// Where the angle grows over the trials (issue 35: creep against fatigue): the growth from trial 2
  /// to the last trial (least-squares slope of the per-trial mean x (trials - 2)) of the mean
  /// residual measured - model over the top holds (the steps at the highest level, within 5 %) and
  /// over the steps at rest (|level| < 5 % of it). Trial 1 is left out: its rest is the virgin state. A creep that
  /// recovers slower than the rests grows the rest angle as much as the top one; a permanent
  /// softening (fatigue) grows the top and barely the rest (tests/data/othermeans/components.py).
  /// 0 with fewer than three trials having both.
  double top_growth_deg = 0.0, rest_growth_deg = 0.0;
  int growth_trials = 0;              ///< trials the two growths are taken over (0: not computed)
  /// The growth of the difference top - rest per trial (= top_growth_deg - rest_growth_deg): a
  /// fatigue's signature is a positive one, a creep recovering slower than modelled a negative one.
  double split_growth_deg = 0.0;
  /// Standard errors of the three growths (deg): per trial, the larger of the angle noise's error of
  /// the trial's mean (noise / sqrt(frames), the top's and the rest's combined for the difference)
  /// and, from four trials after the first, the scatter of the trial means about their line; then the
  /// least-squares slope's error times the span (growth_significant judges a growth by it).
  double top_growth_se_deg = 0.0, rest_growth_se_deg = 0.0, split_growth_se_deg = 0.0;
};

/// A growth of the split is significant when it is at least kGrowthSigmas standard errors and at
/// least half the last digit printed (0.005 deg: noise-free data give a zero error).
constexpr double kGrowthSigmas = 3.0;
bool growth_significant(double growth_deg, double se_deg);

Signature signature_of(const Comparison& c);

/// The growth split of `s` as the outputs record it (DiagnosisResult::baseline_growth, final_growth).
GrowthSplit growth_split_of(const Signature& s);

/// The growth split in words: "over the 5 trials after the first the residual (measured - model)
/// grows by +0.43 deg at the top holds and +0.06 deg at rest"; "" when not computed.
std::string growth_split_text(const Signature& s);

/// The sentence about the residual feature that `effect` explains. Every word of direction in it
/// (grows / falls / stays flat, more / less / as modelled, ...) is read off the numbers it quotes:
/// a difference within the angle tracking noise (s.noise_deg, and at least half the last digit
/// printed, so "+0.00" is never a trend) is called flat, and a correlation below 0.5 in size weak.
std::string evidence(const std::string& effect, const Signature& s);

// ---- full FEM (fem.cpp)

/// --refine and --fem-calibrate: re-calibrates the constants of `chosen` against the full FEM of
/// `scene` (space mapping on the reduced model of `cal_scene`, N + 1 FEM runs for --refine N, then
/// local FEM calibration), and keeps those of the best complete FEM run. Updates `chosen`,
/// `selected_sets` (the scene overrides of `chosen`), `rom_runs` and out.fem_error /
/// out.refined_params; `fitted_fem` (if given) gets the FEM angle traces of the kept constants when
/// a refinement run computed them (else it is left empty). Does nothing when neither is asked for
/// or nothing was selected.
void refine_with_fem(const Scene& scene, const Scene& cal_scene, const Recording& rec,
                     const std::vector<ComparedFrame>& frames, const PathModelEvaluator& rom, const DiagnoseOptions& opt,
                     ChosenEffects& chosen, std::vector<std::string>& selected_sets, long& rom_runs,
                     DiagnosisResult& out, std::vector<Series>* fitted_fem = nullptr);

/// --verify: the full-FEM NRMSEs of the baseline `scene` and of `fitted` (out.verified_*; -1 and a
/// note in out.fem_error when a run fails). `fitted_fem`, when non-empty, are the FEM traces of
/// `fitted` already computed (by refine_with_fem): its run is not repeated.
void verify_with_fem(const Scene& scene, const Scene& fitted, const Recording& rec, const DiagnoseOptions& opt,
                     DiagnosisResult& out, const std::vector<Series>* fitted_fem = nullptr);

// ---- outputs (output.cpp)

/// Writes diagnosis.json, fitted.toml, diagnosis.csv, calibration.csv and report.md to opt.out_dir
/// (each atomically) and appends the baseline and the model after each round to its history.jsonl.
void write_diagnosis(const Scene& scene, const Scene& fitted, const Recording& rec, const PathModelEvaluator& rom,
                     const ChosenEffects& chosen, const DiagnoseOptions& opt, const DiagnosisResult& out);

// ---- report (report.cpp)

/// report.md: the recording and the scene, the error per trial of the baseline beside the final
/// model's (and after each round), every round's candidates with their tests, the chosen effect
/// and its constants, and the reasons in words (the candidates' `why`). Only formats `out`.
std::string diagnosis_report(const Scene& scene, const Recording& rec, const PathModelEvaluator& rom,
                             const DiagnoseOptions& opt, const DiagnosisResult& out);

}  // namespace pneufem::diagnose_detail
