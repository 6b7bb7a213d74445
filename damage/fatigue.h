#pragma once
// Progressive (cyclic, time-driven) fatigue damage of the isochoric response: a rate law in the
// spirit of FEBio's reactive fatigue material (FEBioMech, FEReactiveFatigue: bonds break at a rate
// set by a damage criterion and the surviving fraction carries the load), reduced here to one
// irreversible scalar d in [0, 1) with first-order kinetics:
//
//   dd/dt = (1/tau) g (1 - d),       g = < X / X_th - 1 >^q,   <x> = max(x, 0),
//   P_iso = (1 - d) P0_iso,          psi_iso = (1 - d) W0        (strain equivalence, Lemaitre),
//
// with the driver X either the effective (undamaged) isochoric energy W0 = psi_iso of the base
// (threshold W_th) or the largest principal stretch lambda = sqrt(lambda_max(C)) (threshold
// lambda_th > 1). Below the threshold d does not change at all; above it, a higher driver breaks
// faster. q > 1 makes g, and with it the consistent tangent, continuous at the threshold.
//
// Time integration over the physical increment dt (TimeStep::dt_s), backward Euler with g at the end
// of the increment, has the closed form (a = dt g / tau):
//   d_new = (d_old + a) / (1 + a),   i.e.   1 - d_new = (1 - d_old) / (1 + a),
// so d_new is in [d_old, 1): damage never decreases and never reaches 1 (first-order accurate; the
// exact solution at constant g is 1 - d = (1 - d_old) exp(-g dt / tau)). The integrity 1 - d is what
// is stored, which keeps it strictly positive (no rounding of d up to 1).
//
// Consistent tangent (the trial d_new depends on F through the driver):
//   A_iso = (1 - d_new) A0_iso - P0_iso (x) d d_new/dF,
//   d d_new/dF = (1 - d_new)/(1 + a) (dt/tau) g'(X) dX/dF,
//   dX/dF = P0_iso (energy; needs a base whose psi_iso is a potential of P_iso) or
//   dX/dF = F n (x) n / lambda (stretch; n the unit eigenvector of C of its largest eigenvalue).
// With dt = 0 (a static solve in pseudo time) the law is the elastic base scaled by the committed 1 - d.
//
// Failure: fields().failed once d >= d_fail. The point keeps the residual stiffness fraction 1 - d > 0,
// so stresses stay finite and nothing divides by zero; what failure means is the driver's decision.
//
// psi_iso = (1 - d_new) W0 is the stored energy of the damaged solid. It is not a potential of P_iso
// within an increment with dt > 0 (d_new depends on F), only at dt = 0.
//
// State per point: [1 - d].
#include <string>

#include "materials/material.h"

namespace pneufem {

enum class FatigueDriver {
  energy,                 ///< X = W0 (base psi_iso, J/m^3), threshold W_th_Pa
  max_principal_stretch,  ///< X = sqrt(lambda_max(C)), threshold lambda_th
};

/// W_th_Pa > 0 (threshold energy density, J/m^3 = Pa), tau_s > 0 (s, time scale of the damage rate),
/// q >= 1 (exponent), d_fail in (0, 1) (failure criterion). With the stretch driver lambda_th > 1
/// replaces W_th_Pa (which is then ignored).
struct FatigueParams {
  double W_th_Pa = 0.0;
  double tau_s = 0.0;
  double q = 2.0;
  double d_fail = 0.9;
  FatigueDriver driver = FatigueDriver::energy;
  double lambda_th = 0.0;
};

/// Driver excess and damage rate at one point, dd/dt = rate (1 - d) with rate = g / tau.
struct FatigueRate {
  double X = 0.0;       ///< driver value (J/m^3 or dimensionless stretch)
  double g = 0.0;       ///< <X/X_th - 1>^q
  double dg_dX = 0.0;   ///< dg/dX
};
FatigueRate fatigue_rate(double X, const FatigueParams& p);

class FatigueDamage final : public Material {
 public:
  static constexpr int kOwnState = 1;  ///< [1 - d]

  /// Throws InputError for bad parameters or a base that is not split or whose energy is not a
  /// potential of its stress (a viscoelastic base: wrap viscoelastic around fatigue instead).
  FatigueDamage(MaterialPtr base, const FatigueParams& p);

  std::string name() const override { return "fatigue(" + base_->name() + ")"; }
  int state_size() const override { return kOwnState + base_->state_size(); }
  void init_state(std::span<double> state) const override;
  void evaluate(std::span<const Mat3> F, const TimeStep& step, std::span<const double> state_old,
                std::span<double> state_new, std::span<PointResponse> out, bool tangent) const override;
  /// damage = 1 - (1 - d)(1 - base damage); failed = d >= d_fail or the base failed; the rest from the base.
  PointFields fields(std::span<const double> state) const override;
  double initial_shear_modulus() const override { return base_->initial_shear_modulus(); }
  double initial_bulk_modulus() const override { return base_->initial_bulk_modulus(); }

  const FatigueParams& params() const { return p_; }
  const MaterialPtr& base() const { return base_; }
  /// Damage d of this layer alone from a point's state block.
  static double damage(std::span<const double> state) { return 1.0 - state[0]; }

 private:
  MaterialPtr base_;
  FatigueParams p_;
};

}  // namespace pneufem
