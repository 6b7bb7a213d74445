#pragma once
// The one list of inelastic material effects pneufem knows: the built-ins (mullins, fatigue,
// viscoelastic) and any effect a user adds in C++ (docs/adding_an_effect.md). An effect is a
// decorator over a material with named numeric parameters; registering it makes it available, by
// name, to
//   * scenes:    [materials.<m>.<name>] enabled = true, <param> = value   (scenes/scene_materials.cpp)
//   * sweep:     --param materials.<m>.<name>.<param>=LO:HI:N
//   * compare / diagnose / synth: as a candidate effect with the registered bounds (app/diagnose/effect_catalog.h).
//
// One source of truth. Each parameter (name with its unit, unit, one-line doc, default, calibration
// range) is declared here and nowhere else: the default scene's effect tables are generated from it
// (scenes/effect_tables.h; `pneufem scene --defaults` prints them), the scene reader takes its key
// names and the defaults of keys a scene leaves out from it, the diagnose catalog its units and
// calibration ranges, and docs/scene_reference.md is generated from it (a test keeps it current).
//
// Decoration order. Effects are applied around the (stiffness-scaled) hyperelastic base in
// ascending `order`, ties in registration order. The built-ins have
//     mullins 100, fatigue 200, viscoelastic 300
// which reproduces viscoelastic(fatigue(mullins(base))) (damage/effects.h). The in-tree effect
// fatigue_uniform (damage/fatigue_uniform.h, order 250) is registered beside them but read as a
// registered effect (numbers only; not in the default scene's tables). A new effect with the
// default order 0 wraps the base first: mullins and fatigue are driven by the energy of whatever they
// wrap, which must stay a potential of its stress, so an energy-conserving effect (a softening, an
// anisotropy) belongs below 100; a rate-dependent one (its stress not a potential) belongs above 200.
//
// Registration is not thread-safe: register at start-up. The built-ins are registered on first use;
// an in-tree effect is added to the list in builtins() of registry.cpp; tools and tests may call
// register_material_effect before building any scene.
#include <functional>
#include <map>
#include <string>
#include <vector>

#include "materials/material.h"

namespace pneufem {

struct EffectParameter {
  std::string name;           ///< scene key materials.<m>.<effect>.<name>, units in the name (tau_s, m_MPa)
  std::string unit;           ///< for documentation ("s", "MPa", "1")
  std::string doc;            ///< one line
  double default_value = 0.0; ///< used when a scene omits the parameter
  double lo = 0.0, hi = 0.0;  ///< calibration bounds (diagnose/compare); physical validity is the decorator's job
  bool log = false;           ///< calibrate/sample in log space (then lo > 0)
  /// The scene holds a list, one value per term (the Prony terms of viscoelastic); the registry
  /// describes one term. Built-in effects only: their scene tables are read by scenes/scene_materials.cpp.
  bool per_term = false;
};

/// A non-numeric key of an effect's scene table: one of a few words (fatigue's `driver`). Built-in
/// effects only, like per_term parameters.
struct EffectChoice {
  std::string name;                 ///< scene key materials.<m>.<effect>.<name>
  std::string doc;                  ///< one line
  std::vector<std::string> values;  ///< the allowed words; the first is the default
};

struct MaterialEffect {
  std::string name, doc;
  std::vector<EffectParameter> params;
  /// Wraps `base` with the effect at `values` (every param present, in the scene's units, e.g. MPa).
  /// Throws InputError (naming the parameter) for physically invalid values.
  std::function<MaterialPtr(MaterialPtr base, const std::map<std::string, double>& values)> decorate;
  int order = 0;         ///< decoration order, see above
  bool history = true;   ///< the response depends on the load history (rate or damage); false = elastic
  std::vector<EffectChoice> choices;  ///< non-numeric scene keys (built-ins only)

  /// The parameter called `name`; throws InputError naming the effect and its parameters.
  const EffectParameter& param(const std::string& name) const;
};

/// Adds an effect. Throws InputError on an empty or duplicate name, a name that is not
/// [a-z][a-z0-9_]*, a parameter named "enabled" or twice, bounds with !(lo < hi), a default outside
/// [lo, hi], a log parameter with lo <= 0, no decorate function, or per_term parameters or choices
/// (which only the built-ins' scene reader understands).
void register_material_effect(MaterialEffect e);

/// The effect called `name`, or nullptr.
const MaterialEffect* find_material_effect(const std::string& name);

/// Every effect in registration order (the built-ins first).
std::vector<const MaterialEffect*> material_effects();

/// True for mullins, fatigue and viscoelastic, whose scene tables carry non-numeric keys and are
/// read by scenes/scene_materials.cpp directly (with the names, defaults and choices declared here).
bool is_builtin_effect(const std::string& name);

/// The built-in effect `name` (mullins, fatigue or viscoelastic); a programming error otherwise
/// (std::logic_error): callers name the built-ins literally.
const MaterialEffect& builtin_effect(const std::string& name);

}  // namespace pneufem
