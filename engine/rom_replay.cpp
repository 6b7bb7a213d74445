// The reduced run seen by the full model (engine/rom.h, replay_reduced_run): every element's
// history along the reduced trajectory, the adjoint-weighted full residual at the reports, and the
// corrected history (ReplayOptions).
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>

#include "core/errors.h"
#include "engine/angle.h"
#include "engine/assembly.h"
#include "engine/linear_solver.h"
#include "engine/path_spline.h"
#include "engine/rom.h"
#include "engine/static_solver.h"

namespace pneufem {

namespace {

/// R = f_int - p g - f_g on the free dofs, with `f` the internal force at u; the load stiffness
/// joins K when given. `load` (optional) gets p g + f_g on the free dofs.
Eigen::VectorXd full_residual(const Assembler& A, const Eigen::VectorXd& u, double p_Pa, const Eigen::VectorXd& f,
                              const Eigen::VectorXd& fg, SparseMatrix* K, Eigen::VectorXd* load = nullptr) {
  Eigen::VectorXd fp = Eigen::VectorXd::Zero(u.size());
  A.add_pressure(u, p_Pa, fp, K);
  Eigen::VectorXd R = f - fp - fg;
  A.zero_fixed(R);
  if (load) {
    *load = fp + fg;
    A.zero_fixed(*load);
  }
  return R;
}

/// The Newton step du = K^-1 R on the free dofs; false when K cannot be factorised.
bool newton_step(const Assembler& A, SparseMatrix& K, const Eigen::VectorXd& R, Eigen::VectorXd& du) {
  A.apply_constraints(K, 1.0);
  LinearSolver ls;
  if (!ls.factorize(K)) return false;
  du = ls.solve(R);
  A.zero_fixed(du);
  return true;
}

/// a^T R with a(theta) = K_T^-1 grad(angle) of the reference: linear between the two path samples
/// around theta (clamped to the path's ends), each column wa_k w_k; NaN where a sample has no adjoint.
double adjoint_estimate(const ReducedBasis& B, double theta, const Eigen::VectorXd& R) {
  const int k = path_segment_index(B.theta, theta);
  const double x = std::clamp((theta - B.theta[k]) / (B.theta[k + 1] - B.theta[k]), 0.0, 1.0);
  if (!(B.wa[k] > 0.0 && B.wa[k + 1] > 0.0)) return std::numeric_limits<double>::quiet_NaN();
  return (1.0 - x) * B.wa[k] * B.W.col(k).dot(R) + x * B.wa[k + 1] * B.W.col(k + 1).dot(R);
}

/// The corrected history of ReplayOptions: its state and the correction du_c.
class CorrectedHistory {
 public:
  CorrectedHistory(const Assembler& A, const StaticOptions& newton)
      : A_(A), solver_(A, newton), state_(A.initial_state()), trial_(state_.size()) {
    du_ = Eigen::VectorXd::Zero(A.num_dofs());
    u_converged_ = du_;
  }
  const std::vector<double>& state() const { return state_; }
  /// Advances the history by `step` from u + du_c (u the reduced state), du_c scaled by the
  /// pressure since the last correction (a release takes it to zero with the load). With `correct`,
  /// the step is solved as the full model solves it: Newton from there with the step's own tangent
  /// (StaticSolver::solve), and where that fails (near a limit point) the full model's continuation
  /// from the last converged corrected state (StaticSolver::advance, sub-increments in pressure).
  /// The converged state sets du_c; `converged` says whether there was one (if not, the prediction
  /// stands). Returns the corrected displacement.
  Eigen::VectorXd advance(const ReducedStep& step, const Eigen::VectorXd& u, bool correct, bool& converged) {
    const double scale = p_check_ > 0.0 ? std::clamp(step.pressure_Pa / p_check_, 0.0, 2.0) : 1.0;
    Eigen::VectorXd uc = u + scale * du_;
    const TimeStep ts{step.time_s, step.dt_s};
    converged = false;
    // Where the step's history stands: committed (by a continuation), in trial_ (at the solve's
    // converged state), or still to be evaluated at the prediction.
    enum class History { ToEvaluate, InTrial, Committed } history = History::ToEvaluate;
    if (correct) {
      Eigen::VectorXd solved = uc;
      try {
        converged = solver_.solve(step.pressure_Pa, ts, state_, trial_, solved).converged;
      } catch (const PhysicsError&) {
        converged = false;  // an element inverted on the way
      }
      if (converged) {
        history = History::InTrial;
      } else {
        // Continuation from the last converged corrected state (an equilibrium, at the pressure of
        // the last correction, of a slightly older history), in pressure sub-increments while the
        // time runs from the committed history's to the step's.
        std::vector<double> state = state_;
        solved = u_converged_;
        solver_.set_path({});  // no predictor from an earlier check's path
        try {
          solver_.advance(p_check_, step.pressure_Pa, t_prev_, step.time_s, state, solved);
          converged = true;
          history = History::Committed;
          state_.swap(state);
        } catch (const PhysicsError&) {
          converged = false;  // no equilibrium reached: keep the prediction
        }
      }
      if (converged) {
        uc = solved;
        du_ = uc - u;
        u_converged_ = uc;
        p_check_ = step.pressure_Pa;
      }
    }
    if (history == History::ToEvaluate) solver_.residual(step.pressure_Pa, ts, state_, trial_, uc);  // the step's history at uc
    if (history != History::Committed) state_.swap(trial_);
    A_.update_nonlocal(uc, state_);
    t_prev_ = step.time_s;
    return uc;
  }

 private:
  const Assembler& A_;
  StaticSolver solver_;
  std::vector<double> state_, trial_;
  Eigen::VectorXd du_, u_converged_;  ///< the correction; the last converged corrected state
  double p_check_ = 0.0, t_prev_ = 0.0;  ///< its pressure; the committed history's time
};

}  // namespace

void replay_reduced_run(const ReducedOrderModel& rom, const std::vector<ReducedStep>& trajectory, const ReplayObserver& at_report,
                        const ReplayOptions& options) {
  const Assembler A(rom.model());
  const ReducedBasis& B = rom.basis();
  std::vector<double> state = A.initial_state(), trial(state.size());
  const Eigen::Index n = A.num_dofs();
  Eigen::VectorXd f(n), fg = Eigen::VectorXd::Zero(n);
  A.add_gravity(fg);
  std::unique_ptr<CorrectedHistory> corrected;
  if (options.corrected_at) corrected = std::make_unique<CorrectedHistory>(A, options.newton);
  for (const ReducedStep& step : trajectory) {
    const Eigen::VectorXd u = rom.displacement(step.z);
    f.setZero();
    const bool newton = step.report >= 0 && options.newton_at && options.newton_at(step);
    SparseMatrix K;
    if (newton) K = A.tangent_pattern();
    A.internal(u, TimeStep{step.time_s, step.dt_s}, state, trial, &f, newton ? &K : nullptr, nullptr);
    state.swap(trial);
    A.update_nonlocal(u, state);
    const bool correct = corrected && step.report >= 0 && options.corrected_at(step);
    Eigen::VectorXd uc;
    bool converged = false;
    if (corrected) uc = corrected->advance(step, u, correct, converged);
    if (step.report < 0) continue;
    Eigen::VectorXd load;
    const Eigen::VectorXd R = full_residual(A, u, step.pressure_Pa, f, fg, newton ? &K : nullptr, &load);
    ReducedCheck check;
    check.residual_rel = R.norm() / std::max(load.norm(), 1e-300);
    check.angle_error_deg = adjoint_estimate(B, step.z.theta, R);
    const bool angle_needed = newton || correct;
    const double a0 = angle_needed ? bending_angle(rom.model(), u).angle_deg : 0.0;
    Eigen::VectorXd du;
    if (newton && newton_step(A, K, R, du))
      check.newton_angle_error_deg = -(unwrap_deg(bending_angle(rom.model(), u - du).angle_deg, a0) - a0);
    check.corrected_failed = correct && !converged;
    if (correct && converged) {
      check.corrected_angle_error_deg = -(unwrap_deg(bending_angle(rom.model(), uc).angle_deg, a0) - a0);
      check.corrected_u = uc;
    }
    at_report(step, u, state, check);
  }
}

ReducedRun::HistoryCorrector corrected_history_in_run(const ReducedOrderModel& rom, std::function<bool(const ReducedStep&)> correct_at,
                                                      const StaticOptions& newton,
                                                      std::function<void(const ReducedStep&, bool converged)> on_check) {
  struct Shared {
    Shared(const Model& m, const StaticOptions& o) : A(m), history(A, o) {}
    Assembler A;
    CorrectedHistory history;
  };
  auto shared = std::make_shared<Shared>(rom.model(), newton);
  return [&rom, shared, correct_at = std::move(correct_at), on_check = std::move(on_check)](const ReducedStep& step,
                                                                                              std::vector<double>& kept) {
    const bool correct = correct_at && correct_at(step);
    bool converged = false;
    shared->history.advance(step, rom.displacement(step.z), correct, converged);
    if (correct && on_check) on_check(step, converged);
    rom.gather_history(shared->A, shared->history.state(), kept);
  };
}

}  // namespace pneufem
