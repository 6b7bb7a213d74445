#pragma once
// A stiffness scale s > 0 on any material: psi_s = s psi, P_s = s P, A_s = s A (isochoric and
// volumetric parts alike, so every modulus - shear and bulk - is multiplied by s).
//
// Why a decorator and not a per-law factor: every law (Yeoh, Ogden, St Venant-Kirchhoff, ...) gets
// the same exact scaling from one small class, and the factor is 1 multiplication per stress entry.
// Exact property used by the tests: for a hyperelastic body under pressure p alone, the scaled body
// at pressure s p has the unscaled body's equilibrium at p (the residual s f_int(u) - s p g(u) = 0).
//
// Placement (scenes/scene_materials.cpp): the scale wraps the hyperelastic BASE and sits inside the
// inelastic decorators, mullins(scaled(yeoh)) etc. Their energy thresholds (Mullins m, fatigue
// W_th) therefore act on the scaled energy: a softer material reaches a fixed threshold later, as a
// physically softer silicone would. The state layout is the base's (ScaledMaterial owns no state).
#include "materials/material.h"

namespace pneufem {

class ScaledMaterial final : public Material {
 public:
  /// Throws InputError unless base is non-null and scale is finite and > 0.
  ScaledMaterial(MaterialPtr base, double scale);

  std::string name() const override;
  int state_size() const override { return base_->state_size(); }
  void init_state(std::span<double> state) const override { base_->init_state(state); }
  void evaluate(std::span<const Mat3> F, const TimeStep& step, std::span<const double> state_old,
                std::span<double> state_new, std::span<PointResponse> out, bool tangent) const override;
  void stress(StressBatch& b, const TimeStep& step, std::span<const double> state_old,
              std::span<double> state_new) const override;
  PointFields fields(std::span<const double> state) const override { return base_->fields(state); }
  double initial_shear_modulus() const override { return scale_ * base_->initial_shear_modulus(); }
  double initial_bulk_modulus() const override { return scale_ * base_->initial_bulk_modulus(); }
  bool is_split() const override { return base_->is_split(); }
  /// Forwarded to the base.
  LinearDrive linear_drive() const override { return base_->linear_drive(); }
  void linear_drive_value(std::span<const double> state, std::span<double> out) const override {
    base_->linear_drive_value(state, out);
  }
  bool jumps_cycles() const override { return base_->jumps_cycles(); }
  void jump_cycles(std::span<const double> before, std::span<const double> after, double cycles,
                   std::span<double> out) const override {
    base_->jump_cycles(before, after, cycles, out);
  }
  double jump_error(std::span<const double> predicted, std::span<const double> computed) const override {
    return base_->jump_error(predicted, computed);
  }
  NonlocalSpec nonlocal() const override { return base_->nonlocal(); }
  double nonlocal_driver(const Mat3& F, std::span<const double> state) const override {
    return base_->nonlocal_driver(F, state);
  }
  void set_nonlocal_driver(std::span<double> state, double local, double average) const override {
    base_->set_nonlocal_driver(state, local, average);
  }

  double scale() const { return scale_; }
  const MaterialPtr& base() const { return base_; }

 private:
  MaterialPtr base_;
  double scale_;
};

/// `base` itself when scale == 1 (bit-for-bit the unscaled law), else a ScaledMaterial.
MaterialPtr scale_material(MaterialPtr base, double scale);

}  // namespace pneufem
