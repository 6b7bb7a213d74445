// Materials from the scene (make_material, declared in scenes/build_model.h): the law of a
// [materials.NAME] table, its stiffness scale, and the inelastic effects that wrap it, built-in
// (Mullins, fatigue, viscoelastic) and registered (damage/registry.h).
#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <optional>
#include <set>

#include "core/errors.h"
#include "damage/effects.h"
#include "damage/registry.h"
#include "materials/hyperelastic.h"
#include "materials/ogden.h"
#include "materials/scaled.h"
#include "scenes/build_model.h"
#include "scenes/scene_keys.h"

namespace pneufem {

namespace {

using detail::kMPa;
using detail::positive;
using detail::require_keys;

/// The keys the table of effect `fx` may hold: `enabled`, its parameters and its choices.
std::set<std::string> effect_keys(const MaterialEffect& fx) {
  std::set<std::string> keys{"enabled"};
  for (const EffectParameter& p : fx.params) keys.insert(p.name);
  for (const EffectChoice& c : fx.choices) keys.insert(c.name);
  return keys;
}

/// Parameter `name` of the effect table K: the scene's value, or the registered default when the
/// table leaves it out (damage/registry.h declares every default once).
double effect_number(const Scene& s, const std::string& K, const MaterialEffect& fx, const std::string& name) {
  return s.has(K + "." + name) ? s.number(K + "." + name) : fx.param(name).default_value;
}

/// A per-term parameter (a list, one value per Prony term): the scene's list, or one term at the default.
std::vector<double> effect_terms(const Scene& s, const std::string& K, const MaterialEffect& fx, const std::string& name) {
  return s.has(K + "." + name) ? s.numbers(K + "." + name) : std::vector<double>{fx.param(name).default_value};
}

/// Choice `c` of the effect table K: the scene's word, which must be one of c.values, or the default.
std::string effect_choice(const Scene& s, const std::string& K, const EffectChoice& c) {
  const std::string key = K + "." + c.name;
  if (!s.has(key)) return c.values.front();
  const std::string v = s.string(key);
  if (std::find(c.values.begin(), c.values.end(), v) != c.values.end()) return v;
  std::string allowed;
  for (std::size_t i = 0; i < c.values.size(); ++i)
    allowed += (i == 0 ? "" : i + 1 == c.values.size() ? " or " : ", ") + ("\"" + c.values[i] + "\"");
  s.fail(key, "must be " + allowed);
}

// Built-in inelastic effects of a material table: [materials.NAME.mullins], .fatigue, .viscoelastic,
// each with `enabled` and its constants (names and defaults from the registry). Applied in the
// canonical order viscoelastic(fatigue(mullins)).
EffectParams effect_params(const Scene& s, const std::string& T) {
  EffectParams e;
  auto on = [&](const std::string& k) { return s.has(T + "." + k) && s.boolean(T + "." + k + ".enabled"); };
  if (on("mullins")) {
    const std::string K = T + ".mullins";
    const MaterialEffect& fx = builtin_effect("mullins");
    require_keys(s, K, effect_keys(fx), "mullins");
    e.mullins = MullinsParams{effect_number(s, K, fx, "r"), effect_number(s, K, fx, "m_MPa") * kMPa,
                              effect_number(s, K, fx, "beta")};
  }
  if (on("fatigue")) {
    const std::string K = T + ".fatigue";
    const MaterialEffect& fx = builtin_effect("fatigue");
    require_keys(s, K, effect_keys(fx), "fatigue");
    FatigueParams f;
    f.driver = effect_choice(s, K, fx.choices.at(0)) == "energy" ? FatigueDriver::energy
                                                                 : FatigueDriver::max_principal_stretch;
    f.W_th_Pa = effect_number(s, K, fx, "W_th_MPa") * kMPa;
    f.lambda_th = effect_number(s, K, fx, "lambda_th");
    f.tau_s = effect_number(s, K, fx, "tau_s");
    f.q = effect_number(s, K, fx, "q");
    f.n = effect_number(s, K, fx, "n");
    f.d_fail = effect_number(s, K, fx, "d_fail");
    const double R_mm = effect_number(s, K, fx, "nonlocal_radius_mm");
    if (!(std::isfinite(R_mm) && R_mm >= 0.0))
      s.fail(K + ".nonlocal_radius_mm", "must be >= 0 mm (0 = local driver; > 0: averaged over this radius)");
    f.nonlocal_radius_m = R_mm * 1e-3;
    e.fatigue = f;
  }
  if (on("viscoelastic")) {
    const std::string K = T + ".viscoelastic";
    const MaterialEffect& fx = builtin_effect("viscoelastic");
    require_keys(s, K, effect_keys(fx), "viscoelastic");
    const std::string moduli = effect_choice(s, K, fx.choices.at(0));
    e.viscoelastic = ViscoParams{effect_terms(s, K, fx, "gamma"), effect_terms(s, K, fx, "tau_s"),
                                 moduli == "instantaneous" ? ViscoModuli::instantaneous : ViscoModuli::long_term};
  }
  return e;
}

/// materials.NAME.stiffness_scale (absent in a user-defined table = 1).
double material_scale(const Scene& s, const std::string& name) {
  const std::string key = "materials." + name + ".stiffness_scale";
  if (!s.has(key)) return 1.0;
  const double v = s.number(key);
  if (!(std::isfinite(v) && v > 0.0)) s.fail(key, "must be > 0 (1 = the material as given; 0.8 = 20 % softer)");
  return v;
}

/// Keys every material table may have besides its law's constants: the scale and the effects.
std::set<std::string> with_common_keys(std::set<std::string> keys) {
  keys.insert("stiffness_scale");
  for (const MaterialEffect* fx : material_effects()) keys.insert(fx->name);
  return keys;
}

/// The law of table materials.NAME with its constants, before any scale or effect.
MaterialPtr make_base_material(const Scene& s, const std::string& name) {
  const std::string T = "materials." + name;
  if (!s.has(T)) s.fail(T, "no such material; define a [" + T + "] table");
  const std::string model = s.string(T + ".model");
  static const std::set<std::string> kModels = {"linear_elastic", "yeoh", "neo_hookean", "mooney_rivlin", "ogden"};
  if (!kModels.count(model))
    s.fail(T + ".model", "unknown material model \"" + model +
                             "\"; use yeoh, neo_hookean, mooney_rivlin, ogden or linear_elastic");
  positive(s, T + ".density_kg_m3");
  try {
    if (model == "linear_elastic") {
      require_keys(s, T, with_common_keys({"model", "E_MPa", "nu", "density_kg_m3"}), "model linear_elastic");
      return std::make_shared<SaintVenantKirchhoff>(s.number(T + ".E_MPa") * kMPa, s.number(T + ".nu"));
    }
    const double Kr = s.number(T + ".K_over_mu");
    if (model == "yeoh") {
      require_keys(s, T, with_common_keys({"model", "C10_MPa", "C20_MPa", "C30_MPa", "K_over_mu", "density_kg_m3"}), "model yeoh");
      const double C10 = s.number(T + ".C10_MPa") * kMPa;
      const double C20 = s.has(T + ".C20_MPa") ? s.number(T + ".C20_MPa") * kMPa : 0.0;
      const double C30 = s.has(T + ".C30_MPa") ? s.number(T + ".C30_MPa") * kMPa : 0.0;
      return std::make_shared<InvariantMaterial<Yeoh>>(Yeoh(C10, C20, C30, bulk_from_ratio(2 * C10, Kr)));
    }
    if (model == "neo_hookean") {
      require_keys(s, T, with_common_keys({"model", "C10_MPa", "K_over_mu", "density_kg_m3"}), "model neo_hookean");
      const double C10 = s.number(T + ".C10_MPa") * kMPa;
      return std::make_shared<InvariantMaterial<NeoHookean>>(NeoHookean(C10, bulk_from_ratio(2 * C10, Kr)));
    }
    if (model == "mooney_rivlin") {
      require_keys(s, T, with_common_keys({"model", "C10_MPa", "C01_MPa", "K_over_mu", "density_kg_m3"}), "model mooney_rivlin");
      const double C10 = s.number(T + ".C10_MPa") * kMPa, C01 = s.number(T + ".C01_MPa") * kMPa;
      return std::make_shared<InvariantMaterial<MooneyRivlin>>(
          MooneyRivlin(C10, C01, bulk_from_ratio(2 * (C10 + C01), Kr)));
    }
    if (model == "ogden") {
      require_keys(s, T, with_common_keys({"model", "mu_MPa", "alpha", "K_over_mu", "density_kg_m3"}), "model ogden");
      std::vector<double> mu = s.numbers(T + ".mu_MPa");
      const std::vector<double> alpha = s.numbers(T + ".alpha");
      double mu0 = 0.0;
      for (double& m : mu) {
        m *= kMPa;
        mu0 += m;
      }
      return std::make_shared<Ogden>(mu, alpha, bulk_from_ratio(mu0, Kr));
    }
  } catch (const SceneKeyError&) {
    throw;  // names its key already
  } catch (const InputError& e) {
    s.fail(T, e.what());  // the law's error, with the table it came from
  }
  s.fail(T + ".model", "unknown material model \"" + model +
                           "\"; use yeoh, neo_hookean, mooney_rivlin, ogden or linear_elastic");
}

/// One inelastic layer to apply: ascending `order`, ties in registry order (damage/registry.h).
struct Layer {
  int order;
  std::size_t rank;
  std::string key;  ///< scene table, for error messages
  std::function<MaterialPtr(MaterialPtr)> apply;
};

/// The enabled registered (non-built-in) effect `fx` of table T, or nothing. Parameters left out
/// take the registry defaults; unknown keys are rejected naming the valid ones.
std::optional<Layer> registered_layer(const Scene& s, const std::string& T, const MaterialEffect& fx, std::size_t rank) {
  const std::string K = T + "." + fx.name;
  if (!s.has(K) || !s.boolean(K + ".enabled")) return std::nullopt;
  require_keys(s, K, effect_keys(fx), "effect " + fx.name);
  std::map<std::string, double> values;
  for (const EffectParameter& p : fx.params) values[p.name] = effect_number(s, K, fx, p.name);
  const MaterialEffect* f = &fx;  // registry entries are never moved
  return Layer{fx.order, rank, K, [f, values](MaterialPtr b) { return f->decorate(std::move(b), values); }};
}

}  // namespace

/// The material of table materials.NAME with its stiffness scale times `region_scale`, wrapped by its
/// enabled effects: effect(...(scaled(base))). The scale sits inside the effects, so energy thresholds
/// (Mullins m, fatigue W_th) are in the scaled energy (materials/scaled.h explains why).
MaterialPtr make_material(const Scene& s, const std::string& name, double region_scale) {
  const std::string T = "materials." + name;
  MaterialPtr m = make_base_material(s, name);
  try {
    m = scale_material(std::move(m), material_scale(s, name) * region_scale);
  } catch (const SceneKeyError&) {
    throw;
  } catch (const InputError& err) {
    s.fail(T + ".stiffness_scale", err.what());
  }
  const EffectParams e = effect_params(s, T);
  std::vector<Layer> layers;
  std::size_t rank = 0;
  for (const MaterialEffect* fx : material_effects()) {
    ++rank;
    // An effect's error names its table, and so where its constants were set (a deck's line, too).
    const std::string K = T + "." + fx->name;
    if (fx->name == "mullins" && e.mullins)
      layers.push_back({fx->order, rank, K, [p = *e.mullins](MaterialPtr b) { return make_mullins(std::move(b), p); }});
    else if (fx->name == "fatigue" && e.fatigue)
      layers.push_back({fx->order, rank, K, [p = *e.fatigue](MaterialPtr b) { return make_fatigue(std::move(b), p); }});
    else if (fx->name == "viscoelastic" && e.viscoelastic)
      layers.push_back({fx->order, rank, K, [p = *e.viscoelastic](MaterialPtr b) { return make_viscoelastic(std::move(b), p); }});
    else if (!is_builtin_effect(fx->name))
      if (auto l = registered_layer(s, T, *fx, rank)) layers.push_back(std::move(*l));
  }
  std::stable_sort(layers.begin(), layers.end(),
                   [](const Layer& a, const Layer& b) { return a.order != b.order ? a.order < b.order : a.rank < b.rank; });
  for (const Layer& l : layers) {
    try {
      m = l.apply(std::move(m));
    } catch (const InputError& err) {
      s.fail(l.key, err.what());
    }
  }
  // A non-local fatigue driver reaches the engine through every layer around it (each forwards
  // Material::nonlocal); an effect registered in C++ that does not would silently make it local.
  if (e.fatigue && e.fatigue->nonlocal_radius_m > 0.0 && !(m->nonlocal().radius_m > 0.0))
    s.fail(T + ".fatigue.nonlocal_radius_mm",
           "an effect wrapped around fatigue ('" + m->name() + "') does not forward the non-local driver "
           "(Material::nonlocal, nonlocal_driver, set_nonlocal_driver to its base; docs/adding_an_effect.md); "
           "set nonlocal_radius_mm = 0.0 or forward them");
  return m;
}

MaterialPtr make_material(const Scene& s, const std::string& name) { return make_material(s, name, 1.0); }

}  // namespace pneufem
