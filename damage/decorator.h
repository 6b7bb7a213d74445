#pragma once
// Plumbing shared by the inelastic decorators of damage/ (Mullins, fatigue, viscoelasticity).
//
// A decorator wraps a base Material and owns a few doubles of history per
// quadrature point. The state block of one point is laid out as
//     [ decorator's own state (own doubles) | base's state (base->state_size() doubles) ]
// so decorators nest: viscoelastic(fatigue(mullins(yeoh))) holds
//     [ visco | fatigue | mullins | (yeoh: none) ]
// and each layer hands the tail of the block to its base untouched. Points are consecutive blocks.
//
// Conventions every decorator follows:
//  * only the isochoric response (psi_iso, P_iso, A_iso) is modified; the volumetric part of the
//    base is passed through bit for bit;
//  * an EMPTY state_old means "the virgin state" (own history at its initial values; the base gets
//    an empty span too), so a decorated law can be evaluated like an elastic one;
//  * an empty state_new means "do not write the trial state" (the engine's energy-only passes).
//
// The forwarding that a layer does not change lives once, in MaterialDecorator below (Mullins,
// FatigueDamage, UniformFatigue and Viscoelastic derive from it): the name "effect(base)", the state
// size own + base, the small-strain moduli, the linear-drive history and the non-local driver (each
// handed the base's slice of the block), and the base itself. A layer overrides only what it
// changes (FatigueDamage its non-local driver; Viscoelastic the shear modulus, its instantaneous one,
// and the linear drive, its own branches'). Cycle jumping is deliberately NOT forwarded: a layer
// that does not say how its own history extrapolates must refuse (Material's default for a law with
// state), so Mullins, FatigueDamage and Viscoelastic override jumps_cycles/jump_cycles/jump_error and
// UniformFatigue does not jump. A layer whose own size depends on its parameters (fatigue: 1 or 2,
// Viscoelastic: 6 (1 + terms)) computes it for the base class before checking them; a bad parameter
// then throws from its constructor, after the shared split-base check.
//
// evaluate() calls the base one point at a time (one virtual call per point and layer, since the
// base's slices are strided by the full block): the price of composability, paid where the tangent
// dominates anyway. The force-only stress() calls the base's stress() once for the whole batch
// (stress_base: the base's slices gathered into consecutive blocks on the stack), so nested layers and
// the structure-of-arrays kernels of the base laws are used, and then applies its own modification:
// Mullins and fatigue lane by lane through helpers shared with evaluate(), viscoelasticity in
// structure-of-arrays form with the operation order of evaluate()'s Eigen expressions; the bits are
// evaluate()'s either way (tests/damage, DecoratorBatch). The math is fixed-size and allocation-free,
// and nothing is mutable, so evaluations are safe under TBB.
#include <cassert>
#include <cmath>
#include <cstddef>
#include <initializer_list>
#include <utility>
#include <span>
#include <string>

#include "core/errors.h"
#include "core/number_text.h"
#include "materials/material.h"

namespace pneufem {

/// A Material wrapping a split base law with `own` doubles of history per point in front of the
/// base's (the layout above). Forwards what the layer does not change; the constructor throws
/// InputError unless the base is a non-null split law (detail::require_split_base).
class MaterialDecorator : public Material {
 public:
  /// "effect(base)", e.g. "mullins(yeoh)".
  std::string name() const override { return effect_ + "(" + base_->name() + ")"; }
  /// The layer's own doubles per point, at the head of its block.
  int own_state_size() const { return own_; }
  int state_size() const override { return own_ + base_->state_size(); }
  double initial_shear_modulus() const override { return base_->initial_shear_modulus(); }
  double initial_bulk_modulus() const override { return base_->initial_bulk_modulus(); }
  /// Forwarded to the base (its slice of the state).
  LinearDrive linear_drive() const override { return base_->linear_drive(); }
  void linear_drive_value(std::span<const double> state, std::span<double> out) const override {
    base_->linear_drive_value(base_state(state), out);
  }
  /// Forwarded to the base (its slice of the state): a fatigue law inside keeps its non-local driver.
  NonlocalSpec nonlocal() const override { return base_->nonlocal(); }
  double nonlocal_driver(const Mat3& F, std::span<const double> state) const override {
    return base_->nonlocal_driver(F, base_state(state));
  }
  void set_nonlocal_driver(std::span<double> state, double local, double average) const override {
    base_->set_nonlocal_driver(base_state(state), local, average);
  }
  const MaterialPtr& base() const { return base_; }

 protected:
  /// `effect` names the layer in name() and in the errors of its checks. Defined in decorator.cpp.
  MaterialDecorator(MaterialPtr base, std::string effect, int own);
  const std::string& effect() const { return effect_; }
  /// The base's slice of one point's block [own | base].
  std::span<const double> base_state(std::span<const double> state) const { return state.subspan(own_size()); }
  std::span<double> base_state(std::span<double> state) const { return state.subspan(own_size()); }
  std::size_t own_size() const { return static_cast<std::size_t>(own_); }

 private:
  MaterialPtr base_;
  std::string effect_;
  int own_;
};

}  // namespace pneufem

namespace pneufem::detail {

/// The four views of point q's state for a decorator with `own` doubles wrapping a base with `base`.
struct PointState {
  std::span<const double> own_old;  ///< empty = virgin
  std::span<double> own_new;        ///< empty = trial state not wanted
  std::span<const double> base_old;
  std::span<double> base_new;
};

inline PointState point_state(std::span<const double> state_old, std::span<double> state_new, std::size_t q,
                              std::size_t own, std::size_t base) {
  const std::size_t ss = own + base, o = q * ss;
  PointState p;
  if (!state_old.empty()) {
    assert(state_old.size() >= o + ss);
    p.own_old = state_old.subspan(o, own);
    p.base_old = state_old.subspan(o + own, base);
  }
  if (!state_new.empty()) {
    assert(state_new.size() >= o + ss);
    p.own_new = state_new.subspan(o, own);
    p.base_new = state_new.subspan(o + own, base);
  }
  return p;
}

/// Evaluates the base law at one point into `out` (the decorator then modifies the iso part).
inline void evaluate_base(const Material& base, const Mat3& F, const TimeStep& step, const PointState& ps,
                          PointResponse& out, bool tangent) {
  base.evaluate(std::span<const Mat3>(&F, 1), step, ps.base_old, ps.base_new, std::span<PointResponse>(&out, 1),
                tangent);
}

/// Force-only evaluation of the base on the whole batch (Material::stress) for a decorator with `own`
/// doubles per point: gathers the base's slices of the b.n state blocks [own | base] into consecutive
/// blocks (empty spans stay empty: virgin / no trial state), calls base.stress() and scatters the
/// base's trial slices back into state_new. Returns false, without calling the base, when the base's
/// state is larger than the stack buffers (kMaxBaseState doubles per point; deeper nestings than any
/// scene builds): the caller then takes the point-by-point path, Material::stress. Defined in decorator.cpp.
inline constexpr std::size_t kMaxBaseState = 32;
bool stress_base(const Material& base, StressBatch& b, const TimeStep& step, std::span<const double> state_old,
                 std::span<double> state_new, std::size_t own);

/// Throws InputError unless `base` is a non-null split (isochoric/volumetric) law.
inline void require_split_base(const MaterialPtr& base, const std::string& effect) {
  if (!base) throw InputError(effect + ": no base material given; wrap a hyperelastic law such as yeoh");
  if (!base->is_split())
    throw InputError(effect + ": cannot wrap '" + base->name() +
                     "': the effect only applies to split (isochoric/volumetric) laws such as yeoh");
}

/// Throws InputError unless d(base psi_iso)/dF = base P_iso at a fixed committed state, which the
/// energy-driven effects (mullins, fatigue) rely on for their consistent tangent. Fatigue (whose damage
/// grows within the increment) and viscoelastic (overstress) laws do not satisfy it, so they must be
/// applied outside: the canonical order is viscoelastic(fatigue(mullins(base))). Asks the base
/// (Material::isochoric_energy_is_potential), so this layer names no effect.
void require_potential_base(const MaterialPtr& base, const std::string& effect);

inline void require(bool ok, const std::string& effect, const std::string& msg) {
  if (!ok) throw InputError(effect + ": " + msg);
}

inline void require_finite(const std::string& effect,
                           std::initializer_list<std::pair<const char*, double>> values) {
  for (const auto& [key, v] : values)
    if (!std::isfinite(v)) throw InputError(effect + ": " + key + " must be a finite number, got " + short_num(v));
}

/// Combines two stiffness losses acting in series on the isochoric stress: the stiffness
/// fractions multiply, so damage = 1 - (1 - d_outer)(1 - d_inner).
inline double combine_damage(double d_outer, double d_inner) { return 1.0 - (1.0 - d_outer) * (1.0 - d_inner); }

/// (x)+ = max(x, 0), the Macaulay bracket.
inline double macaulay(double x) { return x > 0.0 ? x : 0.0; }

}  // namespace pneufem::detail
