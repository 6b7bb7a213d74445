#pragma once
// Dynamic relaxation: static equilibrium R(u) = 0 reached by pseudo-dynamics with fictitious
// masses and kinetic damping, the alternative to Newton of the quasi-static driver
// (solver.method = "relaxation", engine/quasi_static.h).
#include <span>

#include <Eigen/Core>

#include "engine/assembly.h"

namespace pneufem {

struct RelaxationOptions {
  double rel_tol = 1e-8;           ///< same residual criterion as the static solver
  double abs_tol_N = 1e-12;
  long max_iterations = 2'000'000;
  double mass_factor = 0.5;        ///< m_i = mass_factor * sum_j |K_ij| (stability needs >= 1/4 at dt = 1;
                                   ///< 1/2 leaves room for stiffening between mass updates)
  int mass_update_interval = 500;  ///< iterations between fictitious-mass updates
};

struct RelaxationReport {
  bool converged = false;
  long iterations = 0;
  long kinetic_peaks = 0;
  double residual_N = 0.0;
  double reference_N = 0.0;
};

/// Dynamic relaxation with kinetic damping (Cundall 1976; Underwood 1983): pseudo-time step 1,
/// per-node fictitious masses from the Gershgorin bound of the current tangent, velocities reset
/// at every kinetic-energy peak. Converges to R(u) = 0 with the static solver's criterion, from
/// the warm start u. Reads the committed state, writes the trial state.
RelaxationReport relax(const Assembler& assembler, double p_Pa, const TimeStep& ts,
                       std::span<const double> state_committed, std::span<double> state_trial,
                       Eigen::VectorXd& u, const RelaxationOptions& options = {});

}  // namespace pneufem
