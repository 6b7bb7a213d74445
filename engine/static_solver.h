#pragma once
// Static (quasi-static) equilibrium by Newton's method with a consistent tangent, including the
// follower-pressure load stiffness, a residual line search, and adaptive load continuation.
// It shares the element and material code of the explicit integrator (Assembler), so
// "the same equilibrium as a static solver" is a statement about the same discrete equations.
//
// Equilibrium: R(u) = f_int(u) - f_ext(u; p) = 0 on the free dofs, with p the cavity pressure.
// Convergence: ||R_free||_2 <= rel_tol * max(||f_ext||_2, ||reactions||_2, floor) (+ abs_tol_N).
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/errors.h"
#include "engine/assembly.h"
#include "engine/linear_solver.h"

namespace pneufem {

struct StaticOptions {
  double rel_tol = 1e-8;          ///< relative residual tolerance
  double abs_tol_N = 1e-12;       ///< absolute residual floor (N)
  int max_iterations = 30;        ///< Newton iterations per increment (then cut back)
  double max_increment_Pa = 5e3;  ///< largest pressure sub-increment of a continuation
  double min_increment_Pa = 1.0;  ///< give up (limit point) below this sub-increment
  bool verbose = false;           ///< print every iteration to stderr
  /// Newton-Krylov: CG iterations allowed with an old factorisation as preconditioner before
  /// re-factorising (0 = factorise every Newton iteration).
  int krylov_max_iterations = 10;
  double krylov_rel_tol = 1e-3;   ///< CG stopping criterion, relative to |R|
  /// Newton-Krylov also on pressure ramps (load increments), not only at constant pressure, with
  /// the give-ups of StaticSolver::linear_step (a CG that cannot reach its tolerance in time, a
  /// Newton residual that does not contract after a Krylov step, a tangent CG proves indefinite).
  /// Off: the ramps factorise every Newton iteration, as before (scene key solver.krylov_ramps).
  bool krylov_on_ramps = false;
  int chord_steps = 3;            ///< back-substitutions with the current factor per iteration
  /// Stiff-layer elimination (see StaticSolver): relaxation steps of the stiff dofs after every
  /// trial update (0 = off), and the shear-modulus ratio above which a part counts as stiff.
  int stiff_relaxation_steps = 3;
  double stiff_modulus_ratio = 100.0;
  /// A tangent that is not positive definite (a trial state off the equilibrium path, or near a
  /// limit point): take the step with the last positive-definite factorisation (a modified-Newton
  /// step, one back-substitution), or shift the diagonal until Cholesky succeeds (a new
  /// factorisation per try). See StaticSolver.
  enum class Indefinite { LastFactor, Shift };
  Indefinite indefinite = Indefinite::LastFactor;
  /// Line search on the total potential energy when the model has one (elastic materials, a
  /// conservative pressure load); otherwise, and when false, on the directional derivative only.
  bool energy_line_search = true;
};

struct NewtonReport {
  bool converged = false;
  int iterations = 0;
  int line_search_cuts = 0;
  int regularised = 0;       ///< factorisations that needed a diagonal shift (not PD)
  double residual_N = 0.0;   ///< final ||R_free||
  double reference_N = 0.0;  ///< force scale used by the relative tolerance
  std::string failure;       ///< why it failed, when it did
};

/// Cumulative counters of a solver (reported in the run summary).
struct StaticStats {
  long increments = 0;
  long cutbacks = 0;
  long iterations = 0;
  long factorizations = 0;
  long residual_evaluations = 0;
  long krylov_iterations = 0;
  long krylov_steps = 0;          ///< Newton iterations stepped by CG with an old factor (no factorisation)
  long krylov_give_ups = 0;       ///< CG attempts abandoned for a factorisation (slow or stalled CG)
  long contraction_refactors = 0; ///< factorisations forced because a Krylov step did not contract |R|
  long indefinite_by_cg = 0;      ///< last-factor steps taken because CG met negative curvature (no failed factorisation)
  long chord_steps = 0;
  long stiff_relaxations = 0;     ///< accepted stiff-layer relaxation steps
  long stiff_factorizations = 0;  ///< factorisations of the stiff-layer block
  long last_factor_steps = 0;     ///< iterations stepped with the last PD factor (tangent not PD)
  long energy_cuts = 0;           ///< line-search cuts because the potential energy rose
  long release_attempts = 0;      ///< releases to zero pressure tried from the reference configuration
  long direct_releases = 0;       ///< of which converged (the others followed the path down)
  double assembly_s = 0.0;
  double factor_s = 0.0;
};

/// Stiff-layer elimination. A thin layer ~10^5 times stiffer than the body it is bonded to (the
/// fabric in the silicone) makes plain Newton wander: a linearised rotation is not isometric, so every
/// step that bends the structure stretches the layer to second order, that spurious stress enters
/// the geometric stiffness of the soft bending mode, and the next step overshoots (6-13 erratic
/// iterations per increment on the default pneu-net, many increments cut back). The solver therefore
/// eliminates the layer nonlinearly (in the spirit of Lanzkron, Rose & Wilkes 1996, "nonlinear
/// elimination"): after every trial update, the dofs of the stiff parts' nodes are relaxed with the
/// rest held (a few Newton steps on the layer's block of the tangent, a small factorisation), and the
/// line search measures the step on that relaxed state. The equilibrium is unchanged (the full
/// residual is still the criterion); only the path to it changes.
///
/// Globalisation (measured in BENCHMARKS.md section 3). Near the top of the staircase and on trial
/// states off the path (a linearised bending step stretches the fabric), the tangent is often not
/// positive definite. Shifting its diagonal until Cholesky succeeds cost one to seven extra
/// factorisations per such iteration (half of all factorisations), and the heavily shifted steps
/// were tiny. Instead the solver keeps the last positive-definite factor (two buffers) and takes a
/// modified-Newton step with it: a descent direction of the potential energy, for the price of a
/// back-substitution. When the model has a potential Pi(u) = W(u) - p V(u) - f_g . u (elastic
/// materials; the follower pressure on a closed cavity is conservative: p dV), the line search
/// also requires Pi to fall (Armijo), which rejects the steps that bend the actuator by a
/// linearised rotation and thereby stretch the stiff fabric (an energy rise the directional
/// derivative alone does not see). Whether the load is conservative is checked once, numerically
/// (the pressure load must be p times the gradient of the cavity volume), so an open cavity of a
/// user's deck falls back to the derivative-only search.
class StaticSolver {
 public:
  StaticSolver(const Assembler& assembler, StaticOptions options = {});

  /// Newton at fixed load (pressure p_Pa, physical step ts for rate laws) from the guess u.
  /// Reads the committed material state, writes the trial state of the final iterate.
  NewtonReport solve(double p_Pa, const TimeStep& ts, std::span<const double> state_committed,
                     std::span<double> state_trial, Eigen::VectorXd& u);

  /// Moves the equilibrium from (p0, t0) to (p1, t1) in adaptive sub-increments, committing the
  /// material state after each accepted one (pressure and time advance together). Throws
  /// PhysicsError when the increment falls below min_increment_Pa (e.g. at a limit point). A release
  /// to zero pressure in zero time (t1 == t0) is first tried as one solve from the reference configuration.
  void advance(double p0_Pa, double p1_Pa, double t0_s, double t1_s, std::vector<double>& state,
               Eigen::VectorXd& u);

  /// Residual R(u) on the free dofs (fixed entries zeroed); with `potential`, also the total
  /// potential energy Pi(u) (J; meaningful only when has_potential()).
  Eigen::VectorXd residual(double p_Pa, const TimeStep& ts, std::span<const double> state_committed,
                           std::span<double> state_trial, const Eigen::VectorXd& u, double* potential = nullptr);
  /// True when R = dPi/du for the potential of residual(): no material history and a pressure load
  /// that is p times the gradient of the cavity volume (checked numerically at construction).
  bool has_potential() const { return has_potential_; }

  const StaticStats& stats() const { return stats_; }
  const StaticOptions& options() const { return opt_; }

  /// The last equilibria of the current load path (the predictor's memory); saved in checkpoints
  /// and restored when a physical step is rejected, so runs are reproducible.
  struct Path {
    std::vector<double> p;
    std::vector<Eigen::VectorXd> u;
  };
  Path path() const { return {path_p_, path_u_}; }
  /// A non-empty path also means an equilibrium was reached (as after advance()): a run resumed
  /// from a checkpoint then releases and carries its weight as the uninterrupted run does.
  void set_path(Path path) {
    path_p_ = std::move(path.p);
    path_u_ = std::move(path.u);
    if (!path_p_.empty()) has_equilibrium_ = true;
  }
  /// Forgets the last factorisation (the preconditioner of the Krylov steps at constant pressure
  /// and the fallback of a tangent that is not positive definite): the next linear step
  /// factorises afresh. A run calls it at every segment start, so that what the solver does next
  /// depends only on what a checkpoint holds (engine/quasi_static.h).
  void forget_factor() { linear_->forget_factor(); }

 private:
  /// Solves K du = -R (Newton-Krylov with the stored factor, else a fresh factorisation).
  bool linear_step(const Eigen::VectorXd& R, Eigen::VectorXd& du, NewtonReport& rep);
  bool factorize_current(NewtonReport& rep);
  /// solve()'s line search along du from u, where R = R(u), W0 the stored energy at u and tol the
  /// iteration's tolerance: returns u + alpha du (see static_solver.cpp).
  Eigen::VectorXd line_search(double p, const TimeStep& ts, std::span<const double> s_old, std::span<double> s_new,
                              const Eigen::VectorXd& u, const Eigen::VectorXd& du, const Eigen::VectorXd& R,
                              double W0, double tol, NewtonReport& rep);
  /// solve()'s chord steps with the factor just computed (Shamanskii), updating u in place.
  void chord_steps(double p, const TimeStep& ts, std::span<const double> s_old, std::span<double> s_new,
                   Eigen::VectorXd& u, const NewtonReport& rep);
  /// advance() at constant pressure p1 over [t0, t1] (rate laws evolve): one solve, Krylov allowed.
  void advance_in_time(double p1, double t0, double t1, std::vector<double>& state, std::vector<double>& trial,
                       Eigen::VectorXd& u);
  /// advance()'s start for the increment pa -> pb: the polynomial extrapolation of the last
  /// equilibria when it balances the load at pb better than u does, else u.
  Eigen::VectorXd predictor(double pa, double pb, double ta, double tb, std::span<const double> state,
                            std::span<double> trial, const Eigen::VectorXd& u);
  /// The PhysicsError of a continuation whose increment fell below min_increment_Pa at pa, with
  /// the hint that what Newton saw supports (a limit point, or too few iterations).
  PhysicsError stalled_continuation(double pa, double ta, const NewtonReport& r) const;
  /// advance() from p0 to zero pressure in zero time: one Newton solve from the reference
  /// configuration; false (u and the state unchanged) when it does not converge. See static_solver.cpp.
  bool release_from_reference(double p0, double t, std::vector<double>& state, std::vector<double>& trial,
                              Eigen::VectorXd& u);
  /// Relaxes the stiff dofs of u (the others held) given R = R(u); updates u and R in place.
  /// Never throws: a relaxation step that fails or does not reduce |R| is not taken.
  void relax_stiff_layer(double p_Pa, const TimeStep& ts, std::span<const double> s_old, std::span<double> s_new,
                         Eigen::VectorXd& u, Eigen::VectorXd& R, double* potential);
  /// Pi(u) from the stored energy W (J) already computed at u.
  double potential_from(double W_J, double p_Pa, const Eigen::VectorXd& u) const;
  /// solve() at constant pressure; when the very first equilibrium of this solver fails with
  /// gravity on, retries with the weight ramped in (see static_solver.cpp).
  NewtonReport solve_first_with_weight(double p_Pa, const TimeStep& ts, std::span<const double> s_old,
                                       std::span<double> s_new, Eigen::VectorXd& u);

  const Assembler& asm_;
  StaticOptions opt_;
  bool krylov_allowed_ = false;  ///< CG with the old factor: pure time increments (and ramps with krylov_on_ramps)
  bool ramp_rules_ = false;         ///< solving a load increment with krylov_on_ramps: linear_step's give-ups apply
  bool last_step_krylov_ = false;   ///< the last linear_step of solve() was a CG step with an old factor
  bool force_factor_ = false;       ///< the next linear_step factorises (a Krylov step did not contract |R|)
  int solve_give_ups_ = 0;          ///< CG attempts of this solve() abandoned (ramps: one ends Krylov for the solve)
  // Two factorisation buffers: a new factorisation goes into spare_ and becomes linear_ only when
  // it succeeds, so linear_ always holds the last positive-definite factor (Indefinite::LastFactor).
  std::unique_ptr<LinearSolver> linear_ = std::make_unique<LinearSolver>();
  std::unique_ptr<LinearSolver> spare_ = std::make_unique<LinearSolver>();
  bool has_potential_ = false;
  Eigen::VectorXd gravity_load_;  ///< f_g at full weight (N), for the potential
  std::vector<int> stiff_dofs_;   ///< free dofs of the nodes of stiff parts (stiff-layer elimination)
  std::vector<int> stiff_index_;  ///< dof -> position in stiff_dofs_, or -1
  LinearSolver stiff_linear_;     ///< factor of the stiff block of K_
  bool stiff_factor_current_ = false;  ///< stiff_linear_ factors the current K_
  SparseMatrix K_;
  StaticStats stats_;
  std::vector<double> path_p_;           ///< pressures of the last (<= 3) equilibria on this path
  std::vector<Eigen::VectorXd> path_u_;  ///< their displacements (for the predictor)
  double force_floor_ = 0.0;        ///< lower bound of the reference force (N)
  double gravity_scale_ = 1.0;      ///< fraction of the weight applied (< 1 only while ramping it in)
  bool has_equilibrium_ = false;    ///< an advance() has converged (the weight is then carried)
};

/// Force scale below which residuals count as zero relative to the structure's stiffness (N).
double reference_force_floor(const Assembler& assembler);

}  // namespace pneufem
