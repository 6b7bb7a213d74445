#include "damage/registry.h"

#include <cmath>
#include <deque>
#include <set>

#include "core/errors.h"
#include "core/number_text.h"
#include "damage/effects.h"

namespace pneufem {

namespace {

constexpr double kMPa = 1e6;

// Calibration bounds of the built-ins. They span what an Ecoflex-class silicone plausibly shows:
//  * mullins r in [1.1, 20] (max softening 1/r from 91 % down to 5 %), m in [1e-3, 0.1] MPa (the
//    energy densities of the pneu-net walls at 45 kPa are ~1e-3..5e-2 MPa, so m spans "abrupt" to
//    "gradual" over that range); beta in [0, 1];
//  * fatigue W_th in [0.003, 0.1] MPa (same energy range), tau in [100, 1e5] s (damage visible
//    after one 160 s trial down to barely visible over ten), q in [1, 4];
//  * viscoelastic gamma in [0.02, 3] (2 % to 300 % instantaneous overstiffness), tau in [0.2, 30] s
//    (faster than the controller's rise down to a whole hold).
std::vector<MaterialEffect> builtins() {
  std::vector<MaterialEffect> v;
  {
    MaterialEffect e;
    e.name = "mullins";
    e.doc = "Ogden-Roxburgh Mullins softening: stress softened by eta(W, W_max) below the peak energy";
    e.params = {{"r", "1", "> 1; maximum softening fraction 1/r", 3.0, 1.1, 20.0, true},
                {"m_MPa", "MPa", ">= 0; energy scale of the softening", 0.01, 1e-3, 0.1, true},
                {"beta", "1", ">= 0; growth of the energy scale with W_max", 0.1, 0.0, 1.0, false}};
    e.decorate = [](MaterialPtr base, const std::map<std::string, double>& p) {
      return make_mullins(std::move(base), MullinsParams{p.at("r"), p.at("m_MPa") * kMPa, p.at("beta")});
    };
    e.order = 100;
    e.extra_keys = {};
    v.push_back(e);
  }
  {
    MaterialEffect e;
    e.name = "fatigue";
    e.doc = "progressive fatigue damage dd/dt = <X/X_th - 1>^q (1 - d)^n / tau above a threshold";
    e.params = {{"W_th_MPa", "MPa", "threshold isochoric energy density (driver = energy)", 0.02, 0.003, 0.1, true},
                {"lambda_th", "1", "threshold stretch (driver = max_principal_stretch)", 1.5, 1.05, 3.0, false},
                {"tau_s", "s", "time scale of the damage rate", 1000.0, 100.0, 1e5, true},
                {"q", "1", ">= 1; exponent of the overload", 2.0, 1.0, 4.0, false},
                {"n", "1", ">= 1; integrity exponent (> 1: growth slows as damage accumulates)", 1.0, 1.0, 6.0, false},
                {"d_fail", "1", "damage at which a point is flagged failed", 0.9, 0.5, 0.99, false}};
    e.decorate = [](MaterialPtr base, const std::map<std::string, double>& p) {
      FatigueParams f;
      f.W_th_Pa = p.at("W_th_MPa") * kMPa;
      f.lambda_th = p.at("lambda_th");
      f.tau_s = p.at("tau_s");
      f.q = p.at("q");
      f.n = p.at("n");
      f.d_fail = p.at("d_fail");
      return make_fatigue(std::move(base), f);  // driver = energy; scenes choose it with `driver`
    };
    e.order = 200;
    e.extra_keys = {"driver"};
    v.push_back(e);
  }
  {
    MaterialEffect e;
    e.name = "viscoelastic";
    e.doc = "Prony-series finite-strain viscoelasticity; the base law is the long-term response";
    e.params = {{"gamma", "1", "relative stiffness of the Prony term (scenes: an array, one per term)", 0.1, 0.02, 3.0, true},
                {"tau_s", "s", "relaxation time of the term (scenes: an array)", 1.0, 0.2, 30.0, true}};
    e.decorate = [](MaterialPtr base, const std::map<std::string, double>& p) {
      return make_viscoelastic(std::move(base), ViscoParams{{p.at("gamma")}, {p.at("tau_s")}});
    };
    e.order = 300;
    e.extra_keys = {"gamma", "tau_s"};  // arrays in scenes (a one-term effect in the registry)
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

}  // namespace pneufem
