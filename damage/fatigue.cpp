#include "damage/fatigue.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

#include "damage/decorator.h"

namespace pneufem {

namespace {
// Floor of the stored integrity 1 - d: keeps it strictly positive even if 1/(1 + a) underflows after
// an absurd overload (it is never reached with finite drivers in practice).
constexpr double kMinIntegrity = std::numeric_limits<double>::min();

/// Backward-Euler integrity update: the root s in (0, s_old] of s + a s^n = s_old, and ds/da.
struct IntegrityUpdate {
  double s = 1.0;
  double ds_da = 0.0;
};
IntegrityUpdate integrity_update(double s_old, double a, double n) {
  IntegrityUpdate u;
  if (a == 0.0) {
    u.s = s_old;
    u.ds_da = -std::pow(s_old, n);
    return u;
  }
  if (n == 1.0) {
    u.s = s_old / (1.0 + a);
  } else {
    // f(s) = s + a s^n - s_old is increasing and convex on s > 0 with f(s_old) >= 0: Newton from
    // s_old decreases monotonically to the root (never overshoots below it, so s stays > 0).
    // Stop once a step no longer changes s beyond rounding; 60 iterations cover any a that leaves s
    // above kMinIntegrity (quadratic once near the root).
    double s = s_old;
    for (int it = 0; it < 60; ++it) {
      const double sn1 = std::pow(s, n - 1.0);
      const double f = s + a * sn1 * s - s_old;
      const double step = f / (1.0 + n * a * sn1);
      const double next = s - step;
      if (!(next > 0.0)) {  // only possible through rounding at absurd overloads
        s = s * 0.5;
        continue;
      }
      if (std::abs(step) <= 4.0 * std::numeric_limits<double>::epsilon() * s) {
        s = next;
        break;
      }
      s = next;
    }
    u.s = s;
  }
  u.s = std::max(u.s, kMinIntegrity);
  // Implicit differentiation of s + a s^n = s_old: ds/da = -s^n / (1 + n a s^(n-1)).
  const double sn1 = n == 1.0 ? 1.0 : std::pow(u.s, n - 1.0);
  u.ds_da = -sn1 * u.s / (1.0 + n * a * sn1);
  return u;
}
}  // namespace

FatigueRate fatigue_rate(double X, const FatigueParams& p) {
  const double X_th = p.driver == FatigueDriver::energy ? p.W_th_Pa : p.lambda_th;
  FatigueRate r;
  r.X = X;
  const double x = X / X_th - 1.0;
  if (!(x > 0.0)) return r;  // at or below the threshold: no damage growth
  r.g = std::pow(x, p.q);
  r.dg_dX = p.q * std::pow(x, p.q - 1.0) / X_th;
  return r;
}

FatigueDamage::FatigueDamage(MaterialPtr base, const FatigueParams& p) : base_(std::move(base)), p_(p) {
  const std::string me = "fatigue";
  detail::require_split_base(base_, me);
  detail::require_potential_base(base_, me);
  detail::require_finite(me, {{"tau", p.tau_s}, {"q", p.q}, {"d_fail", p.d_fail}, {"n", p.n}});
  if (p.driver == FatigueDriver::energy) {
    detail::require_finite(me, {{"W_th", p.W_th_Pa}});
    detail::require(p.W_th_Pa > 0.0, me,
                    "W_th must be > 0 Pa (threshold isochoric energy density below which no damage grows), got " +
                        detail::num(p.W_th_Pa));
  } else {
    detail::require_finite(me, {{"lambda_th", p.lambda_th}});
    detail::require(p.lambda_th > 1.0, me,
                    "lambda_th must be > 1 (threshold largest principal stretch), got " + detail::num(p.lambda_th));
  }
  detail::require(p.tau_s > 0.0, me, "tau must be > 0 s (time scale of the damage rate), got " + detail::num(p.tau_s));
  detail::require(p.q >= 1.0, me,
                  "q must be >= 1 (exponent of the threshold excess; q > 1 gives a continuous tangent), got " +
                      detail::num(p.q));
  detail::require(p.n >= 1.0 && p.n <= 20.0, me,
                  "n must lie in [1, 20] (integrity exponent: 1 = first-order kinetics, larger saturates "
                  "sooner), got " + detail::num(p.n));
  detail::require(p.d_fail > 0.0 && p.d_fail < 1.0, me,
                  "d_fail must lie in (0, 1) (damage at which a point counts as failed), got " + detail::num(p.d_fail));
}

void FatigueDamage::init_state(std::span<double> state) const {
  state[0] = 1.0;  // integrity 1 - d
  base_->init_state(state.subspan(kOwnState));
}

void FatigueDamage::evaluate(std::span<const Mat3> F, const TimeStep& step, std::span<const double> state_old,
                             std::span<double> state_new, std::span<PointResponse> out, bool tangent) const {
  assert(step.dt_s >= 0.0);
  const std::size_t own = kOwnState, nb = static_cast<std::size_t>(base_->state_size());
  const double dt_over_tau = step.dt_s / p_.tau_s;
  const bool by_energy = p_.driver == FatigueDriver::energy;
  for (std::size_t q = 0; q < F.size(); ++q) {
    const detail::PointState ps = detail::point_state(state_old, state_new, q, own, nb);
    PointResponse& r = out[q];
    detail::evaluate_base(*base_, F[q], step, ps, r, tangent);
    const double s_old = ps.own_old.empty() ? 1.0 : ps.own_old[0];

    // Driver X and dX/dF.
    double X = r.psi_iso;
    Mat3 dX_dF = r.P_iso;
    if (!by_energy) {
      const Eigen::SelfAdjointEigenSolver<Mat3> eig(F[q].transpose() * F[q]);
      const Vec3 n = eig.eigenvectors().col(2);  // eigenvalues ascending
      X = std::sqrt(eig.eigenvalues()(2));
      dX_dF = F[q] * n * n.transpose() / X;
    }
    const FatigueRate rate = fatigue_rate(X, p_);
    const double a = dt_over_tau * rate.g;
    IntegrityUpdate upd = integrity_update(s_old, a, p_.n);
    // A failed point (d = d_fail) keeps its residual stiffness 1 - d_fail: the damage stops there
    // (fatigue.h, "Failure"). min(): a state that was already below (an older checkpoint) stays.
    const double s_floor = std::min(s_old, 1.0 - p_.d_fail);
    if (upd.s < s_floor) upd = {s_floor, 0.0};
    const double s_new = upd.s;
    if (!ps.own_new.empty()) ps.own_new[0] = s_new;
    if (tangent) {
      // d s_new / dF = ds/da (dt / tau) g'(X) dX/dF
      const double ds_dX = upd.ds_da * dt_over_tau * rate.dg_dX;
      r.A_iso *= s_new;
      if (ds_dX != 0.0) r.A_iso += ds_dX * flatten(r.P_iso) * flatten(dX_dF).transpose();
    }
    r.P_iso *= s_new;
    r.psi_iso *= s_new;
  }
}

PointFields FatigueDamage::fields(std::span<const double> state) const {
  PointFields f = base_->fields(state.subspan(kOwnState));
  const double d = 1.0 - state[0];
  f.damage = detail::combine_damage(d, f.damage);
  f.failed = f.failed || state[0] <= 1.0 - p_.d_fail;  // the integrity floor, bit for bit (evaluate)
  f.fatigue_damage = damage(state);
  return f;
}

}  // namespace pneufem
