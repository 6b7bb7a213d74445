#pragma once
// The candidate effects that `pneufem diagnose` tries and `pneufem synth --hidden` hides in
// synthetic data: each is a physical effect the base model may be missing, with its calibration
// parameters and the scene overrides that add it to a scene.
//
// Built-ins: stiffness, viscoelastic (moduli = long_term), viscoelastic_instantaneous (moduli =
// instantaneous), viscoelastic_broad (instantaneous, three Prony terms of one shaped spectrum), mullins, fatigue (integrity exponent n = 1), fatigue_saturating (n = 6), pressure_lag,
// gravity; then every effect
// of the material-effect registry (damage/registry.h) that is not a built-in, with the registry's
// parameters and bounds (truth = initial = the registered default). Material effects apply to every
// soft material of the scene's parts (model != "linear_elastic"; the fabric is not softened).
#include <functional>
#include <string>
#include <vector>

#include "scenes/scene.h"

namespace pneufem {

/// none: run by run; rig_angle: the parameter is the rig angle in [0, 180] deg (trigonometric
/// basis); smooth: a smooth response over the bounds (polynomial on Chebyshev nodes of the
/// calibration coordinate, log or linear).
enum class ParameterInterpolation { none, rig_angle, smooth };

struct CandidateParameter {
  std::string name;   ///< e.g. "tau_s"
  std::string unit;   ///< e.g. "s"
  double lo, hi;      ///< calibration bounds
  double initial;     ///< start of calibration
  double truth;       ///< value `pneufem synth --hidden` uses by default
  bool log = false;   ///< calibrate/sample in log space
  /// lo is where the effect reduces to a simpler one of its kind (pressure_lag's tau2 = 0: the
  /// first-order lag), not an extreme: a value there is no "constant at a bound" (params_at_bounds).
  bool reduces_at_lo = false;
};

struct CandidateEffect {
  std::string name;         ///< "stiffness", "viscoelastic", ... or a registered material effect
  std::string description;  ///< one line, plain words
  std::string signature;    ///< residual signature it explains, plain words (diagnose's "why")
  bool history = false;     ///< the response depends on the load history (creep, damage)
  /// Candidates of one family are forms of one effect in one scene table ("creep": the one-term creep
  /// in either convention and the broad spectrum; "fatigue": with and without saturation): they are
  /// not stacked, and after each round diagnose tries the other forms of a selected one in its place
  /// (command.cpp, try_other_forms). "" = none.
  std::string family;
  /// How diagnose may interpolate the model over this candidate's single parameter when every run
  /// costs a static FEM sweep (an elastic model with gravity); see app/diagnose/elastic_curve.h.
  ParameterInterpolation interpolation = ParameterInterpolation::none;
  std::vector<CandidateParameter> params;
  /// `--set` overrides (key=value) that add the effect with these parameter values (one per param,
  /// in order) to `scene`. Throws InputError for a wrong number of values.
  std::function<std::vector<std::string>(const Scene& scene, const std::vector<double>& values)> sets;
  /// Optional: what calibrated `values` mean, in plain words (pressure_lag: which order, zeta and
  /// f_n); diagnose appends it to the candidate's "why".
  std::function<std::string(const std::vector<double>& values)> reading;
};

/// Built-ins then every registered material effect (rebuilt when effects were registered since).
const std::vector<CandidateEffect>& candidate_effects();

/// The candidate called `name`; throws InputError listing the valid names.
const CandidateEffect& candidate_effect(const std::string& name);

/// Names of the soft materials of the scene's parts (model != "linear_elastic"), in part order.
std::vector<std::string> soft_materials(const Scene& scene);

}  // namespace pneufem
