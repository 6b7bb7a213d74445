#include "engine/quasi_static.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <sstream>

#include "engine/angle.h"
#include "materials/errors.h"

namespace pneufem {

QuasiStaticRun::QuasiStaticRun(const Assembler& assembler, QuasiStaticOptions options)
    : asm_(assembler), opt_(options), newton_(assembler, options.newton) {
  u_ = Eigen::VectorXd::Zero(asm_.num_dofs());
  state_ = asm_.initial_state();
}

void QuasiStaticRun::step(double p0, double p1, double t0, double t1) {
  if (opt_.method == EquilibriumMethod::Newton) {
    newton_.advance(p0, p1, t0, t1, state_, u_);
  } else {
    std::vector<double> trial(state_.size());
    RelaxationReport r = relax(asm_, p1, TimeStep{t1, t1 - t0}, state_, trial, u_, opt_.relaxation);
    stats_.relaxation_iterations += r.iterations;
    if (!r.converged) {
      std::ostringstream s;
      s << "dynamic relaxation did not converge at p = " << p1 * 1e-3 << " kPa, t = " << t1 << " s in "
        << r.iterations << " iterations (residual " << r.residual_N << " N). Hint: raise "
        << "solver.max_iterations or use solver.method = \"newton\".";
      throw PhysicsError(s.str(), -1, t1);
    }
    state_.swap(trial);
  }
  ++stats_.states;
}

void QuasiStaticRun::run(const LoadHistory& load, const Observer& observer) {
  const auto wall0 = std::chrono::steady_clock::now();
  double t_global = 0.0;
  for (std::size_t k = 0; k < load.trials.size(); ++k) {
    const TrialLoad& tl = load.trials[k];
    if (k > 0 && load.rest_between_trials_s > 0.0) {
      // Unloaded rest between trials: advance the history at the pressure the trial ended with
      // released to zero.
      const double p_end = load.trials[k - 1].pressure_Pa.back();
      step(p_end, 0.0, t_global, t_global + load.rest_between_trials_s);
      t_global += load.rest_between_trials_s;
    } else if (k > 0) {
      step(load.trials[k - 1].pressure_Pa.back(), tl.pressure_Pa.front(), t_global, t_global);
    }
    std::vector<double> times = tl.time_s;
    times.insert(times.end(), tl.output_s.begin(), tl.output_s.end());
    std::sort(times.begin(), times.end());
    times.erase(std::unique(times.begin(), times.end(), [](double a, double b) { return std::abs(a - b) < 1e-12; }),
                times.end());
    // Split long intervals (rate laws need resolved physical time).
    if (opt_.max_dt_s > 0.0) {
      std::vector<double> fine;
      for (std::size_t i = 0; i < times.size(); ++i) {
        if (i > 0) {
          const double gap = times[i] - times[i - 1];
          const int n = static_cast<int>(std::ceil(gap / opt_.max_dt_s - 1e-9));
          for (int j = 1; j < n; ++j) fine.push_back(times[i - 1] + gap * j / n);
        }
        fine.push_back(times[i]);
      }
      times.swap(fine);
    }
    std::size_t next_out = 0;
    std::vector<double> outs = tl.output_s;
    std::sort(outs.begin(), outs.end());
    double t_prev = times.front();
    double p_prev = tl.pressure(t_prev);
    for (double t : times) {
      const double p = tl.pressure(t);
      if (t > t_prev || p != p_prev) step(p_prev, p, t_global + t_prev, t_global + t);
      t_prev = t;
      p_prev = p;
      while (next_out < outs.size() && outs[next_out] <= t + 1e-12) {
        StateRecord rec;
        rec.trial = static_cast<int>(k) + 1;
        rec.time_s = outs[next_out];
        rec.global_time_s = t_global + outs[next_out];
        rec.pressure_Pa = p;
        const AngleResult a = bending_angle(asm_.model(), u_);
        rec.angle_deg = unwrap_deg(a.angle_deg, last_angle_);
        last_angle_ = rec.angle_deg;
        rec.plane_rms_m = a.plane_rms_m;
        rec.cavity_volume_m3 = asm_.cavity_volume(u_);
        if (observer) observer(rec, u_, state_);
        ++next_out;
      }
    }
    t_global += tl.duration();
  }
  stats_.wall_s += std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
}

}  // namespace pneufem
