#pragma once
// Quasi-static march through a load history: a sequence of static equilibria, each with the
// material history committed at the previous one, in physical time (so rate-dependent laws
// evolve between states). Equilibria come from Newton (default) or dynamic relaxation; both
// use the same element and material code and the same residual criterion.
//
// Physical time steps adapt when the materials carry history (creep, damage): a step is
// accepted when the largest change of any point's damage or viscous strain stays below
// `time_tol` (rejected and retried shorter above 2 time_tol), and the next step is scaled by
// 0.9 time_tol / change, within [0.5, 2] of the last. Tightening time_tol converges the angle
// history (tested).
//
// time_control = Error bounds an estimate of each step's local error instead of its size. The
// history update is first order in the step (backward Euler / exponential Prony update), so its
// local error is ~ x'' h^2 / 2; comparing the step's change with the previous step's change
// extrapolated at constant rate, e = |dx_n - r dx_(n-1)| r / (1 + r) with r = h_n / h_(n-1)
// (Milne's device), estimates it per point; the step is accepted when max e <= time_tol (retried
// shorter above 2 time_tol) and the next one scaled by 0.9 sqrt(time_tol / e) within [0.5, 2].
// A relaxing or steadily damaging hold then takes steps of seconds where the change limit took
// tenths. Where the load rate jumps (the first step after a kink) there is no valid previous
// rate: that step falls back to the change limit.
//
// time_control = Drive estimates the error of what each update actually gets wrong. The fatigue
// damage is backward Euler (damage/fatigue.h): first order, Milne's estimate above applies (see
// below for the damaging points). The viscous strain is NOT integrated to first order: the exponential Prony update
// (damage/viscoelastic.h) is exact whenever the elastic stress S0 that drives it varies linearly in
// time over the step, whatever the step's length and however curved the relaxing overstress Q
// itself is (Q ~ exp(-t/tau) has Q'' = Q/tau^2, which Milne's estimate on Q counts as error: after
// a release that gave 0.04 s steps growing 4-10 % per step, ~30 states for 30 s of recovery). Its
// local error comes from the curvature of the drive only (history_step.h, linear_drive_error):
//   e_v = |D''| sum_i a_i tau_i^2 G(h / tau_i),   D = S0 / (2 mu_inf) (Material::LinearDrive),
// with D'' from the second divided difference of the committed D of the last three states,
//   D'' = 2 (dD_n / h_n - dD_(n-1) / h_(n-1)) / (h_n + h_(n-1)).
// At a point whose fatigue damage grows (in this step or the last) the control keeps Error's
// estimate on damage AND viscous strain: the damage update is backward Euler in a driver (the
// stretch) that creeps with the viscous relaxation, and its errors, unlike the viscous ones, are
// not damped but add up over the trials. Measured on the h = 6 story (bench/notes/2026-11-27-gap-
// drive-control.md): with the drive estimate there too the 45 kPa holds took 4 s steps and the
// reported angles drifted from the error control's by 0.004, 0.010, 0.018, 0.028 deg in trials 1-4
// at time_tol 0.02 (0.005, 0.004, 0.010 deg at time_tol 0.002), the drift of the damage.
// Damage too slow to matter (the unchecked budget): a damage change over a step can move the point's
// stress by at most |dd| |S0_undamaged| = |dd| max(|D|, |D'|) / (1 - d') in viscous-strain units,
// and its error by no more than that (the backward-Euler increment h ddot(t+h) and the exact one both
// lie in [0, h max ddot] when the rate is monotone over the step). So at a damaging point whose
// damage changes taken under the drive estimate, summed since the last release, stay within
// time_tol (per point, `unchecked`), no error of its damage can matter more than one accepted viscous
// step, and the point gets the drive estimate; once its sum would pass time_tol it keeps Milne's. This
// is what the rest needs: after trials 6-9 of the h = 6 story a few end-cap points stay above the
// fatigue threshold for ~4 s after the release, damaging by ~5e-5 / s; Milne's estimate on their
// relaxing viscous strain (its exponential decay counted as error, 0.016 per 0.5 s step) set 0.5 s
// steps there and the rest took 12-21 states instead of 8 (bench/notes/2026-11-28-gap-damage-
// budget.md). The walls damaging in the holds pass the budget within a few steps (their |dd| |D| is
// ~1e-3-1e-2 per step against time_tol 0.02), so the holds keep the error control's estimate.
// The budget restarts at every release (per trial: the guarantee is time_tol per point per trial).
// A step is accepted when max over points of the error <= time_tol (retried shorter above
// 2 time_tol); the next step is the longest within [0.5, 2] h whose predicted error (the damaging
// points' growing like h^2, e_v with G at each kind's largest |D''|) is 0.9 time_tol.
// The first step of a hold or rest (no curvature known yet: after a kink, a release, the run's
// start) is sized from the shortest relaxation time instead of the change limit: at fixed load the
// stress a point's branches carry passes to S0 as they relax, so S0 changes in all by at most
// `recovery` x viscous strain (Material::LinearDrive), on the time scale of the relaxation (>= the
// shortest tau_i; the structure's creep time (1 + gamma) tau is longer), i.e.
// |D''| <= recovery v / tau_min^2, and the step is the longest whose error bound
// recovery v sum_i a_i (tau_i / tau_min)^2 G(h / tau_i) is 0.9 time_tol (at most max_dt_s); only its
// damage change is limited (time_tol, as the change limit). The first step of a ramp, and of a hold
// whose damage grew in the last step, keeps the change limit of damage and viscous strain. A
// segment of zero length that solves nothing (the zero-length jump to a trial's first pressure when
// it equals the rest's) keeps the control's memory. Without a Prony term (no linear drive) the
// control is Error's at damaging points and needs nothing elsewhere.
//
// Cycle jumping (options.cycle_jump, engine/cycle_jump.h): at the end of a trial, when the last three
// trial ends allow it, the history is extrapolated over the next N trials, which are reported as
// extrapolated (StateRecord::extrapolated) and not solved; the run continues with the release into
// trial N + 1 after the last computed one. It needs trials that repeat one cycle (identical loads)
// and laws that say how their history extrapolates (Material::jumps_cycles): InputError otherwise.
//
// The run is a list of segments (the intervals between the load's breakpoints and report
// times, plus the rest between trials). After each segment the full state can be checkpointed;
// resuming from a checkpoint continues as the uninterrupted run would, bit for bit. The one piece of
// solver state a checkpoint cannot hold, the last factorisation (it preconditions the Krylov steps
// at constant pressure), is forgotten at every segment start (StaticSolver::forget_factor), so the
// uninterrupted run also starts each segment without it. Cost: one factorisation at the start of
// each hold and rest where a Krylov step would have reused the ramp's (measured in BENCHMARKS.md).
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/errors.h"
#include "engine/assembly.h"
#include "engine/cycle_jump.h"
#include "engine/load_history.h"
#include "engine/relaxation.h"
#include "engine/static_solver.h"

namespace pneufem {

enum class EquilibriumMethod { Newton, Relaxation };
enum class TimeControl { Change, Error, Drive };

struct QuasiStaticOptions {
  EquilibriumMethod method = EquilibriumMethod::Newton;
  StaticOptions newton;
  RelaxationOptions relaxation;
  double time_tol = 0.01;   ///< max change (Change) or local-error estimate (Error, Drive) of damage / viscous strain per physical step
  TimeControl time_control = TimeControl::Change;
  double min_dt_s = 1e-3;   ///< smallest physical step
  double max_dt_s = 4.0;    ///< largest physical step (rate-dependent materials only)
  /// Physical steps (accepted + rejected) allowed in one load segment (a ramp, a hold, a rest)
  /// before the run stops with the element whose history changes fastest: a history that keeps
  /// the step near min_dt_s would otherwise look like a hang (tens of thousands of Newton solves).
  long max_segment_steps = 5000;
  /// Skipping trials whose history is extrapolated (engine/cycle_jump.h); off by default.
  CycleJumpOptions cycle_jump;
};

/// One reported state.
struct StateRecord {
  int trial = 0;             ///< 1-based
  /// The trial was skipped by a cycle jump: the values are extrapolated linearly in the trial count
  /// from the last two trials before the jump (at the same report of the trial), not solved.
  bool extrapolated = false;
  double time_s = 0.0;       ///< time within the trial
  double global_time_s = 0.0;
  double pressure_Pa = 0.0;
  double angle_deg = 0.0;
  double cavity_volume_m3 = 0.0;
  double plane_rms_m = 0.0;
};

struct QuasiStaticStats {
  long states = 0;           ///< equilibria solved (physical steps)
  long rejected_steps = 0;   ///< physical steps redone shorter
  long relaxation_iterations = 0;
  double wall_s = 0.0;
  long cycle_jumps = 0;          ///< cycle jumps taken
  long trials_extrapolated = 0;  ///< trials skipped by them (reported as extrapolated)
};

/// Everything needed to continue a run exactly where it stopped.
struct QuasiStaticCheckpoint {
  std::size_t next_segment = 0;
  double dt_suggest_s = 0.0;
  double last_angle_deg = 0.0;
  Eigen::VectorXd u;
  std::vector<double> state;
  std::vector<double> path_p;
  std::vector<Eigen::VectorXd> path_u;
  QuasiStaticStats stats;
  /// The step control's memory of the last accepted step (empty when it has none): per point
  /// (damage, viscous strain) at its start (error control only) and end, its length and load rate.
  std::vector<double> hist_prev, hist_cur;
  double h_prev_s = 0.0, rate_prev_Pa_s = 0.0;
  /// Drive control only: per point the linear drive D (Assembler::linear_drives) at the last accepted
  /// step's start and end (empty when there is none).
  std::vector<double> drive_prev, drive_cur;
  bool damage_grew = false;  ///< drive control: some point's damage grew in the last accepted step
  /// Drive control: per point the stress (viscous-strain units) that the damage changes it took
  /// without the error control's estimate could move, summed over the run (empty: none yet).
  std::vector<double> unchecked_damage;
  /// The first step of the last falling [0] and rising [1] ramp since the last release, as the
  /// pressure increment the control suggested after it (Pa; 0 = none): the next ramp's first guess.
  double ramp_start_dp_Pa[2] = {0.0, 0.0};
  /// Cycle jumping only: the histories at the last (up to 3) consecutive trial ends, the reports of
  /// those trials and those of the current trial so far.
  std::vector<std::vector<double>> cycle_ends;
  std::vector<std::vector<StateRecord>> cycle_reports;
  std::vector<StateRecord> trial_reports;

  void write(std::ostream& os) const;
  /// Throws InputError when the stream is not a checkpoint of a model with `dofs` and `state_size`.
  static QuasiStaticCheckpoint read(std::istream& is, std::size_t dofs, std::size_t state_size);
};

class QuasiStaticRun {
 public:
  using Observer = std::function<void(const StateRecord&, const Eigen::VectorXd& u, const std::vector<double>& state)>;
  using CheckpointSink = std::function<void(const QuasiStaticCheckpoint&)>;
  QuasiStaticRun(const Assembler& assembler, QuasiStaticOptions options);

  /// Runs every trial of `load`; calls `observer` at every report time and `sink` (if given)
  /// after every segment. With `resume`, continues from that checkpoint.
  void run(const LoadHistory& load, const Observer& observer, const CheckpointSink& sink = nullptr,
           const QuasiStaticCheckpoint* resume = nullptr);

  const Eigen::VectorXd& u() const { return u_; }
  const std::vector<double>& state() const { return state_; }
  const StaticSolver& static_solver() const { return newton_; }
  const QuasiStaticStats& stats() const { return stats_; }

  /// The run's load segments (QuasiStaticCheckpoint::next_segment counts them): between trials a
  /// release (t0 = t1 = 0, g0 = g1, p1 = 0), the rest (t0 = t1 = 0, g1 > g0) and the jump to the
  /// trial's first pressure; then the intervals between the trial's breakpoints and report times.
  struct Segment {
    int trial;               ///< 0-based
    double t0, t1;           ///< trial-local times
    double g0, g1;           ///< global times
    double p0, p1;           ///< pressures at the ends (linear in between)
    bool report;             ///< a report is due at t1
  };
  static std::vector<Segment> segments(const LoadHistory& load);

 private:
  /// Cycle jumping at the end of the trial whose last segment is segs[i] (engine/cycle_jump.h):
  /// records the trial's end, and when (3) allows a jump by N, extrapolates the history, reports
  /// the N skipped trials as extrapolated and returns the index of the last skipped segment (else i).
  std::size_t end_of_trial(const std::vector<Segment>& segs, std::size_t i, const Observer& observer);
  std::string failure_note() const;  ///< where damage laws report failed points ("" = none)
  /// The run's state from a checkpoint (run's resume), and the checkpoint of the state after the
  /// segments before `next_segment`: the same fields, one way and the other.
  void restore(const QuasiStaticCheckpoint& c);
  QuasiStaticCheckpoint checkpoint(std::size_t next_segment) const;
  /// The state at the end of reported segment s (its angle unwrapped from the last report's).
  StateRecord report(const Segment& s);
  /// The segment's physical time in steps whose length the history control chooses (time_tol,
  /// time_control), rejecting and retrying a step whose history moved too far or whose
  /// equilibrium failed.
  void solve_segment(const Segment& s);
  /// A segment of no physical time, or of a model without history: one equilibrium (when the load
  /// changes), and the step control's memory reset (a jump or an elastic state makes it stale).
  void solve_instant_segment(const Segment& s);
  /// The PhysicsError of a segment that took more than max_segment_steps steps.
  PhysicsError stalled(const Segment& s, double t, double last_h, double last_change, int last_element) const;
  /// How a physical step moved the history, as the step control measures it (quasi_static.cpp).
  struct StepMeasure;
  /// The step control's measure of the step of length h just solved (from state_saved to state_);
  /// hold_start: drive control's first step of a hold, where only the damage's change counts.
  StepMeasure measure_step(const std::vector<double>& state_saved, double h, bool hold_start);
  /// measure_step under time_control = "drive": per point, Milne's estimate where damage moves
  /// beyond its unchecked budget, else the drives' curvature error.
  void measure_drive_step(const std::vector<double>& state_saved, double h, bool hold_start, StepMeasure& sm);
  /// The step the control suggests after a step of length h that `sm` measured: after a rejection
  /// at most h (at least 0.2 h), else within [0.5 h, 2 h]; always within [min_dt_s, max_dt_s] (a
  /// rejection: at least min_dt_s).
  double next_step(double h, const StepMeasure& sm, bool rejected) const;
  /// How a segment of physical time starts: its load rate (Pa/s), the direction of a ramp (1 up,
  /// 0 down: ramp_start_dp_'s index), whether it is a ramp after a hold (its first step, when the
  /// control set its length, then sets ramp_start_dp_) and whether it is drive control's first step
  /// of a hold.
  struct SegmentStart {
    double rate = 0.0;
    int dir = 0;
    bool ramp_start = false, hold_start = false;
  };
  /// The first step of segment s (span > 0) into dt_suggest_: from the last ramp's start after a
  /// hold, from the relaxation times at the start of a hold under drive control; a kink of the
  /// load forgets the previous step.
  SegmentStart start_segment(const Segment& s);
  /// An accepted step of length h at load rate `rate`: the step control's memory moves on by one step.
  void accept_step(StepMeasure& sm, double h, double rate);
  void equilibrium(double p0, double p1, double t0, double t1);
  /// Drive control: the first step of a hold or rest, from the current viscous strains (see above).
  double first_hold_step() const;
  /// Drive control: the longest step within [lo, hi] whose predicted error is `target`, given the
  /// last step h's damage error ed (~ h^2) and each drive kind's largest |D''| (c_kind).
  double drive_step(double h, double ed, const std::vector<double>& c_kind, double target, double lo, double hi) const;

  const Assembler& asm_;
  QuasiStaticOptions opt_;
  StaticSolver newton_;
  Eigen::VectorXd u_;
  std::vector<double> state_;
  QuasiStaticStats stats_;
  double last_angle_ = 0.0;
  double dt_suggest_ = 0.0;
  bool rate_dependent_ = false;
  // The last accepted step, as in the checkpoint (hist_cur_: the current history's scalars).
  std::vector<double> hist_prev_, hist_cur_;
  double h_prev_ = 0.0, rate_prev_ = 0.0;
  double ramp_start_dp_[2] = {0.0, 0.0};  // as QuasiStaticCheckpoint::ramp_start_dp_Pa
  // Drive control: per point the index of its law's LinearDrive in drive_kinds_ (-1: none), and D at
  // the last accepted step's start and end (as the checkpoint's drive_prev, drive_cur).
  std::vector<int> drive_kind_;
  std::vector<Material::LinearDrive> drive_kinds_;
  std::vector<double> drive_prev_, drive_cur_;
  bool damage_grew_ = false;
  std::vector<double> unchecked_;  // as the checkpoint's unchecked_damage
  // Cycle jumping, as the checkpoint's cycle_ends, cycle_reports, trial_reports.
  std::vector<std::vector<double>> cycle_ends_;
  std::vector<std::vector<StateRecord>> cycle_reports_;
  std::vector<StateRecord> trial_reports_;
};

}  // namespace pneufem
