#pragma once
// Quasi-static march through a load history: a sequence of static equilibria, each with the
// material history committed at the previous one, in physical time (so rate-dependent laws
// evolve between states). Equilibria come from Newton (default) or dynamic relaxation; both
// use the same element and material code and the same residual criterion.
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "engine/assembly.h"
#include "engine/explicit.h"
#include "engine/load_history.h"
#include "engine/static_solver.h"

namespace pneufem {

enum class EquilibriumMethod { Newton, Relaxation };

struct QuasiStaticOptions {
  EquilibriumMethod method = EquilibriumMethod::Newton;
  StaticOptions newton;
  RelaxationOptions relaxation;
  double max_dt_s = 0.0;  ///< > 0: split long constant-pressure intervals into steps <= this
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
  long states = 0;
  long relaxation_iterations = 0;
  double wall_s = 0.0;
};

class QuasiStaticRun {
 public:
  using Observer = std::function<void(const StateRecord&, const Eigen::VectorXd& u, const std::vector<double>& state)>;
  QuasiStaticRun(const Assembler& assembler, QuasiStaticOptions options);

  /// Runs every trial of `load`; calls `observer` at every output time.
  void run(const LoadHistory& load, const Observer& observer);

  const Eigen::VectorXd& u() const { return u_; }
  const std::vector<double>& state() const { return state_; }
  const StaticSolver& static_solver() const { return newton_; }
  const QuasiStaticStats& stats() const { return stats_; }

 private:
  void step(double p0, double p1, double t0, double t1);

  const Assembler& asm_;
  QuasiStaticOptions opt_;
  StaticSolver newton_;
  Eigen::VectorXd u_;
  std::vector<double> state_;
  QuasiStaticStats stats_;
  double last_angle_ = 0.0;
};

}  // namespace pneufem
