#pragma once
// Explicit central-difference time integration (real dynamics) on the lumped mass of the
// Assembler. Dynamic relaxation (quasi-static equilibrium with fictitious masses) is in
// engine/relaxation.h.
//
// Central difference with mass-proportional damping (Belytschko, Liu & Moran 2014, box 6.1):
//   v^{n+1/2} = [(1 - a dt/2) v^{n-1/2} + dt M^{-1} (f_ext^n - f_int^n)] / (1 + a dt/2)
//   u^{n+1}   = u^n + dt v^{n+1/2}
// Stable step: dt <= 2/omega_max; omega_max^2 <= max_i sum_j |K_ij| / m_i (Gershgorin applied to
// M^{-1} K, similar to the symmetric M^{-1/2} K M^{-1/2}), with K the current tangent, so the
// bound holds for the nonlinear material and the follower load at the state it is evaluated.
// Selective mass scaling raises only the masses of nodes that would force dt below the target
// (the stiff fabric layer), and the added mass is reported.
#include <functional>
#include <vector>

#include <Eigen/Core>

#include "engine/assembly.h"

namespace pneufem {

struct ExplicitOptions {
  double dt_safety = 0.8;          ///< fraction of the Gershgorin stable step used
  double target_dt_s = 0.0;        ///< > 0: mass-scale nodes so the stable step is >= this
  double damping_alpha_1_s = 0.0;  ///< mass-proportional damping coefficient a (1/s)
  /// Adaptive damping for quasi-static runs: a = 2 omega with omega^2 the Rayleigh quotient of
  /// the current motion, du.(f_int(u+du) - f_int(u)) / du.M du (Underwood 1983; Papadrakakis 1981),
  /// i.e. critical damping of the mode the structure is moving in. Overrides damping_alpha_1_s.
  bool adaptive_damping = false;
  int stability_interval = 200;    ///< steps between stable-step re-estimates
  double fixed_dt_s = 0.0;         ///< > 0: use this step instead of the estimate (expert use)
};

struct EnergyBalance {
  double kinetic_J = 0.0;
  double internal_J = 0.0;
  double external_work_J = 0.0;
  double damping_J = 0.0;
  /// |W_ext - KE - IE - W_damp| / max(W_ext, KE, IE, tiny): should stay small (< 1e-2).
  double relative_error() const;
};

struct ExplicitStats {
  long steps = 0;
  double dt_s = 0.0;
  double dt_min_s = 0.0;
  double added_mass_kg = 0.0;  ///< mass added by selective mass scaling
  double physical_mass_kg = 0.0;
  long stability_estimates = 0;
};

class ExplicitIntegrator {
 public:
  using PressureFn = std::function<double(double /*time_s*/)>;
  ExplicitIntegrator(const Assembler& assembler, ExplicitOptions options);

  /// Integrates from the current time to t_end. `observer(t, u, v)` is called every
  /// `observe_every` steps and at the end. Throws PhysicsError on inversion / instability.
  void run(double t_end, const PressureFn& pressure, int observe_every,
           const std::function<void(double, const Eigen::VectorXd&, const Eigen::VectorXd&)>& observer);

  /// Estimates the stable step at the current state and applies mass scaling when configured.
  double estimate_stable_dt();

  /// How much the mass added by selective mass scaling changes the answer now: the force the
  /// added mass takes, relative to the loads, ||(dm_i / m_i) (f_ext - f_int)_i|| / max(||f_ext||,
  /// ||f_int||) over the free dofs, after the last run() (0 before any step or without scaling).
  /// Why this measure: with M a + C v = f_ext - f_int and mass-proportional damping C = a M, the
  /// added mass dm takes the share dm/m of every node's out-of-balance force, inertia and damping
  /// alike; the run with the physical masses would have applied that force to the structure, so
  /// the displacement it withholds is K^-1 of it, and its size relative to the loads is (for a
  /// response near linear) the relative error of the deformed shape. A quasi-static run (slow,
  /// damped: f_ext ~ f_int) gives ~0 however much mass was added; a dynamic one whose moving nodes
  /// were scaled gives the fraction of its inertia that is fictitious.
  double added_mass_force_share() const;

  double time() const { return t_; }
  Eigen::VectorXd& u() { return u_; }
  Eigen::VectorXd& v() { return v_; }
  std::vector<double>& state() { return state_; }
  const EnergyBalance& energy() const { return energy_; }
  const ExplicitStats& stats() const { return stats_; }
  const Eigen::VectorXd& nodal_mass() const { return m_; }

 private:
  Eigen::VectorXd external(double t, const PressureFn& pressure) const;

  const Assembler& asm_;
  ExplicitOptions opt_;
  Eigen::VectorXd m_;  ///< nodal (possibly scaled) masses, one per node
  Eigen::VectorXd u_, v_;
  Eigen::VectorXd f_int_, f_ext_;  ///< the forces at the end of the last run() (empty before)
  std::vector<double> state_, trial_;
  double t_ = 0.0;
  double dt_ = 0.0;
  SparseMatrix K_;
  EnergyBalance energy_;
  ExplicitStats stats_;
};

}  // namespace pneufem
