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

/// Backward-Euler integrity update: the root s in (0, s_old] of s + a s^n = s_old (s_old for a = 0).
double integrity_root(double s_old, double a, double n) {
  if (a == 0.0) return s_old;
  double s = s_old;
  if (n == 1.0) {
    s = s_old / (1.0 + a);
  } else {
    // f(s) = s + a s^n - s_old is increasing and convex on s > 0 with f(s_old) >= 0: Newton from
    // s_old decreases monotonically to the root (never overshoots below it, so s stays > 0).
    // Stop once a step no longer changes s beyond rounding; 60 iterations cover any a that leaves s
    // above kMinIntegrity (quadratic once near the root).
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
  }
  return std::max(s, kMinIntegrity);
}

/// ds/da at the root s = integrity_root(s_old, a, n), by implicit differentiation of s + a s^n = s_old:
/// -s^n / (1 + n a s^(n-1)). Only the consistent tangent needs it.
double integrity_rate(double s, double s_old, double a, double n) {
  if (a == 0.0) return -std::pow(s_old, n);
  const double sn1 = n == 1.0 ? 1.0 : std::pow(s, n - 1.0);
  return -sn1 * s / (1.0 + n * a * sn1);
}

/// The trial integrity of one point: backward Euler over the increment (a = dt g / tau), then the
/// failure floor. evaluate() and stress() share it.
struct IntegrityUpdate {
  double s = 1.0;
  double a = 0.0;
  bool at_floor = false;  ///< held at the floor: ds/da = 0
};
IntegrityUpdate update_integrity(double s_old, double g, double dt_over_tau, const FatigueParams& p) {
  IntegrityUpdate u;
  u.a = dt_over_tau * g;
  u.s = integrity_root(s_old, u.a, p.n);
  // A failed point (d = d_fail) keeps its residual stiffness 1 - d_fail: the damage stops there
  // (fatigue.h, "Failure"). min(): a state that was already below (an older checkpoint) stays.
  const double s_floor = std::min(s_old, 1.0 - p.d_fail);
  if (u.s < s_floor) {
    u.s = s_floor;
    u.at_floor = true;
  }
  return u;
}

/// g = <X / X_th - 1>^q.
double growth_factor(double X, const FatigueParams& p) {
  const double X_th = p.driver == FatigueDriver::energy ? p.W_th_Pa : p.lambda_th;
  const double x = X / X_th - 1.0;
  return x > 0.0 ? std::pow(x, p.q) : 0.0;  // at or below the threshold: no damage growth
}

/// True when a cheap bound puts the largest principal stretch of F surely below lambda_th: then g = 0
/// whatever its exact value, and the eigenvalue problem (most of the cost of the stretch driver) is
/// skipped. With C = F^T F = (tr C / 3) I + dev C, lambda_max(C) <= tr C / 3 + sqrt(2/3) |dev C| (the
/// largest eigenvalue of a traceless symmetric tensor is at most sqrt(2/3) of its norm; equality when the
/// two smaller eigenvalues are equal, as in uniaxial tension). The relative margin 1e-6 exceeds the rounding of the bound and of the eigensolver
/// (~1e-14 of |C|) by orders of magnitude, so a point passed here would have x < 0 in growth_factor too.
/// A NaN fails the test and takes the exact path. F(k) is entry k = i + 3J of F, so that the same code
/// serves a Mat3 and a lane of a StressBatch (where the lane loop vectorises).
template <class Entry>
bool stretch_surely_below(const Entry& F, double lambda_th) {
  const double c00 = F(0) * F(0) + F(1) * F(1) + F(2) * F(2);
  const double c11 = F(3) * F(3) + F(4) * F(4) + F(5) * F(5);
  const double c22 = F(6) * F(6) + F(7) * F(7) + F(8) * F(8);
  const double c01 = F(0) * F(3) + F(1) * F(4) + F(2) * F(5);
  const double c02 = F(0) * F(6) + F(1) * F(7) + F(2) * F(8);
  const double c12 = F(3) * F(6) + F(4) * F(7) + F(5) * F(8);
  const double m = (c00 + c11 + c22) * (1.0 / 3.0), d0 = c00 - m, d1 = c11 - m, d2 = c22 - m;
  const double dev2 = d0 * d0 + d1 * d1 + d2 * d2 + 2.0 * (c01 * c01 + c02 * c02 + c12 * c12);
  return m + std::sqrt((2.0 / 3.0) * dev2) <= (1.0 - 1e-6) * lambda_th * lambda_th;
}
bool stretch_surely_below(const Mat3& F, double lambda_th) {
  return stretch_surely_below([&F](int k) { return F(k); }, lambda_th);
}

/// sqrt(lambda_max(F^T F)) from the eigenvalues alone. Eigen's tridiagonal QR iteration computes them
/// with the same operations whether or not it also accumulates the eigenvectors (which only the
/// tangent needs), so this is the tangent path's value bit for bit.
double max_principal_stretch(const Mat3& F) {
  const Eigen::SelfAdjointEigenSolver<Mat3> eig(F.transpose() * F, Eigen::EigenvaluesOnly);
  return std::sqrt(eig.eigenvalues()(2));  // eigenvalues ascending
}

/// g of one point for a force-only evaluation: F and the base's isochoric energy W0 of the point,
/// the non-local ratio rho (1 when local); `below` = stretch_surely_below(F, lambda_th / rho) when
/// already known. (rho = 1 multiplies exactly: the local law's bits.)
double force_only_growth(const Mat3& F, double W0, double rho, const FatigueParams& p, bool below) {
  if (p.driver == FatigueDriver::energy) return growth_factor(rho * W0, p);
  if (below) return 0.0;
  return growth_factor(rho * max_principal_stretch(F), p);
}
}  // namespace

FatigueRate fatigue_rate(double X, const FatigueParams& p) {
  const double X_th = p.driver == FatigueDriver::energy ? p.W_th_Pa : p.lambda_th;
  FatigueRate r;
  r.X = X;
  r.g = growth_factor(X, p);
  const double x = X / X_th - 1.0;
  if (x > 0.0) r.dg_dX = p.q * std::pow(x, p.q - 1.0) / X_th;
  return r;
}

FatigueDamage::FatigueDamage(MaterialPtr base, const FatigueParams& p)
    : MaterialDecorator(std::move(base), "fatigue", p.nonlocal_radius_m > 0.0 ? 2 : 1), p_(p) {
  const std::string& me = effect();
  detail::require_potential_base(this->base(), me);
  detail::require_finite(me, {{"tau", p.tau_s}, {"q", p.q}, {"d_fail", p.d_fail}, {"n", p.n}});
  if (p.driver == FatigueDriver::energy) {
    detail::require_finite(me, {{"W_th", p.W_th_Pa}});
    detail::require(p.W_th_Pa > 0.0, me,
                    "W_th must be > 0 Pa (threshold isochoric energy density below which no damage grows), got " +
                        short_num(p.W_th_Pa));
  } else {
    detail::require_finite(me, {{"lambda_th", p.lambda_th}});
    detail::require(p.lambda_th > 1.0, me,
                    "lambda_th must be > 1 (threshold largest principal stretch), got " + short_num(p.lambda_th));
  }
  detail::require(p.tau_s > 0.0, me, "tau must be > 0 s (time scale of the damage rate), got " + short_num(p.tau_s));
  detail::require(p.q >= 1.0, me,
                  "q must be >= 1 (exponent of the threshold excess; q > 1 gives a continuous tangent), got " +
                      short_num(p.q));
  detail::require(p.n >= 1.0 && p.n <= 20.0, me,
                  "n must lie in [1, 20] (integrity exponent: 1 = first-order kinetics, larger saturates "
                  "sooner), got " + short_num(p.n));
  detail::require(p.d_fail > 0.0 && p.d_fail < 1.0, me,
                  "d_fail must lie in (0, 1) (damage at which a point counts as failed), got " + short_num(p.d_fail));
}

void FatigueDamage::init_state(std::span<double> state) const {
  state[0] = 1.0;  // integrity 1 - d
  if (own_state_size() > 1) state[1] = 1.0;  // rho: no average known yet
  base()->init_state(base_state(state));
}

void FatigueDamage::jump_cycles(std::span<const double> before, std::span<const double> after, double cycles,
                                std::span<double> out) const {
  const std::size_t own = own_size();
  std::copy(after.begin(), after.begin() + static_cast<std::ptrdiff_t>(own), out.begin());  // rho: the last cycle's
  // z = s^(1-n) (n > 1) or -ln s (n = 1), linear in time at a constant driver (fatigue.h).
  const auto z_of = [&](double s) { return p_.n > 1.0 ? std::pow(s, 1.0 - p_.n) : -std::log(s); };
  const auto s_of = [&](double z) { return p_.n > 1.0 ? std::pow(z, -1.0 / (p_.n - 1.0)) : std::exp(-z); };
  const double s_after = after[0];
  const double dz = std::max(0.0, z_of(s_after) - z_of(before[0]));
  const double s_jump = s_of(z_of(s_after) + cycles * dz);
  out[0] = std::min(s_after, std::max(s_jump, 1.0 - p_.d_fail));  // never heals, stops at d_fail
  base()->jump_cycles(before.subspan(own), after.subspan(own), cycles, out.subspan(own));
}

double FatigueDamage::jump_error(std::span<const double> predicted, std::span<const double> computed) const {
  const std::size_t own = own_size();
  return std::max(std::abs(predicted[0] - computed[0]), base()->jump_error(predicted.subspan(own), computed.subspan(own)));
}

Material::NonlocalSpec FatigueDamage::nonlocal() const {
  if (!(p_.nonlocal_radius_m > 0.0)) return MaterialDecorator::nonlocal();
  return {p_.nonlocal_radius_m, p_.driver == FatigueDriver::energy ? "fatigue:energy" : "fatigue:stretch"};
}

double FatigueDamage::nonlocal_driver(const Mat3& F, std::span<const double> state) const {
  if (!(p_.nonlocal_radius_m > 0.0)) return MaterialDecorator::nonlocal_driver(F, state);
  if (p_.driver == FatigueDriver::max_principal_stretch) return max_principal_stretch(F);
  // W0: the base's isochoric energy at its committed state (as evaluate() sees it at dt = 0).
  PointResponse r;
  detail::evaluate_base(*base(), F, TimeStep{}, detail::PointState{{}, {}, base_state(state), {}}, r, false);
  return r.psi_iso;
}

void FatigueDamage::set_nonlocal_driver(std::span<double> state, double local, double average) const {
  if (!(p_.nonlocal_radius_m > 0.0)) return MaterialDecorator::set_nonlocal_driver(state, local, average);
  // rho = average / local; 1 where the local driver is ~0 (an unloaded point of the energy driver:
  // below any threshold either way) or not finite.
  const double scale = p_.driver == FatigueDriver::energy ? p_.W_th_Pa : 1.0;
  const double rho = local > 1e-9 * scale ? average / local : 1.0;
  state[1] = std::isfinite(rho) && rho > 0.0 ? rho : 1.0;
}

void FatigueDamage::evaluate(std::span<const Mat3> F, const TimeStep& step, std::span<const double> state_old,
                             std::span<double> state_new, std::span<PointResponse> out, bool tangent) const {
  assert(step.dt_s >= 0.0);
  const std::size_t own = own_size(), nb = static_cast<std::size_t>(base()->state_size());
  const double dt_over_tau = step.dt_s / p_.tau_s;
  const bool by_energy = p_.driver == FatigueDriver::energy;
  for (std::size_t q = 0; q < F.size(); ++q) {
    const detail::PointState ps = detail::point_state(state_old, state_new, q, own, nb);
    PointResponse& r = out[q];
    detail::evaluate_base(*base(), F[q], step, ps, r, tangent);
    const double s_old = ps.own_old.empty() ? 1.0 : ps.own_old[0];
    const double rho = own > 1 && !ps.own_old.empty() ? ps.own_old[1] : 1.0;  // non-local ratio (1: local)

    // Driver X (rho times the local one), its rate factor g and dX/dF (the tangent's). Below the
    // threshold g = dg/dX = 0, and dX/dF then drops out of the tangent (ds/dX = 0).
    FatigueRate rate;
    Mat3 dX_dF = rho * r.P_iso;
    if (!tangent) {
      const bool below = !by_energy && stretch_surely_below(F[q], p_.lambda_th / rho);
      rate.g = force_only_growth(F[q], r.psi_iso, rho, p_, below);
    } else if (by_energy) {
      rate = fatigue_rate(rho * r.psi_iso, p_);
    } else if (!stretch_surely_below(F[q], p_.lambda_th / rho)) {
      const Eigen::SelfAdjointEigenSolver<Mat3> eig(F[q].transpose() * F[q]);
      const Vec3 n = eig.eigenvectors().col(2);  // eigenvalues ascending
      const double lambda = std::sqrt(eig.eigenvalues()(2));
      rate = fatigue_rate(rho * lambda, p_);
      dX_dF = rho * (F[q] * n * n.transpose() / lambda);
    }
    const IntegrityUpdate upd = update_integrity(s_old, rate.g, dt_over_tau, p_);
    const double s_new = upd.s;
    if (!ps.own_new.empty()) {
      ps.own_new[0] = s_new;
      if (own > 1) ps.own_new[1] = rho;
    }
    if (tangent) {
      // d s_new / dF = ds/da (dt / tau) g'(X) dX/dF
      const double ds_da = upd.at_floor ? 0.0 : integrity_rate(s_new, s_old, upd.a, p_.n);
      const double ds_dX = ds_da * dt_over_tau * rate.dg_dX;
      r.A_iso *= s_new;
      if (ds_dX != 0.0) r.A_iso += ds_dX * flatten(r.P_iso) * flatten(dX_dF).transpose();
    }
    r.P_iso *= s_new;
    r.psi_iso *= s_new;
  }
}

void FatigueDamage::stress(StressBatch& b, const TimeStep& step, std::span<const double> state_old,
                           std::span<double> state_new) const {
  assert(step.dt_s >= 0.0);
  const std::size_t own = own_size(), nb = static_cast<std::size_t>(base()->state_size());
  if (!detail::stress_base(*base(), b, step, state_old, state_new, own))
    return Material::stress(b, step, state_old, state_new);
  const double dt_over_tau = step.dt_s / p_.tau_s;
  const bool by_energy = p_.driver == FatigueDriver::energy;
  double rho[StressBatch::kLanes];  // non-local ratio per lane (1: local, and for the padding lanes)
  for (int l = 0; l < StressBatch::kLanes; ++l)
    rho[l] = own > 1 && !state_old.empty() && l < b.n ? state_old[static_cast<std::size_t>(l) * (own + nb) + 1] : 1.0;
  bool below[StressBatch::kLanes] = {};  // the stretch driver's bound, all lanes at once
  if (!by_energy)
    for (int l = 0; l < StressBatch::kLanes; ++l)
      below[l] = stretch_surely_below([&b, l](int k) { return b.F[k][l]; }, p_.lambda_th / rho[l]);
  for (int l = 0; l < b.n; ++l) {
    const detail::PointState ps = detail::point_state(state_old, state_new, static_cast<std::size_t>(l), own, nb);
    const double s_old = ps.own_old.empty() ? 1.0 : ps.own_old[0];
    const double g = force_only_growth(b.F_of(l), b.psi_iso[l], rho[l], p_, below[l]);
    const double s_new = update_integrity(s_old, g, dt_over_tau, p_).s;
    if (!ps.own_new.empty()) {
      ps.own_new[0] = s_new;
      if (own > 1) ps.own_new[1] = rho[l];
    }
    for (int k = 0; k < 9; ++k) b.P_iso[k][l] *= s_new;
    b.psi_iso[l] *= s_new;
  }
}

PointFields FatigueDamage::fields(std::span<const double> state) const {
  PointFields f = base()->fields(base_state(state));
  const double d = 1.0 - state[0];
  f.damage = detail::combine_damage(d, f.damage);
  f.failed = f.failed || state[0] <= 1.0 - p_.d_fail;  // the integrity floor, bit for bit (evaluate)
  f.fatigue_damage = damage(state);
  return f;
}

}  // namespace pneufem
