#include "damage/mullins.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>

#include "damage/decorator.h"

namespace pneufem {

MullinsEta ogden_roxburgh(double W_dev, double W_max, const MullinsParams& p) {
  MullinsEta e;
  // Primary curve (eta = 1, phi(1) = 0), and the virgin state: nothing to soften before any loading
  // (a W_dev of -1e-12 Pa from rounding at a pure dilatation is not an unloading).
  if (W_dev >= W_max || W_max <= 0.0) return e;
  const double D = p.m_Pa + p.beta * W_max;  // > 0: W_max > 0 and m, beta >= 0, not both 0
  const double z = (W_max - W_dev) / D, ez2 = std::exp(-z * z);
  e.eta = 1.0 - std::erf(z) / p.r;
  e.deta_dW = 2.0 / (p.r * std::sqrt(std::numbers::pi) * D) * ez2;
  e.phi = (1.0 - e.eta) * W_max - D * (1.0 - ez2) / (p.r * std::sqrt(std::numbers::pi));
  return e;
}

Mullins::Mullins(MaterialPtr base, const MullinsParams& p)
    : MaterialDecorator(std::move(base), "mullins", kOwnState), p_(p) {
  const std::string& me = effect();
  detail::require_potential_base(this->base(), me);
  detail::require_finite(me, {{"r", p.r}, {"m", p.m_Pa}, {"beta", p.beta}});
  detail::require(p.r > 1.0, me, "r must be > 1 (the largest stress softening is 1/r), got " + short_num(p.r));
  detail::require(p.m_Pa >= 0.0, me, "m must be >= 0 Pa (an energy density), got " + short_num(p.m_Pa));
  detail::require(p.beta >= 0.0, me, "beta must be >= 0, got " + short_num(p.beta));
  detail::require(p.m_Pa > 0.0 || p.beta > 0.0, me,
                  "m and beta cannot both be 0 (the erf argument would divide by zero); set m > 0 Pa, the "
                  "energy-density scale over which the softening develops");
}

void Mullins::init_state(std::span<double> state) const {
  state[0] = 0.0;  // W_max
  state[1] = 1.0;  // eta
  base()->init_state(base_state(state));
}

void Mullins::jump_cycles(std::span<const double> before, std::span<const double> after, double cycles,
                          std::span<double> out) const {
  out[0] = after[0] + cycles * std::max(0.0, after[0] - before[0]);  // W_max: linear per cycle (mullins.h)
  out[1] = after[1];                                                 // eta_last: output only
  base()->jump_cycles(before.subspan(kOwnState), after.subspan(kOwnState), cycles, out.subspan(kOwnState));
}

double Mullins::jump_error(std::span<const double> predicted, std::span<const double> computed) const {
  const double inner = base()->jump_error(predicted.subspan(kOwnState), computed.subspan(kOwnState));
  const double dW = std::abs(predicted[0] - computed[0]);
  if (dW == 0.0) return inner;
  const double D = p_.m_Pa + p_.beta * std::min(predicted[0], computed[0]);
  // The bound of mullins.h; with m = 0 and a virgin point (D = 0) the softening can change by up to 1/r.
  const double e = D > 0.0 ? std::min(1.0 / p_.r, 2.0 * dW / (p_.r * std::sqrt(std::numbers::pi) * D)) : 1.0 / p_.r;
  return std::max(inner, e);
}

namespace {
/// One point's Ogden-Roxburgh update from the base's isochoric energy W_dev, shared by evaluate() and
/// stress(): writes the trial state [W_max, eta] and returns the softening, or nothing on the primary
/// curve and in the virgin state, where the base response is kept as is.
std::optional<MullinsEta> soften(double W_dev, const detail::PointState& ps, const MullinsParams& p) {
  const double W_max_old = ps.own_old.empty() ? 0.0 : ps.own_old[0];
  const double W_max = std::max(W_max_old, W_dev);
  const MullinsEta e = ogden_roxburgh(W_dev, W_max_old, p);
  if (!ps.own_new.empty()) {
    ps.own_new[0] = W_max;
    ps.own_new[1] = e.eta;
  }
  if (W_dev >= W_max_old || W_max_old <= 0.0) return std::nullopt;
  return e;
}
}  // namespace

void Mullins::evaluate(std::span<const Mat3> F, const TimeStep& step, std::span<const double> state_old,
                       std::span<double> state_new, std::span<PointResponse> out, bool tangent) const {
  const std::size_t own = kOwnState, nb = static_cast<std::size_t>(base()->state_size());
  for (std::size_t q = 0; q < F.size(); ++q) {
    const detail::PointState ps = detail::point_state(state_old, state_new, q, own, nb);
    PointResponse& r = out[q];
    detail::evaluate_base(*base(), F[q], step, ps, r, tangent);
    const double W_dev = r.psi_iso;
    const std::optional<MullinsEta> e = soften(W_dev, ps, p_);
    if (!e) continue;
    if (tangent) {
      const Vec9 p0 = flatten(r.P_iso);
      r.A_iso = e->eta * r.A_iso + e->deta_dW * p0 * p0.transpose();
    }
    r.P_iso *= e->eta;
    r.psi_iso = e->eta * W_dev + e->phi;
  }
}

void Mullins::stress(StressBatch& b, const TimeStep& step, std::span<const double> state_old,
                     std::span<double> state_new) const {
  const std::size_t own = kOwnState, nb = static_cast<std::size_t>(base()->state_size());
  if (!detail::stress_base(*base(), b, step, state_old, state_new, own))
    return Material::stress(b, step, state_old, state_new);
  for (int l = 0; l < b.n; ++l) {
    const detail::PointState ps = detail::point_state(state_old, state_new, static_cast<std::size_t>(l), own, nb);
    const double W_dev = b.psi_iso[l];
    const std::optional<MullinsEta> e = soften(W_dev, ps, p_);
    if (!e) continue;
    for (int k = 0; k < 9; ++k) b.P_iso[k][l] *= e->eta;
    b.psi_iso[l] = e->eta * W_dev + e->phi;
  }
}

PointFields Mullins::fields(std::span<const double> state) const {
  PointFields f = base()->fields(base_state(state));
  f.W_max = state[0];
  f.damage = detail::combine_damage(1.0 - state[1], f.damage);
  return f;
}

}  // namespace pneufem
