// The table of scenes/key_limits.h: the range of each numeric scene key and why.
#include "scenes/key_limits.h"

#include "core/number_text.h"

namespace pneufem {

namespace {

// Shared bounds, each with its reason.
//   lengths: a pneu-net is centimetres long; a metre in a key written in mm is a unit mistake, and the
//   mesher's cell limit (scenes/pneunet.cpp) stops far smaller meshes.
constexpr double kMaxLength_mm = 1000.0;
const char* kLengthWhy = "a pneu-net is centimetres long; a metre in a key in mm is a unit mistake";
//   times: the protocols pneufem runs last minutes to hours; 10^7 s (116 days) can only be a mistake,
//   and every step of it would be a solver increment.
constexpr double kMaxTime_s = 1e7;
const char* kTimeWhy = "protocols last minutes to hours; 1e7 s is 116 days";
//   pressures: a soft actuator bursts far below 10 MPa (the paper's protocol reaches 45 kPa).
constexpr double kMaxPressure_kPa = 1e4;
const char* kPressureWhy = "a silicone actuator bursts far below 10 MPa (the paper's protocol: 45 kPa)";
//   moduli: stiffer than 10^6 MPa (1000 GPa, above diamond) is no material.
constexpr double kMaxModulus_MPa = 1e6;
const char* kModulusWhy = "1e6 MPa is stiffer than diamond";
//   scales of a stiffness: 10^6 either way would make the tangent lose 6 of its 16 digits.
constexpr double kMaxScale = 1e6;

KeyLimit closed(const std::string& key, double lo, double hi, const std::string& why) {
  return KeyLimit{key, lo, hi, false, false, why};
}
KeyLimit positive(const std::string& key, double hi, const std::string& why) {
  return KeyLimit{key, 0.0, hi, true, false, why};
}

std::vector<KeyLimit> make_limits() {
  std::vector<KeyLimit> l;
  // [geometry]
  for (const char* k : {"width_mm", "base_thickness_mm", "body_height_mm", "chamber_length_mm", "interior_wall_mm",
                        "side_wall_mm", "roof_mm", "end_cap_mm", "channel_width_mm", "channel_height_mm",
                        "fabric_thickness_mm"})
    l.push_back(positive(std::string("geometry.") + k, kMaxLength_mm, kLengthWhy));
  l.push_back(closed("geometry.fabric_z0_mm", 0.0, kMaxLength_mm, kLengthWhy));
  // Pneu-nets have a handful to a few dozen chambers; 1000 of the default 8 mm pitch is 8 m long.
  l.push_back(closed("geometry.chambers", 1, 1000, "pneu-nets have a few dozen chambers; 1000 of the default pitch is 8 m"));
  // [mesh]
  l.push_back(positive("mesh.h_mm", kMaxLength_mm, kLengthWhy));
  l.push_back(closed("mesh.h_z_mm", 0.0, kMaxLength_mm, std::string("0 = same as mesh.h_mm; ") + kLengthWhy));
  // Elements through a layer: a few resolve it; 100 would multiply the mesh through it a hundredfold.
  l.push_back(closed("mesh.fabric_layers", 1, 100, "a few elements resolve a layer; 100 is a mistake"));
  l.push_back(closed("mesh.wall_layers", 0, 100, "0 = from mesh.h_mm; a few elements resolve a wall; 100 is a mistake"));
  l.push_back(closed("mesh.wall_cells", 0, 8, "0 = no refinement; two or three cells resolve a wall; each more multiplies the cells there"));
  // mesh.source = "stl": points and z ranges in the model's frame (mm).
  for (const char* k : {"mesh.cavity_inlet_mm", "mesh.fixed_point_mm", "mesh.fabric_slab_mm"})
    l.push_back(closed(k, -kMaxLength_mm, kMaxLength_mm, kLengthWhy));
  // [materials.*]
  l.push_back(positive("materials.*.C10_MPa", kMaxModulus_MPa, kModulusWhy));
  for (const char* k : {"C20_MPa", "C30_MPa", "C01_MPa"})
    l.push_back(closed(std::string("materials.*.") + k, -kMaxModulus_MPa, kMaxModulus_MPa, kModulusWhy));
  l.push_back(closed("materials.*.mu_MPa", -kMaxModulus_MPa, kMaxModulus_MPa, kModulusWhy));
  // Ogden exponents: the law raises stretches to alpha; at |alpha| = 100 a stretch of 1000 is 1e300,
  // the end of a double (fitted rubbers have |alpha| < 30).
  l.push_back(closed("materials.*.alpha", -100.0, 100.0, "stretch^alpha: at 100 a stretch of 1000 is 1e300; fits are < 30"));
  l.push_back(positive("materials.*.E_MPa", kMaxModulus_MPa, kModulusWhy));
  l.push_back(KeyLimit{"materials.*.nu", -1.0, 0.5, true, true, "a stable isotropic solid has -1 < nu < 0.5"});
  // K0/mu0: 1 is nu = 0.125, more compressible than any elastomer; 1e5 is nu = 0.499995, where the
  // bulk term dominates the tangent by that factor and Newton loses its digits (silicone: 100-1000).
  l.push_back(closed("materials.*.K_over_mu", 1.0, 1e5,
                     "1 is nu = 0.125 (no elastomer); 1e5 is nu = 0.499995, where the tangent loses 5 digits to the bulk "
                     "term; silicone: 100-1000"));
  // Osmium, the densest element, is 22,590 kg/m^3.
  l.push_back(positive("materials.*.density_kg_m3", 1e5, "no material is denser than 22,590 kg/m3 (osmium)"));
  l.push_back(positive("materials.*.stiffness_scale", kMaxScale, "1e6 would cost the tangent 6 of its 16 digits"));
  l.push_back(positive("regions.*.stiffness_scale", kMaxScale, "1e6 would cost the tangent 6 of its 16 digits"));
  // The built-in effects' list keys (their scalars are checked by the decorators, damage/).
  // gamma = g / (1 - sum g) with Abaqus' g: any gamma >= 0 is a valid long-term convention (sum gamma >= 1
  // is fine here; it is sum g that must stay < 1); 1000 is g = 0.999, a long-term modulus that is
  // numerically zero beside the instantaneous one.
  l.push_back(closed("materials.*.viscoelastic.gamma", 0.0, 1000.0,
                     "gamma = g/(1 - sum g); 1000 is Abaqus g = 0.999, a long-term modulus of nearly zero"));
  l.push_back(positive("materials.*.viscoelastic.tau_s", kMaxTime_s, kTimeWhy));
  // [load]
  l.push_back(closed("load.max_kPa", 0.0, kMaxPressure_kPa, kPressureWhy));
  l.push_back(positive("load.step_kPa", kMaxPressure_kPa, kPressureWhy));
  l.push_back(positive("load.hold_s", kMaxTime_s, kTimeWhy));
  l.push_back(closed("load.ramp_s", 0.0, kMaxTime_s, kTimeWhy));
  // Trials: the paper runs 10; 10^5 of the default staircase (20 reports each) would already make
  // twice the report limit of engine/load_history.h, which bounds the rest.
  l.push_back(closed("load.trials", 1, 100000, "the paper runs 10; 1e5 default trials are 2e6 reports, over the limit"));
  l.push_back(closed("load.mark_s", 0.0, kMaxTime_s, kTimeWhy));
  l.push_back(closed("load.rest_s", 0.0, kMaxTime_s, std::string("0 = no rest; ") + kTimeWhy));
  l.push_back(closed("load.output_every_s", 0.0, kMaxTime_s, std::string("0 = only the mark and the end; ") + kTimeWhy));
  l.push_back(closed("load.pressure_lag_s", 0.0, kMaxTime_s, std::string("0 = no lag; ") + kTimeWhy));
  l.push_back(closed("load.pressure_lag2_s", 0.0, kMaxTime_s, std::string("0 = a first-order lag; ") + kTimeWhy));
  // [gravity], [angle]: 1000 g is no rig on earth.
  l.push_back(closed("gravity.g_m_s2", -1e4, 1e4, "1000 g is no rig on earth"));
  l.push_back(closed("gravity.rig_angle_deg", -360.0, 180.0, "< 0 = off (g_m_s2 applies); else degrees from the axis"));
  // [solver]
  l.push_back(KeyLimit{"solver.rel_tol", 0.0, 1.0, true, true, "a relative residual tolerance"});
  l.push_back(closed("solver.max_iterations", 1, 10000, "Newton converges in tens of iterations or not at all"));
  l.push_back(closed("solver.stiff_relaxation_steps", 0, 10000, "0 = off; a few steps are enough"));
  l.push_back(positive("solver.max_increment_kPa", kMaxPressure_kPa, kPressureWhy));
  l.push_back(positive("solver.min_increment_kPa", kMaxPressure_kPa, kPressureWhy));
  // 2e9 fits an int; dynamic relaxation needs ~10^5-10^6 iterations on the default mesh.
  l.push_back(closed("solver.relaxation_max_iterations", 1, 2000000000, "an iteration count that fits an int"));
  l.push_back(KeyLimit{"solver.time_tol", 0.0, 1.0, true, true, "a change of damage or viscous strain per step"});
  l.push_back(positive("solver.min_dt_s", kMaxTime_s, kTimeWhy));
  l.push_back(positive("solver.max_dt_s", kMaxTime_s, kTimeWhy));
  l.push_back(closed("solver.max_segment_steps", 1, 100000000, "1e8 steps of one segment is a stall"));
  l.push_back(KeyLimit{"solver.cycle_jump_tol", 0.0, 0.1, true, false,
                       "a relative error of the compliance; 0.1 would let a jump be 10 % wrong"});
  l.push_back(KeyLimit{"solver.cycle_jump_change", 0.0, 0.5, true, false,
                       "a relative compliance change; half of it in one jump is no extrapolation"});
  l.push_back(closed("solver.krylov_max_iterations", 0, 10000, "0 = off; tens of CG steps are enough"));
  l.push_back(KeyLimit{"solver.dt_safety", 0.0, 1.0, true, false, "a fraction of the stable time step"});
  l.push_back(closed("solver.target_dt_s", 0.0, 1.0, "0 = no mass scaling; explicit steps are microseconds"));
  l.push_back(closed("solver.damping_1_s", 0.0, 1e6, "0 = undamped; 1e6/s damps a microsecond"));
  l.push_back(positive("solver.time_scale", 1e6, "1e6 times faster turns minutes into microseconds"));
  l.push_back(closed("solver.reduced_modes", 1, 1000, "the reduced model uses tens of modes"));
  l.push_back(KeyLimit{"solver.reduced_ecsw_tol", 0.0, 1.0, true, true, "a relative error"});
  l.push_back(closed("solver.reduced_ecsw_blocks", 0, 10000, "0 = one block per softening cluster; tens of blocks are plenty"));
  l.push_back(closed("solver.reduced_softened_levels", 0, 20, "each level is a nonlinear solve per field and mode sample"));
  l.push_back(positive("solver.reduced_check_deg", 360.0, "an angle error in degrees"));
  l.push_back(closed("solver.reduced_enrich_rounds", 0, 10, "each round is a basis build, a reduced run and a replay"));
  return l;
}

bool matches(const std::string& pattern, const std::string& key) {
  std::size_t p = 0, k = 0;
  while (p < pattern.size() && k < key.size()) {
    if (pattern[p] == '*') {  // one name: up to the next dot of the key
      const std::size_t dot = key.find('.', k);
      if (dot == std::string::npos) return false;
      k = dot;
      ++p;
    } else if (pattern[p++] != key[k++]) {
      return false;
    }
  }
  return p == pattern.size() && k == key.size();
}

}  // namespace

bool KeyLimit::contains(double v) const {
  const bool above = lo_open ? v > lo : v >= lo;
  const bool below = hi_open ? v < hi : v <= hi;
  return above && below;
}

std::string KeyLimit::range_text() const {
  std::string s = (lo_open ? "> " : ">= ") + short_num(lo);
  return s + (hi_open ? " and < " : " and <= ") + short_num(hi);
}

const std::vector<KeyLimit>& key_limits() {
  static const std::vector<KeyLimit> limits = make_limits();
  return limits;
}

const KeyLimit* find_key_limit(const std::string& key) {
  for (const KeyLimit& l : key_limits())
    if (matches(l.pattern, key)) return &l;
  return nullptr;
}

}  // namespace pneufem
