#include "damage/fatigue_uniform.h"

#include <algorithm>
#include <cassert>
#include <cmath>

#include "damage/decorator.h"

namespace pneufem {

UniformFatigue::UniformFatigue(MaterialPtr base, const UniformFatigueParams& p)
    : MaterialDecorator(std::move(base), "fatigue_uniform", kOwnState), p_(p) {
  const std::string& me = effect();
  detail::require_potential_base(this->base(), me);
  detail::require_finite(me, {{"a", p.a}, {"t0", p.t0_s}});
  detail::require(p.a > 0.0, me, "a must be > 0 (compliance growth per e-fold of the count), got " + short_num(p.a));
  detail::require(p.t0_s > 0.0, me, "t0 must be > 0 s (the count at the knee), got " + short_num(p.t0_s));
  floor_Pa_ = kFloorOfMu * this->base()->initial_shear_modulus();
}

double UniformFatigue::growth(double N) const { return p_.a * std::log1p(std::max(N, 0.0) / p_.t0_s); }

void UniformFatigue::init_state(std::span<double> state) const {
  state[0] = 0.0;  // N
  state[1] = 0.0;  // W_max
  base()->init_state(base_state(state));
}

void UniformFatigue::evaluate(std::span<const Mat3> F, const TimeStep& step, std::span<const double> state_old,
                              std::span<double> state_new, std::span<PointResponse> out, bool tangent) const {
  assert(step.dt_s >= 0.0);
  const std::size_t own = kOwnState, nb = static_cast<std::size_t>(base()->state_size());
  for (std::size_t q = 0; q < F.size(); ++q) {
    const detail::PointState ps = detail::point_state(state_old, state_new, q, own, nb);
    PointResponse& r = out[q];
    detail::evaluate_base(*base(), F[q], step, ps, r, tangent);
    const double W0 = r.psi_iso;
    const double N_old = ps.own_old.empty() ? 0.0 : ps.own_old[0];
    const double W_max_old = ps.own_old.empty() ? 0.0 : ps.own_old[1];
    // r = W0 / W_max (<= 1; 1 on the primary curve), 0 below the floor (fatigue_uniform.h).
    double rate = 0.0, drate_dW = 0.0;
    if (W0 >= W_max_old) {
      rate = W0 > floor_Pa_ ? 1.0 : 0.0;
    } else if (W_max_old > floor_Pa_) {
      rate = std::max(W0, 0.0) / W_max_old;
      drate_dW = W0 > 0.0 ? 1.0 / W_max_old : 0.0;
    }
    const double N_new = N_old + step.dt_s * rate;
    const double s = 1.0 / (1.0 + growth(N_new));
    if (!ps.own_new.empty()) {
      ps.own_new[0] = N_new;
      ps.own_new[1] = std::max(W_max_old, W0);
    }
    if (tangent) {
      const double ds_dW = -s * s * p_.a / (p_.t0_s + N_new) * step.dt_s * drate_dW;
      r.A_iso *= s;
      if (ds_dW != 0.0) {
        const Vec9 p0 = flatten(r.P_iso);
        r.A_iso += ds_dW * p0 * p0.transpose();
      }
    }
    r.P_iso *= s;
    r.psi_iso *= s;
  }
}

PointFields UniformFatigue::fields(std::span<const double> state) const {
  PointFields f = base()->fields(base_state(state));
  const double D = growth(state[0]);
  f.damage = detail::combine_damage(D / (1.0 + D), f.damage);
  f.fatigue_damage = detail::combine_damage(D / (1.0 + D), f.fatigue_damage);
  f.W_max = std::max(f.W_max, state[1]);
  return f;
}

}  // namespace pneufem
