#include "app/diagnose/effect_catalog.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <mutex>

#include "core/errors.h"
#include "damage/registry.h"

namespace pneufem {

namespace {

std::string fmt(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  for (int p = 6; p <= 17; ++p) {  // shortest representation that reads back exactly
    std::snprintf(buf, sizeof buf, "%.*g", p, v);
    if (std::strtod(buf, nullptr) == v) break;
  }
  return buf;
}

void require_count(const CandidateEffect& c, const std::vector<double>& v) {
  if (v.size() != c.params.size())
    throw InputError("candidate effect '" + c.name + "': expected " + std::to_string(c.params.size()) +
                     " parameter value(s), got " + std::to_string(v.size()));
}

/// "materials.M.<suffix>=<value>" for every soft material M.
std::vector<std::string> per_soft_material(const Scene& s, const std::vector<std::pair<std::string, std::string>>& kv) {
  const std::vector<std::string> mats = soft_materials(s);
  if (mats.empty())
    throw InputError("the scene has no soft material (every part is linear_elastic); material effects need one");
  std::vector<std::string> out;
  for (const std::string& m : mats)
    for (const auto& [k, v] : kv) out.push_back("materials." + m + "." + k + "=" + v);
  return out;
}

std::vector<CandidateEffect> builtin_candidates() {
  std::vector<CandidateEffect> c;
  // Bounds: the same physical ranges as the registry's built-ins (damage/registry.cpp explains them);
  // `truth` is a clearly visible but plausible effect, `initial` a neutral start inside the bounds.
  {
    CandidateEffect e;
    e.name = "stiffness";
    e.description = "the silicone is uniformly stiffer or softer than its nominal constants";
    e.signature = "angle off by a similar fraction at every pressure, from the first trial on, no drift in time";
    // scale in [0.5, 2]: batch-to-batch and cure variation of Ecoflex moduli is tens of percent;
    // truth 1.3 is a 30 % stiffer batch.
    e.params = {{"scale", "1", 0.5, 2.0, 1.0, 1.3, true}};
    e.interpolation = ParameterInterpolation::smooth;
    e.sets = [e](const Scene& s, const std::vector<double>& v) {
      require_count(e, v);
      std::vector<std::string> out;
      for (const std::string& m : soft_materials(s)) {  // relative to the scene's own scale
        const std::string key = "materials." + m + ".stiffness_scale";
        const double own = s.has(key) ? s.number(key) : 1.0;
        out.push_back(key + "=" + fmt(own * v[0]));
      }
      if (out.empty()) throw InputError("candidate 'stiffness': the scene has no soft material");
      return out;
    };
    c.push_back(e);
  }
  {
    CandidateEffect e;
    e.name = "viscoelastic";
    e.description = "the silicone creeps: one Prony term of relaxation stiffens it right after each step";
    e.signature = "angle creeps upward during each hold (smaller at the 2.5 s mark than at the hold's end), "
                  "recovering between trials";
    e.history = true;
    e.params = {{"gamma", "1", 0.02, 3.0, 0.2, 0.5, true}, {"tau_s", "s", 0.2, 30.0, 2.0, 4.0, true}};
    e.sets = [e](const Scene& s, const std::vector<double>& v) {
      require_count(e, v);
      return per_soft_material(s, {{"viscoelastic.enabled", "true"},
                                   {"viscoelastic.gamma", "[" + fmt(v[0]) + "]"},
                                   {"viscoelastic.tau_s", "[" + fmt(v[1]) + "]"}});
    };
    c.push_back(e);
  }
  {
    CandidateEffect e;
    e.name = "mullins";
    e.description = "Mullins softening: the silicone is softer below the largest strain it has seen";
    e.signature = "first trial stiffer than the later ones, later trials nearly alike; the drop is largest "
                  "at low and mid pressures";
    e.history = true;
    e.params = {{"r", "1", 1.1, 20.0, 5.0, 3.0, true}, {"m_MPa", "MPa", 1e-3, 0.1, 0.01, 0.01, true}};
    e.sets = [e](const Scene& s, const std::vector<double>& v) {
      require_count(e, v);  // beta stays at the scene's value
      return per_soft_material(s, {{"mullins.enabled", "true"}, {"mullins.r", fmt(v[0])}, {"mullins.m_MPa", fmt(v[1])}});
    };
    c.push_back(e);
  }
  {
    CandidateEffect e;
    e.name = "fatigue";
    e.description = "progressive fatigue damage of the most strained silicone, growing with time under load";
    e.signature = "angle grows from trial to trial without settling, fastest at the highest pressures";
    e.history = true;
    e.params = {{"W_th_MPa", "MPa", 0.003, 0.1, 0.03, 0.02, true}, {"tau_s", "s", 100.0, 1e5, 5000.0, 2000.0, true}};
    e.sets = [e](const Scene& s, const std::vector<double>& v) {
      require_count(e, v);  // q and driver stay at the scene's values
      return per_soft_material(s, {{"fatigue.enabled", "true"}, {"fatigue.W_th_MPa", fmt(v[0])}, {"fatigue.tau_s", fmt(v[1])}});
    };
    c.push_back(e);
  }
  {
    CandidateEffect e;
    e.name = "pressure_lag";
    e.description = "the chamber pressure lags the inlet sensor (tubing and valve resistance), first order";
    e.signature = "angle lags the pressure steps by a fraction of a second; plateau angles unaffected";
    e.history = true;
    // tau in [0.02, 3] s: from a short wide tube to a long thin one at these flows; truth 0.5 s.
    e.params = {{"tau_s", "s", 0.02, 3.0, 0.1, 0.5, true}};
    e.sets = [e](const Scene&, const std::vector<double>& v) {
      require_count(e, v);
      return std::vector<std::string>{"load.pressure_lag_s=" + fmt(v[0])};
    };
    c.push_back(e);
  }
  {
    CandidateEffect e;
    e.name = "gravity";
    e.description = "the actuator's own weight, with the rig at angle phi: 0 = hanging tip-down, 90 = horizontal";
    e.signature = "an angle offset at zero pressure that changes with pressure as the tip swings, identical in every trial";
    // The rig angle phi is set in the actuator's own angle frame (gravity.rig_angle_deg, applied by
    // scenes/angle_frame.cpp): 0 = g along the actuator away from the clamp (the tip hangs below it),
    // 90 deg = g towards the bend direction (horizontal, fabric side down), 180 = tip-up. So a deck in
    // any orientation (its frame taken from the mesh) is hung the same way; for the built-in actuator
    // (y along it, fabric at -z) g = [0, 9.81 cos(phi), -9.81 sin(phi)], and the half model (x >= 0)
    // keeps its symmetry since g_x = 0. A gravity vector of the scene itself is replaced.
    e.params = {{"rig_angle_deg", "deg", 0.0, 180.0, 90.0, 90.0, false}};
    e.interpolation = ParameterInterpolation::rig_angle;
    e.sets = [e](const Scene&, const std::vector<double>& v) {
      require_count(e, v);
      return std::vector<std::string>{"gravity.g_m_s2=[0.0, 0.0, 0.0]", "gravity.rig_angle_deg=" + fmt(v[0])};
    };
    c.push_back(e);
  }
  return c;
}

CandidateEffect registered_candidate(const MaterialEffect& fx) {
  CandidateEffect e;
  e.name = fx.name;
  e.description = fx.doc;
  e.signature = "the signature of the registered material effect '" + fx.name + "' (" + fx.doc + ")";
  e.history = fx.history;
  for (const EffectParameter& p : fx.params)
    e.params.push_back({p.name, p.unit, p.lo, p.hi, p.default_value, p.default_value, p.log});
  const std::string name = fx.name;
  e.sets = [e, name](const Scene& s, const std::vector<double>& v) {
    require_count(e, v);
    std::vector<std::pair<std::string, std::string>> kv{{name + ".enabled", "true"}};
    for (std::size_t i = 0; i < v.size(); ++i) kv.emplace_back(name + "." + e.params[i].name, fmt(v[i]));
    return per_soft_material(s, kv);
  };
  return e;
}

}  // namespace

std::vector<std::string> soft_materials(const Scene& s) {
  std::vector<std::string> out;
  for (int i = 0; i < s.array_size("parts"); ++i) {
    const std::string m = s.string("parts[" + std::to_string(i) + "].material");
    if (std::find(out.begin(), out.end(), m) != out.end()) continue;
    if (s.has("materials." + m + ".model") && s.string("materials." + m + ".model") == "linear_elastic") continue;
    out.push_back(m);
  }
  return out;
}

const std::vector<CandidateEffect>& candidate_effects() {
  // Rebuilt when the registry grew (effects registered after the first call); the old list stays
  // alive so references handed out earlier remain valid.
  static std::mutex mu;
  static std::vector<std::unique_ptr<std::vector<CandidateEffect>>> lists;
  static std::size_t registered = 0;
  std::lock_guard<std::mutex> lock(mu);
  const std::vector<const MaterialEffect*> fx = material_effects();
  if (lists.empty() || fx.size() != registered) {
    auto list = std::make_unique<std::vector<CandidateEffect>>(builtin_candidates());
    for (const MaterialEffect* f : fx)
      if (!is_builtin_effect(f->name)) list->push_back(registered_candidate(*f));
    lists.push_back(std::move(list));
    registered = fx.size();
  }
  return *lists.back();
}

const CandidateEffect& candidate_effect(const std::string& name) {
  const std::vector<CandidateEffect>& all = candidate_effects();
  for (const CandidateEffect& c : all)
    if (c.name == name) return c;
  std::string valid;
  for (const CandidateEffect& c : all) valid += (valid.empty() ? "" : ", ") + c.name;
  throw InputError("unknown candidate effect '" + name + "'; valid: " + valid);
}

}  // namespace pneufem
