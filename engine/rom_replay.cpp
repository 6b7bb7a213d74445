// The reduced run seen by the full model (engine/rom.h, replay_reduced_run): every element's
// history along the reduced trajectory, and the adjoint-weighted full residual at the reports.
#include <algorithm>
#include <cmath>
#include <limits>

#include "engine/angle.h"
#include "engine/assembly.h"
#include "engine/linear_solver.h"
#include "engine/path_spline.h"
#include "engine/rom.h"

namespace pneufem {

void replay_reduced_run(const ReducedOrderModel& rom, const std::vector<ReducedStep>& trajectory, const ReplayObserver& at_report,
                        const std::function<bool(const ReducedStep&)>& newton_at) {
  const Assembler A(rom.model());
  const ReducedBasis& B = rom.basis();
  std::vector<double> state = A.initial_state(), trial(state.size());
  const Eigen::Index n = A.num_dofs();
  Eigen::VectorXd f(n), fp(n), fg = Eigen::VectorXd::Zero(n);
  A.add_gravity(fg);
  for (const ReducedStep& step : trajectory) {
    const Eigen::VectorXd u = rom.displacement(step.z);
    f.setZero();
    const bool newton = step.report >= 0 && newton_at && newton_at(step);
    SparseMatrix K;
    if (newton) K = A.tangent_pattern();
    A.internal(u, TimeStep{step.time_s, step.dt_s}, state, trial, &f, newton ? &K : nullptr, nullptr);
    state.swap(trial);
    A.update_nonlocal(u, state);
    if (step.report < 0) continue;
    // R = f_int - p g - f_g on the free dofs.
    fp.setZero();
    A.add_pressure(u, step.pressure_Pa, fp, newton ? &K : nullptr);
    Eigen::VectorXd R = f - fp - fg;
    A.zero_fixed(R);
    Eigen::VectorXd load = fp + fg;
    A.zero_fixed(load);
    ReducedCheck check;
    check.residual_rel = R.norm() / std::max(load.norm(), 1e-300);
    // a(theta) = K_T^-1 grad(angle): linear between the two samples around theta (clamped to the
    // path's ends), each column wa_k w_k; NaN where a sample has no adjoint.
    const int k = path_segment_index(B.theta, step.z.theta);
    const double x = std::clamp((step.z.theta - B.theta[k]) / (B.theta[k + 1] - B.theta[k]), 0.0, 1.0);
    if (B.wa[k] > 0.0 && B.wa[k + 1] > 0.0) {
      const double r0 = B.W.col(k).dot(R), r1 = B.W.col(k + 1).dot(R);
      check.angle_error_deg = (1.0 - x) * B.wa[k] * r0 + x * B.wa[k + 1] * r1;
    } else {
      check.angle_error_deg = std::numeric_limits<double>::quiet_NaN();
    }
    if (newton) {
      A.apply_constraints(K, 1.0);
      LinearSolver ls;
      if (ls.factorize(K)) {
        Eigen::VectorXd du = ls.solve(R);
        A.zero_fixed(du);
        const double a0 = bending_angle(rom.model(), u).angle_deg;
        check.newton_angle_error_deg = -(unwrap_deg(bending_angle(rom.model(), u - du).angle_deg, a0) - a0);
      }
    }
    at_report(step, u, state, check);
  }
}

}  // namespace pneufem
