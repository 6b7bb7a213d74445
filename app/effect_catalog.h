#pragma once
// The candidate effects that `pneufem diagnose` tries and `pneufem synth --hidden` hides in
// synthetic data: each is a physical effect the base model may be missing, with its calibration
// parameters and the scene overrides that add it to a scene.
//
// Built-ins: stiffness, viscoelastic, mullins, fatigue, pressure_lag, gravity; then every effect
// of the material-effect registry (damage/registry.h) that is not a built-in, with the registry's
// parameters and bounds (truth = initial = the registered default). Material effects apply to every
// soft material of the scene's parts (model != "linear_elastic"; the fabric is not softened).
#include <functional>
#include <string>
#include <vector>

#include "scenes/scene.h"

namespace pneufem {

struct CandidateParameter {
  std::string name;   ///< e.g. "tau_s"
  std::string unit;   ///< e.g. "s"
  double lo, hi;      ///< calibration bounds
  double initial;     ///< start of calibration
  double truth;       ///< value `pneufem synth --hidden` uses by default
  bool log = false;   ///< calibrate/sample in log space
};

struct CandidateEffect {
  std::string name;         ///< "stiffness", "viscoelastic", ... or a registered material effect
  std::string description;  ///< one line, plain words
  std::string signature;    ///< residual signature it explains, plain words (diagnose's "why")
  bool history = false;     ///< the response depends on the load history (creep, damage)
  /// The only parameter is the rig angle (the gravity direction in the y-z plane): diagnose then
  /// calibrates on FEM curves interpolated over the angle (five sweeps) instead of one sweep per run.
  bool rig_angle = false;
  std::vector<CandidateParameter> params;
  /// `--set` overrides (key=value) that add the effect with these parameter values (one per param,
  /// in order) to `scene`. Throws InputError for a wrong number of values.
  std::function<std::vector<std::string>(const Scene& scene, const std::vector<double>& values)> sets;
};

/// Built-ins then every registered material effect (rebuilt when effects were registered since).
const std::vector<CandidateEffect>& candidate_effects();

/// The candidate called `name`; throws InputError listing the valid names.
const CandidateEffect& candidate_effect(const std::string& name);

/// Names of the soft materials of the scene's parts (model != "linear_elastic"), in part order.
std::vector<std::string> soft_materials(const Scene& scene);

}  // namespace pneufem
