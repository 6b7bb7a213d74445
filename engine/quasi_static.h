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
// The run is a list of segments (the intervals between the load's breakpoints and report
// times, plus the rest between trials). After each segment the full state can be checkpointed;
// resuming from a checkpoint continues bit-for-bit as the uninterrupted run would.
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "engine/assembly.h"
#include "engine/load_history.h"
#include "engine/relaxation.h"
#include "engine/static_solver.h"

namespace pneufem {

enum class EquilibriumMethod { Newton, Relaxation };
enum class TimeControl { Change, Error };

struct QuasiStaticOptions {
  EquilibriumMethod method = EquilibriumMethod::Newton;
  StaticOptions newton;
  RelaxationOptions relaxation;
  double time_tol = 0.01;   ///< max change (Change) or local-error estimate (Error) of damage / viscous strain per physical step
  TimeControl time_control = TimeControl::Change;
  double min_dt_s = 1e-3;   ///< smallest physical step
  double max_dt_s = 4.0;    ///< largest physical step (rate-dependent materials only)
  /// Physical steps (accepted + rejected) allowed in one load segment (a ramp, a hold, a rest)
  /// before the run stops with the element whose history changes fastest: a history that keeps
  /// the step near min_dt_s would otherwise look like a hang (tens of thousands of Newton solves).
  long max_segment_steps = 5000;
};

/// One reported state.
struct StateRecord {
  int trial = 0;             ///< 1-based
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
  /// The first step of the last falling [0] and rising [1] ramp since the last release, as the
  /// pressure increment the control suggested after it (Pa; 0 = none): the next ramp's first guess.
  double ramp_start_dp_Pa[2] = {0.0, 0.0};

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

 private:
  struct Segment {
    int trial;               ///< 0-based
    double t0, t1;           ///< trial-local times
    double g0, g1;           ///< global times
    double p0, p1;           ///< pressures at the ends (linear in between)
    bool report;             ///< a report is due at t1
  };
  static std::vector<Segment> segments(const LoadHistory& load);
  std::string failure_note() const;  ///< where damage laws report failed points ("" = none)
  void solve_segment(const Segment& s);
  void equilibrium(double p0, double p1, double t0, double t1);

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
};

}  // namespace pneufem
