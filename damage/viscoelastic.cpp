#include "damage/viscoelastic.h"

#include <cassert>
#include <cmath>

#include "damage/decorator.h"

namespace pneufem {

namespace {

// Symmetric tensor <-> 6 doubles in the order (11, 22, 33, 23, 13, 12).
Mat3 unpack(std::span<const double> v) {
  Mat3 S;
  S << v[0], v[5], v[4],  //
      v[5], v[1], v[3],   //
      v[4], v[3], v[2];
  return S;
}
void pack(const Mat3& S, std::span<double> v) {
  v[0] = S(0, 0);
  v[1] = S(1, 1);
  v[2] = S(2, 2);
  v[3] = S(1, 2);
  v[4] = S(0, 2);
  v[5] = S(0, 1);
}

// k(x) = (1 - exp(-x)) / x, with k(0) = 1; expm1 keeps it accurate for small x.
double k_factor(double x) { return x > 0.0 ? -std::expm1(-x) / x : 1.0; }

std::string term(const char* key, std::size_t i) { return std::string(key) + "_" + std::to_string(i + 1); }

}  // namespace

ViscoParams prony_from_abaqus(const std::vector<double>& g, const std::vector<double>& tau_s) {
  const std::string me = "viscoelastic";
  double sum = 0.0;
  for (std::size_t i = 0; i < g.size(); ++i) {
    detail::require(std::isfinite(g[i]) && g[i] >= 0.0, me,
                    term("g", i) + " must be >= 0 (Abaqus relative modulus), got " + detail::num(g[i]));
    sum += g[i];
  }
  detail::require(sum < 1.0, me,
                  "the Abaqus g_i must sum to < 1 (the long-term modulus G_0 (1 - sum g) must stay positive), got " +
                      detail::num(sum));
  ViscoParams p{g, tau_s};
  for (double& gi : p.gamma) gi /= 1.0 - sum;
  return p;
}

Viscoelastic::Viscoelastic(MaterialPtr base, const ViscoParams& p) : base_(std::move(base)) {
  const std::string me = "viscoelastic";
  detail::require_split_base(base_, me);
  const std::size_t n = p.gamma.size();
  detail::require(n >= 1 && n <= kMaxTerms && p.tau_s.size() == n, me,
                  "gamma and tau need the same number of Prony terms, 1 to 3; got " + std::to_string(n) +
                      " gamma and " + std::to_string(p.tau_s.size()) + " tau");
  for (std::size_t i = 0; i < n; ++i) {
    detail::require(std::isfinite(p.gamma[i]) && p.gamma[i] >= 0.0, me,
                    term("gamma", i) + " must be >= 0 (stiffness of the branch relative to the long-term law), got " +
                        detail::num(p.gamma[i]));
    detail::require(std::isfinite(p.tau_s[i]) && p.tau_s[i] > 0.0, me,
                    term("tau", i) + " must be > 0 s (relaxation time), got " + detail::num(p.tau_s[i]));
    gamma_[i] = p.gamma[i];
    tau_[i] = p.tau_s[i];
    gamma_sum_ += p.gamma[i];
  }
  n_ = static_cast<int>(n);
  mu_inf_ = base_->initial_shear_modulus();
}

void Viscoelastic::init_state(std::span<double> state) const {
  const std::size_t own = static_cast<std::size_t>(own_state_size());
  for (std::size_t i = 0; i < own; ++i) state[i] = 0.0;  // S0 = 0 and Q_i = 0 in the virgin state
  base_->init_state(state.subspan(own));
}

void Viscoelastic::evaluate(std::span<const Mat3> F, const TimeStep& step, std::span<const double> state_old,
                            std::span<double> state_new, std::span<PointResponse> out, bool tangent) const {
  assert(step.dt_s >= 0.0);
  const std::size_t own = static_cast<std::size_t>(own_state_size()), nb = static_cast<std::size_t>(base_->state_size());
  std::array<double, kMaxTerms> decay{}, gk{};  // exp(-x_i), gamma_i k_i
  double c = 0.0;
  for (int i = 0; i < n_; ++i) {
    const double x = step.dt_s / tau_[i];
    decay[i] = std::exp(-x);
    gk[i] = gamma_[i] * k_factor(x);
    c += gk[i];
  }
  for (std::size_t q = 0; q < F.size(); ++q) {
    const detail::PointState ps = detail::point_state(state_old, state_new, q, own, nb);
    PointResponse& r = out[q];
    detail::evaluate_base(*base_, F[q], step, ps, r, tangent);
    const bool virgin = ps.own_old.empty();

    const Mat3 S0_trial = F[q].inverse() * r.P_iso;
    const Mat3 S0 = 0.5 * (S0_trial + S0_trial.transpose());
    const Mat3 S0_old = virgin ? Mat3::Zero() : unpack(ps.own_old.subspan(0, 6));
    Mat3 H = Mat3::Zero();
    double psi_branches = 0.0;
    for (int i = 0; i < n_; ++i) {
      const Mat3 Q_old = virgin ? Mat3::Zero() : unpack(ps.own_old.subspan(6 * (i + 1), 6));
      const Mat3 Q_new = decay[i] * Q_old + gk[i] * (S0 - S0_old);
      H += decay[i] * Q_old - gk[i] * S0_old;
      if (gamma_[i] > 0.0) psi_branches += Q_new.squaredNorm() / (4.0 * gamma_[i] * mu_inf_);
      if (!ps.own_new.empty()) pack(Q_new, ps.own_new.subspan(6 * (i + 1), 6));
    }
    if (!ps.own_new.empty()) pack(S0, ps.own_new.subspan(0, 6));

    if (tangent) {
      r.A_iso *= 1.0 + c;
      for (int i = 0; i < 3; ++i)  // + delta_ik H_JL
        for (int J = 0; J < 3; ++J)
          for (int L = 0; L < 3; ++L) r.A_iso(flat(i, J), flat(i, L)) += H(J, L);
    }
    r.P_iso = (1.0 + c) * r.P_iso + F[q] * H;
    r.psi_iso += psi_branches;
  }
}

PointFields Viscoelastic::fields(std::span<const double> state) const {
  const std::size_t own = static_cast<std::size_t>(own_state_size());
  PointFields f = base_->fields(state.subspan(own));
  Mat3 Q = Mat3::Zero();
  for (int i = 0; i < n_; ++i) Q += unpack(state.subspan(6 * (i + 1), 6));
  f.viscous_strain = Q.norm() / (2.0 * mu_inf_);
  return f;
}

}  // namespace pneufem
