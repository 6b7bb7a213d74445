#include "damage/viscoelastic.h"

#include <algorithm>
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

// ---- Structure-of-arrays arithmetic of the batched stress (material.h: StressBatch). Tensor component
// k = i + 3J of lane l is at [k][l]. Each function performs the operations of the Eigen expression it
// replaces in the order Eigen 3.4 evaluates it at the baseline ISA (SSE2 packets of 2 doubles, as in
// materials/invariant_kernel.h), so the results are evaluate()'s bit for bit (test
// DecoratorBattery.StressBatchIsEvaluateBitForBit, which would catch another ISA's order). Only the lanes
// 0..n-1 in use are computed: the engine's batches with history hold one element (4 of the 8 lanes for
// a quadratic tet).
constexpr int N = StressBatch::kLanes;
// Packed symmetric storage (pack/unpack): component k of the full tensor is packed entry kUnpacked[k].
constexpr int kUnpacked[9] = {0, 5, 4, 5, 1, 3, 4, 3, 2};
constexpr int kPacked[6] = {0, 4, 8, 7, 6, 3};  // packed entry v holds component kPacked[v]

/// C = A B as Eigen's 3x3 product: rows 0-1 summed left to right (its packet path), row 2 as
/// a0 b0 + (a1 b1 + a2 b2) (its scalar reduction).
void product(const double A[9][N], const double B[9][N], double C[9][N], int n) {
  for (int j = 0; j < 3; ++j) {
    for (int i = 0; i < 2; ++i)
      for (int l = 0; l < n; ++l)
        C[i + 3 * j][l] = (A[i][l] * B[3 * j][l] + A[i + 3][l] * B[3 * j + 1][l]) + A[i + 6][l] * B[3 * j + 2][l];
    for (int l = 0; l < n; ++l)
      C[2 + 3 * j][l] = A[2][l] * B[3 * j][l] + (A[5][l] * B[3 * j + 1][l] + A[8][l] * B[3 * j + 2][l]);
  }
}

/// F^-1 as Eigen's 3x3 inverse: cofactor(i, j) = F(i1, j1) F(i2, j2) - F(i1, j2) F(i2, j1) with
/// i1 = i+1, i2 = i+2 (mod 3), det = (c00 F00 + c10 F10) + c20 F20, F^-1(r, c) = cofactor(c, r) (1 / det).
void inverse(const double F[9][N], double Finv[9][N], int n) {
  const auto cofactor = [&F](int i, int j, int l) {
    const int i1 = (i + 1) % 3, i2 = (i + 2) % 3, j1 = (j + 1) % 3, j2 = (j + 2) % 3;
    return F[i1 + 3 * j1][l] * F[i2 + 3 * j2][l] - F[i1 + 3 * j2][l] * F[i2 + 3 * j1][l];
  };
  double invdet[N];
  for (int l = 0; l < n; ++l)
    invdet[l] = 1.0 / ((cofactor(0, 0, l) * F[0][l] + cofactor(1, 0, l) * F[1][l]) + cofactor(2, 0, l) * F[2][l]);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c)
      for (int l = 0; l < n; ++l) Finv[r + 3 * c][l] = cofactor(c, r, l) * invdet[l];
}

/// |Q|^2 of lane l as Eigen's vectorised reduction of the 9 squares: pairs (2m, 2m+1) summed as
/// packets ((p0 + p1) + (p2 + p3)), the packet's two halves added, then the odd ninth.
double squared_norm(const double Q[9][N], int l) {
  double q[9];
  for (int k = 0; k < 9; ++k) q[k] = Q[k][l] * Q[k][l];
  return (((q[0] + q[2]) + (q[4] + q[6])) + ((q[1] + q[3]) + (q[5] + q[7]))) + q[8];
}

/// Unpacks the symmetric tensor at `offset` of the state blocks of lanes 0..n-1 (zero in the virgin
/// state, an empty span), and packs it back.
void unpack_lanes(std::span<const double> state, std::size_t block, std::size_t offset, int n, double S[9][N]) {
  for (int k = 0; k < 9; ++k)
    for (int l = 0; l < n; ++l)
      S[k][l] = !state.empty() ? state[static_cast<std::size_t>(l) * block + offset + kUnpacked[k]] : 0.0;
}
void pack_lanes(const double S[9][N], int n, std::size_t block, std::size_t offset, std::span<double> state) {
  for (int l = 0; l < n; ++l)
    for (int v = 0; v < 6; ++v) state[static_cast<std::size_t>(l) * block + offset + v] = S[kPacked[v]][l];
}

}  // namespace

const char* to_string(ViscoModuli m) { return m == ViscoModuli::instantaneous ? "instantaneous" : "long_term"; }

ViscoParams prony_from_abaqus(const std::vector<double>& g, const std::vector<double>& tau_s, ViscoModuli moduli) {
  const std::string me = "viscoelastic";
  double sum = 0.0;
  for (std::size_t i = 0; i < g.size(); ++i) {
    detail::require(std::isfinite(g[i]) && g[i] >= 0.0, me,
                    term("g", i) + " must be >= 0 (Abaqus relative modulus), got " + short_num(g[i]));
    sum += g[i];
  }
  detail::require(sum < 1.0, me,
                  "the Abaqus g_i must sum to < 1 (the long-term modulus G_0 (1 - sum g) must stay positive), got " +
                      short_num(sum));
  ViscoParams p{g, tau_s, moduli};
  for (double& gi : p.gamma) gi /= 1.0 - sum;
  return p;
}

// The own state size, 6 (1 + terms), is handed to the base class before the terms are checked: a bad count
// throws below, after the shared constructor's split-base check, in the order the checks had before.
Viscoelastic::Viscoelastic(MaterialPtr base, const ViscoParams& p)
    : MaterialDecorator(std::move(base), "viscoelastic", 6 * (1 + static_cast<int>(p.gamma.size()))) {
  const std::string& me = effect();
  const std::size_t n = p.gamma.size();
  detail::require(n >= 1 && n <= kMaxTerms && p.tau_s.size() == n, me,
                  "gamma and tau need the same number of Prony terms, 1 to 3; got " + std::to_string(n) +
                      " gamma and " + std::to_string(p.tau_s.size()) + " tau");
  for (std::size_t i = 0; i < n; ++i) {
    detail::require(std::isfinite(p.gamma[i]) && p.gamma[i] >= 0.0, me,
                    term("gamma", i) + " must be >= 0 (stiffness of the branch relative to the long-term law), got " +
                        short_num(p.gamma[i]));
    detail::require(std::isfinite(p.tau_s[i]) && p.tau_s[i] > 0.0, me,
                    term("tau", i) + " must be > 0 s (relaxation time), got " + short_num(p.tau_s[i]));
    gamma_[i] = p.gamma[i];
    tau_[i] = p.tau_s[i];
    gamma_sum_ += p.gamma[i];
  }
  n_ = static_cast<int>(n);
  moduli_ = p.moduli;
  // beta = 1 (long_term) or 1 - sum g = 1 / (1 + sum gamma) (instantaneous); a_i = beta gamma_i, which
  // is gamma_i bit for bit in the long-term convention (the arithmetic before the choice existed).
  beta_ = moduli_ == ViscoModuli::instantaneous ? 1.0 / (1.0 + gamma_sum_) : 1.0;
  for (int i = 0; i < n_; ++i) a_[i] = moduli_ == ViscoModuli::instantaneous ? beta_ * gamma_[i] : gamma_[i];
  mu_base_ = this->base()->initial_shear_modulus();  // this->: the parameter `base` was moved from
}

void Viscoelastic::init_state(std::span<double> state) const {
  for (std::size_t i = 0; i < own_size(); ++i) state[i] = 0.0;  // S0 = 0 and Q_i = 0 in the virgin state
  base()->init_state(base_state(state));
}

void Viscoelastic::jump_cycles(std::span<const double> before, std::span<const double> after, double cycles,
                               std::span<double> out) const {
  const std::size_t own = own_size();
  std::copy(after.begin(), after.begin() + static_cast<std::ptrdiff_t>(own), out.begin());  // set by the last rest
  base()->jump_cycles(base_state(before), base_state(after), cycles, base_state(out));
}

struct Viscoelastic::Increment {
  std::array<double, kMaxTerms> decay{}, gk{};  // exp(-x_i), a_i k_i
  double b = 1.0;                               // beta + sum_i a_i k_i, the factor of P0_iso
};

// b = 1 + sum gamma_i k_i (long_term: as before the choice existed, bit for bit) or
// 1 - sum g_i (1 - k_i) (instantaneous: exactly 1 at dt = 0, where k_i = 1).
Viscoelastic::Increment Viscoelastic::increment(double dt_s) const {
  Increment inc;
  double c = 0.0, loss = 0.0;  // sum a_i k_i, sum a_i (1 - k_i)
  for (int i = 0; i < n_; ++i) {
    const double x = dt_s / tau_[i];
    const double k = k_factor(x);
    inc.decay[i] = std::exp(-x);
    inc.gk[i] = a_[i] * k;
    c += inc.gk[i];
    loss += a_[i] * (1.0 - k);
  }
  inc.b = moduli_ == ViscoModuli::instantaneous ? 1.0 - loss : 1.0 + c;
  return inc;
}

void Viscoelastic::evaluate(std::span<const Mat3> F, const TimeStep& step, std::span<const double> state_old,
                            std::span<double> state_new, std::span<PointResponse> out, bool tangent) const {
  assert(step.dt_s >= 0.0);
  const std::size_t own = own_size(), nb = static_cast<std::size_t>(base()->state_size());
  const Increment inc = increment(step.dt_s);
  for (std::size_t q = 0; q < F.size(); ++q) {
    const detail::PointState ps = detail::point_state(state_old, state_new, q, own, nb);
    PointResponse& r = out[q];
    detail::evaluate_base(*base(), F[q], step, ps, r, tangent);
    const bool virgin = ps.own_old.empty();

    const Mat3 S0_trial = F[q].inverse() * r.P_iso;
    const Mat3 S0 = 0.5 * (S0_trial + S0_trial.transpose());
    const Mat3 S0_old = virgin ? Mat3::Zero() : unpack(ps.own_old.subspan(0, 6));
    Mat3 H = Mat3::Zero();
    double psi_branches = 0.0;
    for (int i = 0; i < n_; ++i) {
      const Mat3 Q_old = virgin ? Mat3::Zero() : unpack(ps.own_old.subspan(6 * (i + 1), 6));
      const Mat3 Q_new = inc.decay[i] * Q_old + inc.gk[i] * (S0 - S0_old);
      H += inc.decay[i] * Q_old - inc.gk[i] * S0_old;
      if (a_[i] > 0.0) psi_branches += Q_new.squaredNorm() / (4.0 * a_[i] * mu_base_);
      if (!ps.own_new.empty()) pack(Q_new, ps.own_new.subspan(6 * (i + 1), 6));
    }
    if (!ps.own_new.empty()) pack(S0, ps.own_new.subspan(0, 6));

    if (tangent) {
      r.A_iso *= inc.b;
      for (int i = 0; i < 3; ++i)  // + delta_ik H_JL
        for (int J = 0; J < 3; ++J)
          for (int L = 0; L < 3; ++L) r.A_iso(flat(i, J), flat(i, L)) += H(J, L);
    }
    r.P_iso = inc.b * r.P_iso + F[q] * H;
    r.psi_iso = beta_ * r.psi_iso + psi_branches;
  }
}

// evaluate()'s force part for the whole batch in structure-of-arrays form (the helpers above): the base's
// batched stress, then S0 = sym(F^-1 P0_iso), the Prony update of each term and P_iso = b P0_iso + F H.
void Viscoelastic::stress(StressBatch& b, const TimeStep& step, std::span<const double> state_old,
                          std::span<double> state_new) const {
  assert(step.dt_s >= 0.0);
  const std::size_t own = own_size(), nb = static_cast<std::size_t>(base()->state_size());
  if (!detail::stress_base(*base(), b, step, state_old, state_new, own))
    return Material::stress(b, step, state_old, state_new);
  const std::size_t block = own + nb;
  const Increment inc = increment(step.dt_s);
  const int n = b.n;
  double Finv[9][N], S0_trial[9][N], S0[9][N], S0_old[9][N], Q_old[9][N], Q_new[9][N], H[9][N], FH[9][N], psi_branches[N];
  inverse(b.F, Finv, n);
  product(Finv, b.P_iso, S0_trial, n);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
      for (int l = 0; l < n; ++l) S0[i + 3 * j][l] = 0.5 * (S0_trial[i + 3 * j][l] + S0_trial[j + 3 * i][l]);
  unpack_lanes(state_old, block, 0, n, S0_old);
  for (int k = 0; k < 9; ++k)
    for (int l = 0; l < n; ++l) H[k][l] = 0.0;
  for (int l = 0; l < n; ++l) psi_branches[l] = 0.0;
  for (int i = 0; i < n_; ++i) {
    const std::size_t offset = 6 * static_cast<std::size_t>(i + 1);
    const double decay = inc.decay[i], gk = inc.gk[i];
    unpack_lanes(state_old, block, offset, n, Q_old);
    for (int k = 0; k < 9; ++k)
      for (int l = 0; l < n; ++l) {
        Q_new[k][l] = decay * Q_old[k][l] + gk * (S0[k][l] - S0_old[k][l]);
        H[k][l] += decay * Q_old[k][l] - gk * S0_old[k][l];
      }
    if (a_[i] > 0.0) {
      const double scale = 4.0 * a_[i] * mu_base_;
      for (int l = 0; l < n; ++l) psi_branches[l] += squared_norm(Q_new, l) / scale;
    }
    if (!state_new.empty()) pack_lanes(Q_new, n, block, offset, state_new);
  }
  if (!state_new.empty()) pack_lanes(S0, n, block, 0, state_new);
  product(b.F, H, FH, n);
  const double factor = inc.b;
  for (int k = 0; k < 9; ++k)
    for (int l = 0; l < n; ++l) b.P_iso[k][l] = factor * b.P_iso[k][l] + FH[k][l];
  for (int l = 0; l < n; ++l) b.psi_iso[l] = beta_ * b.psi_iso[l] + psi_branches[l];
}

PointFields Viscoelastic::fields(std::span<const double> state) const {
  PointFields f = base()->fields(base_state(state));
  Mat3 Q = Mat3::Zero();
  for (int i = 0; i < n_; ++i) Q += unpack(state.subspan(6 * (i + 1), 6));
  f.viscous_strain = Q.norm() / (2.0 * long_term_shear_modulus());
  return f;
}

Material::LinearDrive Viscoelastic::linear_drive() const {
  LinearDrive d;
  d.terms = n_;
  for (int i = 0; i < n_; ++i) d.a[i] = a_[i], d.tau_s[i] = tau_[i];
  d.recovery = 1.0 / beta_;
  return d;
}

void Viscoelastic::linear_drive_value(std::span<const double> state, std::span<double> out) const {
  // S0 is stored packed as (11, 22, 33, 23, 13, 12): the off-diagonal entries count twice in the
  // Frobenius norm, hence sqrt(2).
  const double s = 1.0 / (2.0 * long_term_shear_modulus()), r2 = std::sqrt(2.0);
  for (int k = 0; k < 6; ++k) out[k] = (k < 3 ? s : r2 * s) * state[k];
}

}  // namespace pneufem
