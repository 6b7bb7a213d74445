#pragma once
// A reduced-order model (ROM) of the quasi-static run (engine/quasi_static.h) that follows the full
// FEM through damage, creep and any other history effect at a cost that does not grow with the mesh.
//
// Kinematics. The displacement is kept on a manifold around the elastic loading path:
//
//     u(theta, q) = u_el(theta) + Phi q,
//
// u_el(theta) the elastic FEM solution traced in load control and parametrised by its bending angle
// theta (deg; a C2 cubic spline through the samples, engine/path_spline.h), which carries the large
// rotation of the actuator, and Phi (dofs x r) correction modes: how the deformation departs from the
// elastic shape when parts of the body soften or stiffen. They come from the linear responses of the
// elastic path to softening each of a few dozen spatial clusters of the soft elements,
//     du_c = K_T(theta_k)^-1 f_iso,c(theta_k)     (K_T the tangent of the path's equilibrium, with the
//                                                  follower load's stiffness; f_iso,c the isochoric
//                                                  internal force of cluster c's elements),
// at several samples theta_k, made mass-orthogonal to the path's tangent and compressed by POD.
// Every history effect of damage/ acts on the isochoric stress, locally (Mullins, fatigue, Prony
// terms, region scales), so a local softening is the generic first-order deformation change; no
// effect's constants enter the basis (the same basis serves any constants and any registered effect).
// The linear responses miss what damage does where it concentrates: a pneu-net's thin interior
// walls stretch ~2x on the path, and a damaged wall balloons into the gap far beyond its linear
// response (measured on a 5-chamber actuator with fatigue: stretch 2.0 -> 2.5-2.7 over three trials
// in the FEM, held at 1.7-1.9 by a basis of 120 linear-response modes of 240 clusters; no basis
// granularity, hyper-reduction, time step or exact follower pressure changed that; a basis holding
// the FEM's own trajectory followed it within 0.03 deg). So the basis also takes softened
// equilibria (softened_states below, RomBasisOptions::softened_levels): static solves of the
// reference at the mode samples' pressures with the isochoric stress of each soft element scaled
// by 1 - s (W_e / W_max)^m, the shape a damage law driven by the strain energy would give. With
// them the fatigue drift errors fell 2-3x (bench/results/rom_h2_story/softened.md).
// More modes can be added from snapshots (an FEM state, an indicator's correction). Snapshots and
// softened equilibria come first, by size (their departure from the path at equal angle). One FEM
// trial of a 3-chamber actuator with fatigue (at other constants) cut the error of three trials'
// drift 7x (tests/engine/test_rom.cpp); on the 15-chamber story near its limit point they fixed
// trial 1 but not the later trials (bench/results/rom_h2_story/snapshots.md), so the product uses
// the softened equilibria, not FEM snapshots.
//
// Equations: a Petrov-Galerkin projection of the equilibrium R(u) = f_int(u) - p dV/du - f_g = 0. The
// q rows are Galerkin (tested with Phi). The theta row is tested with the bending angle's influence
// vector at the path sample, w = K_T^-1 grad(angle) / (g^T K_T^-1 grad(angle)), instead of the path
// tangent u_el': to first order, w^T dR is the change of angle that ANY force perturbation dR causes
// (the adjoint of the output), so the theta balance gets the angle right even when the departure of the
// state from the path lies outside the span of Phi. Damage is such a case: the FEM's damaged state
// departs from the path by a local, within-element redistribution that no compact basis holds, and a
// Galerkin theta row (test u_el') then overestimated every softening about twofold, as the 1-dof path
// model does. The residual is written in a difference ("control variate") form that keeps the elastic
// reference exact and the stiff fabric unlocked:
//
//     r(theta, q) = E(theta, q; p) + P(theta, q; p) + [G_hat(theta, q) - G_hat_ref(theta) - K_hat_ref(theta) q] - T^T f_g
//
//   E:  the exact FEM reference residual linearised in q about the path,
//         E_theta = (p_el(theta) - p) w^T g + [c(theta) + (p_el - p) h(theta)] . q
//         E_q     = (p_el(theta) - p) b(theta) + [K(theta) + (p_el - p) H(theta)] q
//       with p_el(theta) the path's pressure, g = dV/du, b = Phi^T g, c = Phi^T K_T w,
//       K = Phi^T K_T Phi, h = Phi^T H_V w, H = Phi^T H_V Phi (H_V = dg/du, the load stiffness per
//       unit pressure), all computed once per path sample from the assembled FEM tangent and splined
//       in theta. On the path (q = 0) E is the exact projected residual of the reference, so the elastic
//       model is reproduced exactly whatever the rest; the fabric (10^5 times stiffer than the silicone)
//       enters only here, linearly in q: a linearised rotation of a correction mode does not stretch it
//       to second order, which locked every linear reduced basis tried before (BENCHMARKS.md §7).
//       The price: the fabric's second order in q is missing, and with a basis rich enough to hold
//       its finite rotations (the FEM's states) that was the reduced equations' whole late bias;
//       RomBasisOptions::stiff_parts puts the fabric in the bracket below as well.
//   P:  the follower load's second order in q, -p/2 T^T g2[Phi q, Phi q] (pq, pw below). The load per
//       unit pressure g(u) = dV/du is quadratic in the nodal positions, so E plus this term is its
//       exact projection, not a linearisation. It matters where q is large (a damaged wall
//       ballooning into the gap): with the FEM's own states in the basis, the story's 15-chamber
//       actuator (h = 6) was 0.45 deg off by trial 3 without it, 0.17 deg with it
//       (bench/results/rom_h6_pressure_order).
//   G_hat: the hyper-reduced projected internal force of the soft parts with the RUN'S materials and
//       history, sum over sampled elements e of xi_e T_e^T f_e(u_e(theta, q)) (T = [w, Phi], the test vectors); G_hat_ref, K_hat_ref the
//       same quadrature with the reference materials at q = 0 and its q-derivative (precomputed). The
//       bracket is the model's departure from the reference (its damage, overstress, softening) plus
//       the soft parts' nonlinearity in q, both integrated by the sampled elements only.
//   Hyper-reduction: energy-conserving sampling and weighting (ECSW; Farhat, Avery, Chapman & Cortial
//       2014, IJNME 98, 625-662; Farhat, Chapman & Avery 2015, IJNME 102, 1077-1110): element weights
//       xi_e >= 0 from non-negative least squares (engine/nnls.h) on training snapshots, per spatial
//       cluster, so that each cluster's reduced force is reproduced within ecsw_tolerance: a softening
//       confined to any cluster is then integrated as the FEM would. The weighted sum is a sum of
//       element energies: the reduced model keeps a potential structure, and its cost is set by the
//       number of sampled elements, not by the mesh.
//   The gauge: theta and the part of Phi q along u_el'(theta) would describe the same motion, so q is
//       kept mass-orthogonal to u_el'(theta) (one Lagrange multiplier lambda, c(theta)^T q = 0 with
//       c = Phi^T M u_el'). The multiplier enters the q rows only: eliminated, the equations are
//       w^T R = 0 and N^T Phi^T R = 0 (N a basis of c's complement), the Petrov-Galerkin form on the
//       constrained manifold. Its term lambda c'^T q in the theta row belongs to the Galerkin form's
//       Lagrangian and is kept only there (galerkin_theta_row); in the Petrov-Galerkin form it changed
//       no angle of the h = 6 story's ten trials (to 0.001 deg) and did not remove the spurious root of
//       a basis rich in damaged states (bench/results/rom_h6_ceiling, section 5).
//
// Material history lives at the sampled elements' quadrature points only, evaluated by the run's own
// Material objects (any law and decorator; committed/trial as in the FEM). Fields of the whole mesh
// (damage, stress) are reconstructed by replaying every element's history along the reduced
// trajectory (replay_reduced_run below), which also gives the a-posteriori indicator: the full residual of
// the reconstructed state, weighted by the angle's adjoint.
//
// Units: SI; theta in degrees; q in metres (Phi is mass-orthonormal, scaled by the total mass).
#include <functional>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "engine/load_history.h"
#include "engine/model.h"
#include "engine/path_model.h"
#include "engine/quasi_static.h"
#include "engine/reduced_basis.h"
#include "engine/static_solver.h"

namespace pneufem {

struct RomBasisOptions {
  int clusters = 48;              ///< spatial clusters of the soft elements (softening patterns, ECSW blocks)
  int mode_samples = 6;           ///< path samples at which the softening responses are computed
  int max_modes = 16;             ///< softening modes kept (snapshots, when given, add up to as many more)
  double pod_tolerance = 1e-4;    ///< relative energy of the responses the kept modes may leave out
  double ecsw_tolerance = 1e-2;   ///< relative residual of each cluster's hyper-reduced training force
  /// The blocks whose reduced force ECSW reproduces: 0 = each softening cluster (the default), else
  /// about this many k-means blocks of the soft elements, at least one per region. A block must hold
  /// more elements than its training force has independent components at ecsw_tolerance for the fit
  /// to leave any out: with 48 clusters of ~70 elements and 64-171 modes it kept ~60 % of the soft
  /// elements of the h = 6 story (bench/results/rom_h6_ceiling section 12); one block per region
  /// (ecsw_blocks = 1) integrates each region's force, the sampled elements then set by the modes,
  /// not the mesh. The stiff parts' sampled blocks follow the same count. Large blocks are fitted
  /// in the normal-equations form (nnls_normal).
  int ecsw_blocks = 0;
  int training_fields = 3;        ///< random cluster-wise softening fields per mode sample (ECSW training)
  double training_softening = 0.3;  ///< largest softening of a cluster in a training field
  double training_amplitude = 0.05;  ///< cap of a field's response, relative to the path's top RMS displacement
  double stiff_modulus_ratio = 100.0;  ///< parts this much stiffer than the softest are "stiff" (fabric)
  bool hyper_reduce = true;       ///< false: every soft element, weight 1 (for tests and verification)
  /// Softened equilibria as snapshots (softened_states below): 0 = none, else the number of
  /// softening levels per field and mode sample.
  int softened_levels = 0;
  double softened_max = 0.9;      ///< the largest isochoric softening of the most strained element
  /// The theta row's test vector (see the header): the bending angle's influence vector (Petrov-
  /// Galerkin, the default) or the path tangent u_el' / V' (Galerkin). For experiments: with a basis
  /// rich in damaged shapes the Petrov-Galerkin row can admit a spurious root that the Galerkin row
  /// does not, at the price of the Galerkin row's bias on softening (bench/results/rom_h6_ceiling).
  bool galerkin_theta_row = false;
  /// Modes made mass-orthogonal to every tangent of the path (the tangents' POD to 1e-6 of their
  /// energy is projected out of Phi), so that theta and q cannot describe the same motion anywhere
  /// and the reduced equations need no gauge (ReducedBasis::gauge is then zero, which the reduced
  /// model reads as "no gauge"). For experiments: on the h = 6 story's ten trials, with the
  /// Petrov-Galerkin row, it completed with a basis of ten trials' FEM states, where the gauge's
  /// reaction makes a spurious root in trial 2, and cut the default basis's largest error per trial
  /// by ~15 % from trial 3 on (trial 2 0.42 -> 0.48 deg); with the Galerkin row it overshoots from
  /// trial 1 (0.8-0.9 deg), which needs the modes' parts along the tangents
  /// (bench/results/rom_h6_ceiling, section 5).
  bool tangent_free_modes = false;
  /// How the stiff parts (the fabric) enter the reduced equations. E (see the header) holds them
  /// linear in q about the path; the other two also put them in the bracket
  /// G_hat - G_hat_ref - K_hat_ref q, which then carries their nonlinearity in q: the 10^5 times
  /// stiffer fabric stretched to second order by the modes' rotations. Measured on the h = 6 story
  /// with the FEM's states in the basis (bench/results/rom_h6_ceiling, section 10): linear, the
  /// FEM's states with the FEM's history sat 0.14 deg below the reduced equations' roots by trial 5's
  /// 40 kPa hold; exact, 0.02 deg. With a basis that cannot hold the fabric's finite rotation (the
  /// 16 softening modes) the exact fabric locks: a spurious root of 5.5 deg at the first release.
  enum class StiffParts {
    linear,   ///< through E only (the default)
    exact,    ///< every stiff element in the bracket at weight 1 (cost grows with the mesh)
    sampled,  ///< stiff elements in the bracket, sampled by ECSW trained on their nonlinear remainder
  };
  StiffParts stiff_parts = StiffParts::linear;
  /// Release responses: the unloaded body's linear responses to the isochoric second Piola-Kirchhoff
  /// stress of the path, frozen and applied at the reference configuration (the whole soft body's
  /// at every path sample, each cluster's at the mode samples), in a POD of their own after the
  /// other modes. After a release in zero time a Prony term holds h_n - gamma S_0(F_n) (Simo 1987, CMAME 60, 153-173),
  /// the path's stress history weighted by a kernel of time alone; the released state is the
  /// response to it, a small self-equilibrated shape the loaded responses and softened equilibria
  /// do not contain (tests/engine/test_rom.cpp: the FEM's released state is 0.546 outside the
  /// default span, 0.120 outside this one). Measured on the h = 6 story with the fabric exact and
  /// softened equilibria (bench/results/rom_h6_ceiling, section 11): without them the
  /// Petrov-Galerkin release lands at -1.5 deg with a 0.49 mm correction (the FEM reports +0.05 deg
  /// 2.5 s later) and the rest finds no equilibrium; with them it lands at +6.0 deg, relaxes as the
  /// FEM does, and every rest report is within 0.01 deg (the rest after trial 8 still met a fold of
  /// the theta row at 0.1 deg). With the default basis (fabric linear) ten trials go from
  /// 0.17 / 0.42 / 5.98 deg (trials 1, 2, 10) to 0.05 / 0.44 / 5.20. Off by default until measured on
  /// the default h = 2 mesh (bench_rom --release-modes).
  bool release_responses = false;
  bool verbose = false;
};

/// Builds the basis of `reference` (elastic: materials without history, no gravity) from its traced
/// path (engine/path_model.h). Throws InputError for a reference with history or a trace that does
/// not fit it, PhysicsError when no sample's tangent could be factorised.
/// `snapshots` (optional): displacements of states the basis should contain (e.g. FEM states of a run
/// with history effects). Their departures from the path at equal angle come first: their POD by
/// size (up to max_modes modes, to pod_tolerance of their energy), then the softening responses'
/// POD in what those modes leave out; the snapshots also join the ECSW training states.
ReducedBasis build_reduced_basis(const Model& reference, const ElasticPathTrace& trace, const RomBasisOptions& options,
                                 const std::vector<Eigen::VectorXd>& snapshots = {});

/// Nonlinear equilibria of the reference with its soft elements softened like a damage law would
/// soften them, at the mode samples' pressures: the isochoric stress of element e scaled by
/// 1 - s (W_e / W_max)^m (W_e its isochoric energy density on the path there, W_max the largest of
/// the soft elements), for the fields m = 0 (uniform: creep), 1 and 4 (concentrated where the
/// stretch is largest: Mullins, fatigue), at `levels` levels s up to `max_softening`, each solved
/// by Newton from the previous level. Why: damage concentrates where the path is most strained (a
/// pneu-net's thin interior walls), and there the softened wall balloons far beyond its linear
/// response (measured: stretch 2.0 -> 2.7 in three fatigue trials where the linear responses' basis
/// held it at 1.9), a large nonlinear deformation that only equilibria of softened states contain.
/// Levels past the softened structure's limit point (no equilibrium at that pressure) are skipped.
/// Parts stiffer than stiff_modulus_ratio x the softest (the fabric) are never softened.
std::vector<Eigen::VectorXd> softened_states(const Model& reference, const ElasticPathTrace& trace, const std::vector<int>& samples,
                                             int levels, double max_softening, bool verbose = false,
                                             double stiff_modulus_ratio = 100.0);

/// A reduced state: path coordinate, correction amplitudes, gauge multiplier.
struct ReducedCoordinates {
  double theta = 0.0;
  Eigen::VectorXd q;
  double lambda = 0.0;
};

/// One accepted physical step of a reduced run: enough to replay every element's history along it.
struct ReducedStep {
  double time_s = 0.0, dt_s = 0.0;  ///< global time at the end of the step and its length (0: a jump)
  double pressure_Pa = 0.0;
  ReducedCoordinates z;
  int report = -1;                  ///< index of the report made at this state, or -1
};

struct ReducedRunStats {
  long states = 0, rejected_steps = 0, newton_iterations = 0, tangents = 0, residuals = 0;
  long reused_tangents = 0;  ///< iterations solved with an earlier Jacobian (modified Newton)
  double wall_s = 0.0;
  bool beyond_path = false;  ///< theta left the traced path (extrapolated): trust it less
};

/// The online part: a basis bound to the reference model (same mesh) and to a run's model (any
/// materials on the soft parts, gravity). Evaluates the reduced residual and its Jacobian.
class ReducedOrderModel {
 public:
  /// Throws InputError when the basis does not belong to the reference's mesh, or when a stiff part
  /// of `model` (the fabric) has a material that differs in name or initial moduli from the
  /// reference's (the reduced model keeps stiff parts linear about the reference path).
  ReducedOrderModel(const Model& reference, const ReducedBasis& basis, const Model& model);
  ~ReducedOrderModel();
  ReducedOrderModel(const ReducedOrderModel&) = delete;
  ReducedOrderModel& operator=(const ReducedOrderModel&) = delete;

  const ReducedBasis& basis() const { return basis_; }
  const Model& model() const { return model_; }
  int num_modes() const { return basis_.num_modes(); }
  int num_points() const;                      ///< material points kept (sampled elements x points)
  std::size_t history_size() const;            ///< doubles of history at the kept points
  std::vector<double> initial_history() const;

  /// Full displacement (all dofs) of reduced coordinates z.
  Eigen::VectorXd displacement(const ReducedCoordinates& z) const;
  /// Bending angle (deg, unwrapped near `previous_deg`) and tip-plane residual of z.
  double angle_deg(const ReducedCoordinates& z, double previous_deg, double* plane_rms_m = nullptr) const;
  /// Cavity volume (m^3), to second order in q about the path.
  double cavity_volume(const ReducedCoordinates& z) const;

  /// Reduced residual (r + 2: theta row, q rows, gauge row) at z, pressure p, physical step ts; reads
  /// the committed history, writes the trial history of z. With `jacobian`, also d residual / dz
  /// (theta column by a forward difference, the rest analytic). Throws PhysicsError naming the
  /// element of a kept point whose F inverted or whose stress is not finite.
  Eigen::VectorXd residual(const ReducedCoordinates& z, double p_Pa, const TimeStep& ts,
                           const std::vector<double>& history_old, std::vector<double>& history_new,
                           Eigen::MatrixXd* jacobian) const;

  /// Per kept point (2 values: fatigue damage, viscous strain), as Assembler::history_scalars.
  std::vector<double> history_scalars(const std::vector<double>& history) const;
  int element_of_point(int i) const;           ///< mesh element of kept point i
  /// The kept points' history taken from a history of every element (laid out by `full`, an
  /// Assembler of this model's mesh and materials).
  void gather_history(const Assembler& full, std::span<const double> full_state, std::vector<double>& kept) const;

 private:
  struct Impl;
  const Model& reference_;
  const ReducedBasis& basis_;
  const Model& model_;
  std::unique_ptr<Impl> impl_;
};

/// Quasi-static march through a load history in the reduced model: the same segments, physical step
/// control (QuasiStaticOptions: time_control, with "drive" run as "error"; time_tol, min/max_dt_s) and reports as QuasiStaticRun,
/// with Newton in the reduced coordinates.
class ReducedRun {
 public:
  /// Called at every report with its record, the reduced coordinates and the full displacement.
  using Observer = std::function<void(const StateRecord&, const ReducedCoordinates&, const Eigen::VectorXd& u)>;
  ReducedRun(const ReducedOrderModel& rom, QuasiStaticOptions options);

  void run(const LoadHistory& load, const Observer& observer);
  /// Off: a fresh Jacobian at every Newton iteration (plain Newton; for verification of the kept one).
  void set_jacobian_reuse(bool on) { reuse_jacobian_ = on; }
  /// Called after every committed step with the step and the committed history of the kept
  /// points, which it may replace (corrected_history_in_run); the next step starts from it.
  using HistoryCorrector = std::function<void(const ReducedStep&, std::vector<double>& history)>;
  void set_history_corrector(HistoryCorrector c) { corrector_ = std::move(c); }

  const std::vector<ReducedStep>& trajectory() const { return steps_; }
  const ReducedRunStats& stats() const { return stats_; }
  const ReducedCoordinates& coordinates() const { return z_; }
  const std::vector<double>& history() const { return hist_; }

 private:
  struct Segment;
  void solve_segment(const Segment& s);
  /// A segment without time (a load or release in zero time) or of a model without rate laws:
  /// pressure continuation with the history frozen.
  void solve_instantaneous(const Segment& s);
  /// Equilibrium at (p, t) after a step dt from the committed state; on success commits and
  /// records the step. Throws PhysicsError when Newton fails.
  void equilibrium(double p_Pa, double t_s, double dt_s);

  const ReducedOrderModel& rom_;
  QuasiStaticOptions opt_;
  /// The last factorised reduced Jacobian, reused by later iterations and steps while it still
  /// contracts (equilibrium()); reset where the state jumps (a release, a zero-time load).
  Eigen::MatrixXd jacobian_;  ///< empty: none kept
  bool reuse_jacobian_ = true;
  ReducedCoordinates z_;
  ReducedCoordinates z_prev_;       ///< the committed state before the last one in this segment (predictor)
  double h_seg_prev_ = 0.0;         ///< the last committed step's length in this segment
  long seg_steps_ = 0;              ///< steps committed in this segment
  std::vector<double> hist_, trial_;
  std::vector<ReducedStep> steps_;
  ReducedRunStats stats_;
  double dt_suggest_ = 0.0, last_angle_ = 0.0;
  std::vector<double> hist_prev_, hist_cur_;
  double h_prev_ = 0.0, rate_prev_ = 0.0;
  bool rate_dependent_ = false;
  HistoryCorrector corrector_;
  /// Commits the trial history of the state z_ reached at (t, p) after a step dt, and records it.
  void commit(double t, double dt, double p, bool report);
  /// Records a committed step and lets the corrector replace its history.
  void record_step(const ReducedStep& step);
};

/// What the full model says about a reduced state (replay_reduced_run).
struct ReducedCheck {
  /// First-order estimate of the angle error of the reduced state (deg, reduced minus full):
  /// a^T R, R the full residual of the reconstructed state with the replayed history
  /// and a = K_T^-1 grad(angle) of the reference at the same path coordinate (the adjoint of the
  /// angle; a dual-weighted residual, Becker & Rannacher 2001, Acta Numerica 10). It sees what the
  /// reduced equations leave out: the hyper-reduction, the linearisation of the fabric, the
  /// departures of the history at the points not kept. NaN where the path has no adjoint.
  double angle_error_deg = 0.0;
  /// |R| over |p g| + |f_g| (free dofs): the relative size of the full residual.
  double residual_rel = 0.0;
  /// Where requested (`newton_at`): the angle after one full Newton step from the reconstructed
  /// state, u - K^-1 R with the run's model's own tangent there (one factorisation), minus the
  /// reduced angle. Near the full solution Newton converges quadratically, so this is the reduced
  /// model's angle error to second order, including what the first estimate cannot see (the
  /// reference's adjoint where the damaged model's would be needed). NaN where not requested.
  double newton_angle_error_deg = std::numeric_limits<double>::quiet_NaN();
  /// Where requested (ReplayOptions::corrected_at): the reduced angle minus the angle of the
  /// corrected state (below), which carries the history the full model would have built. The
  /// first two estimates measure the reduced state against the full equilibrium *for the reduced
  /// model's own history*; this one also sees how far that history has drifted (a damaged point
  /// of the full model stretches more, which damages it faster). NaN where not requested.
  double corrected_angle_error_deg = std::numeric_limits<double>::quiet_NaN();
  /// Requested, but the full model's solve of the corrected state found no equilibrium (near a
  /// limit point): the reduced state could not be checked there.
  bool corrected_failed = false;
  /// The corrected state where it converged (empty elsewhere): a full-model equilibrium near the
  /// reduced state, with the history the full model would have built (a snapshot for enrichment).
  Eigen::VectorXd corrected_u;
};

/// The corrected history (the drift check). A second history of every element is integrated along
/// the reduced trajectory shifted by a correction, u_c = u(z) + (p / p_c) du_c, and at every state
/// that `corrected_at` picks, the step is solved as the full model solves it (StaticSolver::solve
/// from u_c, with that history and the step's own tangent); the converged state u* sets
/// du_c = u* - u(z) and p_c = p. Between checks the correction is held, scaled with the pressure (a
/// release takes it to zero). This is a defect correction of the reduced trajectory: the reduced
/// model is the predictor, the full equations the corrector (Kerfriden, Gosselet, Adhikari & Bordas
/// 2011, CMAME 200, 850-866, pair them the same way to decide when a reduced basis must be
/// enriched). With a check at every report, the corrected history is the full model's except for
/// the path between reports, and the reduced angle minus u*'s is the reduced model's error
/// including the drift of its history (a damaged point of the full model stretches more, which
/// damages it faster), which the Newton-step check, made with the reduced run's own history, cannot
/// see. Cost: a second force evaluation per step, and a Newton solve (a few factorisations) per check.
struct ReplayOptions {
  /// Reports that get the Newton-step check of the reduced state (ReducedCheck::newton_angle_error_deg).
  std::function<bool(const ReducedStep&)> newton_at;
  /// Reports at which the corrected history is corrected (ReducedCheck::corrected_angle_error_deg).
  /// Empty: no corrected history.
  std::function<bool(const ReducedStep&)> corrected_at;
  /// The full model's Newton for the corrected states (the run's solver.quasi_static.newton).
  StaticOptions newton;
};

/// Replays every element's history of the run's model (the full mesh) along a reduced trajectory,
/// with the run's own materials (one force evaluation per step), and checks every report state:
/// `at_report(step, u, state, check)` gets the full displacement, the whole history and the
/// indicator. The history at the kept points equals the reduced run's. Cost: one force assembly
/// per step of the trajectory. Throws PhysicsError when an element inverts in the reconstruction.
using ReplayObserver =
    std::function<void(const ReducedStep&, const Eigen::VectorXd& u, const std::vector<double>& state, const ReducedCheck&)>;
/// `options` add the Newton-step check and the corrected history at the reports they pick; the
/// observer's `state` is the reduced run's replayed history either way.
void replay_reduced_run(const ReducedOrderModel& rom, const std::vector<ReducedStep>& trajectory, const ReplayObserver& at_report,
                        const ReplayOptions& options = {});

/// The corrected history of ReplayOptions fed back into the run (ReducedRun::set_history_corrector):
/// every element's history is integrated along u(z) + (p / p_c) du_c, du_c set by the full model's
/// solve at the committed steps `correct_at` picks (its ReducedStep::report is 0 at a report, -1
/// elsewhere), and the kept points take that history after every step, so the reduced equations see
/// the history the full model would build rather than the one their own trajectory builds (a defect
/// correction fed back, Kerfriden et al. 2011). `on_check(step, converged)` hears each check.
/// Cost: one full force evaluation per step and a full Newton solve per check: the online cost
/// then grows with the mesh.
ReducedRun::HistoryCorrector corrected_history_in_run(const ReducedOrderModel& rom, std::function<bool(const ReducedStep&)> correct_at,
                                                      const StaticOptions& newton,
                                                      std::function<void(const ReducedStep&, bool converged)> on_check = {});

}  // namespace pneufem
