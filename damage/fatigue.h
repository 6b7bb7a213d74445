#pragma once
// Progressive (cyclic, time-driven) fatigue damage of the isochoric response: a rate law in the
// spirit of FEBio's reactive fatigue material (FEBioMech, FEReactiveFatigue: bonds break at a rate
// set by a damage criterion and the surviving fraction carries the load), reduced here to one
// irreversible scalar d in [0, 1):
//
//   dd/dt = (1/tau) g (1 - d)^n,     g = < X / X_th - 1 >^q,   <x> = max(x, 0),
//   P_iso = (1 - d) P0_iso,          psi_iso = (1 - d) W0        (strain equivalence, Lemaitre),
//
// with the driver X either the effective (undamaged) isochoric energy W0 = psi_iso of the base
// (threshold W_th) or the largest principal stretch lambda = sqrt(lambda_max(C)) (threshold
// lambda_th > 1). Below the threshold d does not change at all; above it, a higher driver breaks
// faster. q > 1 makes g, and with it the consistent tangent, continuous at the threshold. The stretch
// driver solves the eigenvalue problem of C only where a cheap bound on lambda_max(C) does not already
// put lambda below lambda_th (g = 0 there either way; fatigue.cpp, stretch_surely_below).
//
// The integrity exponent n >= 1 sets how growth slows as damage accumulates. n = 1 is first-order
// kinetics (a constant overload halves the integrity every tau ln2 / g). n > 1 saturates: the rate
// falls like (1 - d)^n, so already-damaged points damage ever more slowly and damage spreads to
// neighbours instead of running away at the hot spots (a structure softens, its stretch at a given
// pressure rises, and with n = 1 that feedback makes the damage, and the error it causes, accelerate
// trial after trial). It is the damage-dependent rate of continuum fatigue laws written in the
// remaining integrity: only the still-intact fraction can break, and it breaks ever more slowly.
//
// Time integration over the physical increment dt (TimeStep::dt_s) is backward Euler with g at the
// end of the increment. With the integrity s = 1 - d and a = dt g / tau it reads
//   s_new + a s_new^n = s_old,
// which for n = 1 has the closed form s_new = s_old / (1 + a) and for n > 1 is solved by scalar Newton
// (the left side is increasing and convex in s > 0, so Newton from s_old converges monotonically from
// above). s_new is in (0, s_old]: damage never decreases and never reaches 1 (first-order accurate;
// the exact solution at constant g is s = s_old exp(-a) for n = 1 and
// s = (s_old^(1-n) + (n-1) a)^(-1/(n-1)) for n > 1). The integrity is what is stored, which keeps it
// strictly positive (no rounding of d up to 1).
//
// Consistent tangent (the trial s_new depends on F through the driver):
//   A_iso = s_new A0_iso + P0_iso (x) d s_new/dF,
//   d s_new/dF = -s_new^n / (1 + n a s_new^(n-1)) (dt/tau) g'(X) dX/dF,
//   dX/dF = P0_iso (energy; needs a base whose psi_iso is a potential of P_iso) or
//   dX/dF = F n (x) n / lambda (stretch; n the unit eigenvector of C of its largest eigenvalue).
// With dt = 0 (a static solve in pseudo time) the law is the elastic base scaled by the committed 1 - d.
//
// Failure: at d = d_fail the point has failed (fields().failed) and its damage stops there: it keeps
// the residual stiffness fraction 1 - d_fail, like the "maximum degradation" of Abaqus's damage
// evolution. Why not let d -> 1: a failed wall with vanishing stiffness makes the structure singular,
// the static solve stops at the first torn wall, and nothing after it (the angle of a torn actuator,
// the FEM check of fitted constants in diagnose --refine) can be computed. Runs that stop for another
// reason name the failed points (engine/quasi_static.h); the fields carry them for ParaView.
//
// psi_iso = (1 - d_new) W0 is the stored energy of the damaged solid. It is not a potential of P_iso
// within an increment with dt > 0 (d_new depends on F), only at dt = 0.
//
// Non-local driver (nonlocal_radius_m > 0; engine/nonlocal.h). X is replaced by rho X, where rho =
// X_bar / X is the ratio of the averaged to the local driver at the last committed state (kept in the
// state; 1 when the local driver is ~0, e.g. an unloaded energy driver). This is the integral non-local
// model with the spatial averaging lagged by one physical step (an operator split): the law stays
// local and implicit within a step, with the consistent tangent of rho X, and it is the non-local
// model when the driver's spatial shape changes little over a step (exact for proportional
// loading), which the physical step control keeps so. Where the driver is singular (a re-entrant
// corner) rho < 1 caps it at the average over the radius, so damage no longer concentrates in the
// one element at the corner, whose size would then set the result.
//
// State per point: [1 - d] (local) or [1 - d, rho] (non-local).
#include <string>

#include "damage/decorator.h"
#include "materials/material.h"

namespace pneufem {

enum class FatigueDriver {
  energy,                 ///< X = W0 (base psi_iso, J/m^3), threshold W_th_Pa
  max_principal_stretch,  ///< X = sqrt(lambda_max(C)), threshold lambda_th
};

/// W_th_Pa > 0 (threshold energy density, J/m^3 = Pa), tau_s > 0 (s, time scale of the damage rate),
/// q >= 1 (exponent), d_fail in (0, 1) (failure criterion), n >= 1 (integrity exponent; 1 = the
/// first-order law). With the stretch driver lambda_th > 1 replaces W_th_Pa (which is then ignored).
struct FatigueParams {
  double W_th_Pa = 0.0;
  double tau_s = 0.0;
  double q = 2.0;
  double d_fail = 0.9;
  FatigueDriver driver = FatigueDriver::energy;
  double lambda_th = 0.0;
  double n = 1.0;
  double nonlocal_radius_m = 0.0;  ///< > 0: the driver is averaged over this radius (m); 0 = local
};

/// Driver excess and damage rate at one point, dd/dt = (g / tau) (1 - d)^n.
struct FatigueRate {
  double X = 0.0;       ///< driver value (J/m^3 or dimensionless stretch)
  double g = 0.0;       ///< <X/X_th - 1>^q
  double dg_dX = 0.0;   ///< dg/dX
};
FatigueRate fatigue_rate(double X, const FatigueParams& p);

class FatigueDamage final : public MaterialDecorator {
 public:
  /// Throws InputError for bad parameters or a base that is not split or whose energy is not a
  /// potential of its stress (a viscoelastic base: wrap viscoelastic around fatigue instead).
  FatigueDamage(MaterialPtr base, const FatigueParams& p);

  bool isochoric_energy_is_potential() const override { return false; }
  /// Own state (own_state_size()): [1 - d] or, with a non-local driver, [1 - d, rho].
  void init_state(std::span<double> state) const override;
  void evaluate(std::span<const Mat3> F, const TimeStep& step, std::span<const double> state_old,
                std::span<double> state_new, std::span<PointResponse> out, bool tangent) const override;
  /// Force only: the base's batched stress, then the damage lane by lane (evaluate's bits).
  void stress(StressBatch& b, const TimeStep& step, std::span<const double> state_old,
              std::span<double> state_new) const override;
  /// damage = 1 - (1 - d)(1 - base damage); failed = d >= d_fail or the base failed; the rest from the base.
  PointFields fields(std::span<const double> state) const override;
  /// Cycle jumping (Material::jump_cycles). At a constant driver the exact integrity is
  /// s(t)^(1-n) = s(0)^(1-n) + (n - 1) g t / tau (n > 1) and -ln s(t) = -ln s(0) + g t / tau (n = 1):
  /// z = s^(1-n) resp. -ln s grows linearly in time, so over cycles that repeat the driver's history
  /// it grows linearly per cycle, z_(k+N) = z_k + N (z_k - z_(k-1)) (the cycle-jump variable of
  /// Van Paepegem et al. 2001 for a damage rate of this form). The result is clipped to damage
  /// never decreasing and never passing d_fail; rho (non-local) is the last cycle's. jump_error:
  /// |s_predicted - s_computed| (the stiffness fraction is s times the base's), or the base's if larger.
  bool jumps_cycles() const override { return base()->jumps_cycles(); }
  void jump_cycles(std::span<const double> before, std::span<const double> after, double cycles,
                   std::span<double> out) const override;
  double jump_error(std::span<const double> predicted, std::span<const double> computed) const override;
  /// With nonlocal_radius_m > 0: kind "fatigue:energy" or "fatigue:stretch"; the driver X at the
  /// committed state; rho = average / X stored for the next increments. Local: forwarded to the base.
  NonlocalSpec nonlocal() const override;
  double nonlocal_driver(const Mat3& F, std::span<const double> state) const override;
  void set_nonlocal_driver(std::span<double> state, double local, double average) const override;

  const FatigueParams& params() const { return p_; }
  /// Damage d of this layer alone from a point's state block.
  static double damage(std::span<const double> state) { return 1.0 - state[0]; }

 private:
  FatigueParams p_;
};

}  // namespace pneufem
