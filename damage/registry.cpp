#include "damage/registry.h"

#include <cmath>
#include <deque>
#include <memory>
#include <set>
#include <stdexcept>

#include "core/errors.h"
#include "core/number_text.h"
#include "damage/effects.h"
#include "damage/fatigue_uniform.h"

namespace pneufem {

namespace {

constexpr double kMPa = 1e6;

// The built-ins' parameters: the single declaration of their scene keys, units, defaults and
// calibration ranges (registry.h, "One source of truth").
//
// Defaults are what a scene gets for a key it leaves out. Until 2026-11-27 the default scene file
// and this table disagreed (Mullins r 8.0 there, 3.0 here; fatigue lambda_th 1.6 vs 1.5; Prony tau
// 6 s vs 1 s). The scene file's values won: they are the ones every run has used (this table's were
// read by nothing), so no scene's result changed; and r = 8 (at most 12.5 % softening) is the value
// scenes/examples/paper_story.toml argues for against the seed paper's mid steps (with r = 5 trial
// 2's 25-40 kPa steps already sit 5-13 % of the angle range above the ideal model). The diagnose
// catalog's calibration starts (Mullins r 5, the middle of its log range) and synth's hidden truths
// (r 3, a clearly visible effect; app/diagnose/effect_catalog.cpp) are other quantities, not defaults.
//
// Calibration bounds span what an Ecoflex-class silicone plausibly shows:
//  * mullins r in [1.1, 20] (max softening 1/r from 91 % down to 5 %; the default 8 is 12.5 %),
//    m in [1e-3, 0.1] MPa (the energy densities of the pneu-net walls at 45 kPa are ~1e-3..5e-2 MPa,
//    so m spans "abrupt" to "gradual" over that range); beta in [0, 1];
//  * fatigue W_th in [0.003, 0.1] MPa (same energy range), tau in [100, 1e5] s (damage visible
//    after one 160 s trial down to barely visible over ten), q in [1, 4];
//  * viscoelastic gamma in [0.02, 3] (instantaneous modulus 2 % to 300 % above the long-term one, in
//    either moduli convention), tau in [0.2, 30] s (faster than the controller's rise down to a whole hold).
std::vector<MaterialEffect> builtins() {
  std::vector<MaterialEffect> v;
  {
    MaterialEffect e;
    e.name = "mullins";
    e.doc = "Ogden-Roxburgh Mullins softening: eta = 1 - erf((W_max - W)/(m + beta W_max))/r below the peak energy W_max";
    e.params = {{"r", "1", "> 1; maximum softening fraction 1/r", 8.0, 1.1, 20.0, true},
                {"m_MPa", "MPa", ">= 0; energy scale of the softening", 0.01, 1e-3, 0.1, true},
                {"beta", "1", ">= 0; growth of the energy scale with W_max", 0.1, 0.0, 1.0, false}};
    e.decorate = [](MaterialPtr base, const std::map<std::string, double>& p) {
      return make_mullins(std::move(base), MullinsParams{p.at("r"), p.at("m_MPa") * kMPa, p.at("beta")});
    };
    e.order = 100;
    v.push_back(e);
  }
  {
    MaterialEffect e;
    e.name = "fatigue";
    e.doc = "progressive fatigue damage dd/dt = <X/X_th - 1>^q (1 - d)^n / tau above a threshold X_th";
    e.params = {{"W_th_MPa", "MPa", "threshold isochoric energy density (driver = \"energy\")", 0.02, 0.003, 0.1, true},
                {"lambda_th", "1", "threshold stretch (driver = \"max_principal_stretch\")", 1.6, 1.05, 3.0, false},
                {"tau_s", "s", "time scale of the damage rate", 1000.0, 100.0, 1e5, true},
                {"q", "1", ">= 1; exponent of the overload", 2.0, 1.0, 4.0, false},
                {"n", "1", ">= 1; integrity exponent (> 1 saturates: damaged points slow down)", 1.0, 1.0, 6.0, false},
                {"d_fail", "1", "a point fails at this damage, which then stops growing (residual stiffness 1 - d_fail)",
                 0.9, 0.5, 0.99, false},
                {"nonlocal_radius_mm", "mm",
                 ">= 0; > 0: the driver is averaged over this radius (non-local, mesh-objective damage; needs "
                 "elements well below it); 0 = local",
                 0.0, 0.0, 10.0, false}};
    e.choices = {{"driver", "X: the isochoric energy density (W_th_MPa) or the largest principal stretch (lambda_th)",
                  {"energy", "max_principal_stretch"}}};
    e.decorate = [](MaterialPtr base, const std::map<std::string, double>& p) {
      FatigueParams f;
      f.W_th_Pa = p.at("W_th_MPa") * kMPa;
      f.lambda_th = p.at("lambda_th");
      f.tau_s = p.at("tau_s");
      f.q = p.at("q");
      f.n = p.at("n");
      f.d_fail = p.at("d_fail");
      f.nonlocal_radius_m = p.at("nonlocal_radius_mm") * 1e-3;
      return make_fatigue(std::move(base), f);  // driver = energy; scenes choose it with `driver`
    };
    e.order = 200;
    v.push_back(e);
  }
  {
    MaterialEffect e;
    e.name = "viscoelastic";
    e.doc = "Prony-series finite-strain viscoelasticity of the isochoric response; `moduli` says whether the "
            "hyperelastic constants are its instantaneous or its long-term response";
    e.params = {{"gamma", "1",
                 "stiffness of each Prony term relative to the long-term modulus (Abaqus g_i: gamma = g/(1 - sum g))",
                 0.1, 0.02, 3.0, true, true},
                {"tau_s", "s", "relaxation time of each term", 6.0, 0.2, 30.0, true, true}};
    // Default "instantaneous", as Abaqus (MODULI=INSTANTANEOUS with *VISCOELASTIC): the hyperelastic
    // constants are the response right after a step, which relaxes to 1/(1 + sum gamma) = 1 - sum g of
    // it. "long_term" is the convention pneufem had before 2026-11-27 (damage/viscoelastic.h).
    e.choices = {{"moduli",
                  "which response the material's hyperelastic constants describe: the instantaneous one (Abaqus's "
                  "default; the isochoric stress relaxes to 1/(1 + sum gamma) of it) or the long-term one (the "
                  "instantaneous stress is 1 + sum gamma times it); a deck's MODULI= sets it",
                  {"instantaneous", "long_term"}}};
    // Registered-effect callers pass numbers only: the choice takes its default (the scene reader,
    // scenes/scene_materials.cpp, passes the scene's word).
    e.decorate = [](MaterialPtr base, const std::map<std::string, double>& p) {
      return make_viscoelastic(std::move(base),
                               ViscoParams{{p.at("gamma")}, {p.at("tau_s")}, ViscoModuli::instantaneous});
    };
    e.order = 300;
    v.push_back(e);
  }
  {
    // Fatigue as a uniform compliance growth with a load-weighted count (damage/fatigue_uniform.h; issue
    // 35): not a built-in table (no per-term lists, no choices), so the default scene and the scene
    // reference leave it out and scenes read it as any registered effect. Order 250: it counts by the
    // energy of what it wraps, so it wraps mullins (100; a fatigue base, 200, is refused: its energy is
    // not a potential of its stress), and viscoelastic (300) wraps it.
    // Ranges: a in [1e-3, 0.5] (0.1 % to 50 % more compliance per e-fold of the count: from below what
    // a recording resolves to a silicone that halves its stiffness within a few cycles); t0 in
    // [0.1, 1e4] s of peak load (the growth turns logarithmic within the first ramp, up to never within
    // hours of loading: then D ~ a N / t0, a constant rate).
    MaterialEffect e;
    e.name = "fatigue_uniform";
    e.doc = "fatigue as a uniform compliance growth 1 + a ln(1 + N/t0) of the silicone, N = int W/W_max dt the "
            "load-weighted count";
    e.params = {{"a", "1", "> 0; compliance growth per e-fold of the count", 0.03, 1e-3, 0.5, true},
                {"t0_s", "s", "> 0; the count (s at the peak load) where the growth turns logarithmic", 10.0, 0.1,
                 1e4, true}};
    e.decorate = [](MaterialPtr base, const std::map<std::string, double>& p) -> MaterialPtr {
      return std::make_shared<const UniformFatigue>(std::move(base), UniformFatigueParams{p.at("a"), p.at("t0_s")});
    };
    e.order = 250;
    v.push_back(e);
  }
  return v;
}

void validate(const MaterialEffect& e, const std::deque<MaterialEffect>& known) {
  const std::string who = "material effect '" + e.name + "'";
  if (e.name.empty()) throw InputError("register_material_effect: the effect needs a name");
  if (!(e.name[0] >= 'a' && e.name[0] <= 'z') ||
      e.name.find_first_not_of("abcdefghijklmnopqrstuvwxyz0123456789_") != std::string::npos)
    throw InputError(who + ": the name must match [a-z][a-z0-9_]* (it becomes a scene table name)");
  static const std::set<std::string> kReserved = {"model", "density_kg_m3", "K_over_mu", "stiffness_scale",
                                                  "stiffness", "pressure_lag", "gravity"};
  if (kReserved.count(e.name)) throw InputError(who + ": the name is reserved for a scene key or a built-in candidate");
  for (const MaterialEffect& k : known)
    if (k.name == e.name) throw InputError(who + ": already registered; choose another name");
  if (!e.decorate) throw InputError(who + ": no decorate function");
  std::set<std::string> seen;
  for (const EffectParameter& p : e.params) {
    const std::string pw = who + ", parameter '" + p.name + "'";
    if (p.name.empty() || p.name == "enabled") throw InputError(pw + ": a parameter needs a name other than 'enabled'");
    if (!seen.insert(p.name).second) throw InputError(pw + ": given twice");
    if (!(std::isfinite(p.lo) && std::isfinite(p.hi) && p.lo < p.hi))
      throw InputError(pw + ": calibration bounds need finite lo < hi, got [" + short_num(p.lo) + ", " + short_num(p.hi) + "]");
    if (!(p.default_value >= p.lo && p.default_value <= p.hi))
      throw InputError(pw + ": default " + short_num(p.default_value) + " lies outside [" + short_num(p.lo) + ", " + short_num(p.hi) + "]");
    if (p.log && !(p.lo > 0.0)) throw InputError(pw + ": a log-scale parameter needs lo > 0");
    if (p.per_term && !is_builtin_effect(e.name))
      throw InputError(pw + ": per_term lists are read for the built-in effects only; use one parameter per term");
  }
  for (const EffectChoice& c : e.choices) {
    if (!is_builtin_effect(e.name))
      throw InputError(who + ", key '" + c.name + "': choices are read for the built-in effects only");
    if (c.values.empty()) throw InputError(who + ", key '" + c.name + "': a choice needs its allowed values");
    if (c.name == "enabled" || !seen.insert(c.name).second)
      throw InputError(who + ", key '" + c.name + "': named 'enabled' or like another key");
  }
}

// std::deque: references stay valid as effects are appended (find_material_effect hands out pointers).
std::deque<MaterialEffect>& registry() {
  static std::deque<MaterialEffect> r = [] {
    std::deque<MaterialEffect> d;
    for (MaterialEffect& e : builtins()) {
      validate(e, d);
      d.push_back(std::move(e));
    }
    return d;
  }();
  return r;
}

}  // namespace

void register_material_effect(MaterialEffect e) {
  std::deque<MaterialEffect>& r = registry();
  validate(e, r);
  r.push_back(std::move(e));
}

const MaterialEffect* find_material_effect(const std::string& name) {
  for (const MaterialEffect& e : registry())
    if (e.name == name) return &e;
  return nullptr;
}

std::vector<const MaterialEffect*> material_effects() {
  std::vector<const MaterialEffect*> v;
  for (const MaterialEffect& e : registry()) v.push_back(&e);
  return v;
}

bool is_builtin_effect(const std::string& name) {
  return name == "mullins" || name == "fatigue" || name == "viscoelastic";
}

const MaterialEffect& builtin_effect(const std::string& name) {
  const MaterialEffect* e = is_builtin_effect(name) ? find_material_effect(name) : nullptr;
  if (!e) throw std::logic_error("builtin_effect: '" + name + "' is not a built-in effect");
  return *e;
}

const EffectParameter& MaterialEffect::param(const std::string& p) const {
  std::string names;
  for (const EffectParameter& q : params) {
    if (q.name == p) return q;
    names += (names.empty() ? "" : ", ") + q.name;
  }
  throw InputError("material effect '" + name + "' has no parameter '" + p + "'; it has " + names);
}

}  // namespace pneufem
