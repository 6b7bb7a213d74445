#include "engine/rom.h"

#include <algorithm>
#include <atomic>
#include <chrono>
#include <climits>
#include <cmath>
#include <cstdio>
#include <sstream>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <Eigen/LU>

#include "engine/angle.h"
#include "engine/history_step.h"
#include "engine/path_spline.h"
#include "engine/rom_points.h"
#include "engine/tet_element.h"
#include "core/errors.h"

namespace pneufem {


// ================================================================ ReducedOrderModel
namespace {

/// Values of per-sample vectors y (rows x ns) at segment k with Hermite h, and their theta-slope
/// (slopes dy given per sample, same layout).
struct Splined {
  Eigen::VectorXd v, d;
};
Splined spline_at(const Eigen::MatrixXd& y, const Eigen::MatrixXd& dy, int k, const Hermite& h) {
  Splined s;
  const Eigen::VectorXd y0 = y.col(k), y1 = y.col(k + 1), m0 = dy.col(k), m1 = dy.col(k + 1);
  s.v = h.value(y0, y1, m0, m1);
  s.d = h.slope(y0, y1, m0, m1);
  return s;
}

Eigen::MatrixXd slopes_of(const std::vector<double>& theta, const Eigen::MatrixXd& y) {
  const std::vector<Eigen::VectorXd> m =
      spline_slopes<Eigen::VectorXd>(theta, [&](std::size_t k) { return Eigen::VectorXd(y.col(static_cast<Eigen::Index>(k))); });
  Eigen::MatrixXd out(y.rows(), y.cols());
  for (std::size_t k = 0; k < m.size(); ++k) out.col(static_cast<Eigen::Index>(k)) = m[k];
  return out;
}

std::vector<Eigen::MatrixXd> slopes_of(const std::vector<double>& theta, const std::vector<Eigen::MatrixXd>& y) {
  return spline_slopes<Eigen::MatrixXd>(theta, [&](std::size_t k) { return y[k]; });
}

}  // namespace

struct ReducedOrderModel::Impl {
  std::unique_ptr<rom_detail::KeptPoints> points;
  // Spline slopes (theta) of the per-sample operators.
  std::vector<double> dp;                   ///< monotone slopes of p_el
  std::vector<double> dwg;                  ///< slopes of w^T g (spline)
  Eigen::MatrixXd db, dc, dh, dgt, dgauge;  ///< slopes of b (exact), c, h, gt, gauge
  Eigen::MatrixXd dpw;                      ///< slopes of pw
  std::vector<Eigen::MatrixXd> dK, dH, dKref;
  Eigen::Vector3d gravity = Eigen::Vector3d::Zero();
  std::vector<int> tip_nodes;               ///< nodes whose displacement the angle needs
  bool galerkin_theta_row = false;          ///< every sample's theta row tests u_el' (ReducedBasis::wa all 0)
  bool gauge_free = false;                  ///< the modes are orthogonal to the path's tangents (ReducedBasis::gauge all 0)
};

ReducedOrderModel::ReducedOrderModel(const Model& reference, const ReducedBasis& basis, const Model& model)
    : reference_(reference), basis_(basis), model_(model), impl_(std::make_unique<Impl>()) {
  if (basis.dofs() != reference.num_dofs() || model.num_dofs() != reference.num_dofs() ||
      model.mesh.num_elements() != reference.mesh.num_elements() || basis.mesh_fingerprint != mesh_fingerprint(reference.mesh) ||
      (&model.mesh != &reference.mesh && mesh_fingerprint(model.mesh) != basis.mesh_fingerprint))
    throw InputError("reduced model: the basis, the reference and the run's model must share one mesh (basis " +
                     std::to_string(basis.dofs()) + " dof, reference " + std::to_string(reference.num_dofs()) +
                     ", model " + std::to_string(model.num_dofs()) + "); rebuild the basis for this mesh");
  if (basis.stiff_part.size() != reference.parts.size())
    throw InputError("reduced model: the reference has other parts than the basis was built for; rebuild the basis");
  // Elements of the stiff parts (the fabric) must keep the reference's material; the soft parts may
  // differ in anything, per element (region scales split a part into several).
  std::vector<char> checked(model.parts.size(), 0);
  for (int e = 0; e < model.mesh.num_elements(); ++e) {
    const int mp = model.element_part[e];
    const int rp = reference.element_part[e];
    if (checked[mp]) continue;
    checked[mp] = 1;
    const Material& a = *model.parts[mp].material;
    if (!basis.stiff_part[rp]) {
      if (a.nonlocal().radius_m > 0.0)
        throw InputError("reduced model: part '" + model.parts[mp].name + "' has a non-local driver (nonlocal_radius_mm > 0), " +
                         "which needs every material point; run the full FEM (solver.model = \"full\")");
      continue;
    }
    const Material& b = *reference.parts[rp].material;
    if (a.name() != b.name() || a.initial_shear_modulus() != b.initial_shear_modulus() ||
        a.initial_bulk_modulus() != b.initial_bulk_modulus() || a.state_size() != 0)
      throw InputError("reduced model: part '" + model.parts[mp].name + "' is stiff (the fabric) and the reduced model keeps it " +
                       "linear about the reference path, so its material must equal the reference's (" + b.name() +
                       "); run the full FEM (solver.model = \"full\") to change it");
  }
  impl_->points = std::make_unique<rom_detail::KeptPoints>(model, basis);
  const std::vector<double>& th = basis.theta;
  impl_->dp = monotone_slopes(th, basis.p);
  impl_->dwg = spline_slopes<double>(th, [&](std::size_t k) { return basis.wg[k]; });
  impl_->db = basis.db;  // b' = Phi^T H_V u_el' exactly
  impl_->dc = slopes_of(th, basis.c);
  impl_->dh = slopes_of(th, basis.h);
  impl_->dgt = slopes_of(th, basis.gt);
  impl_->dgauge = slopes_of(th, basis.gauge);
  impl_->dK = slopes_of(th, basis.K);
  impl_->dH = slopes_of(th, basis.H);
  impl_->dKref = slopes_of(th, basis.Kref);
  impl_->dpw = slopes_of(th, basis.pw);
  impl_->gravity = model.gravity_m_s2;
  impl_->galerkin_theta_row = std::all_of(basis.wa.begin(), basis.wa.end(), [](double a) { return a == 0.0; });
  impl_->gauge_free = basis.num_modes() > 0 && basis.gauge.isZero(0.0);
}

ReducedOrderModel::~ReducedOrderModel() = default;

int ReducedOrderModel::num_points() const { return impl_->points->size(); }
std::size_t ReducedOrderModel::history_size() const { return impl_->points->history_size(); }
std::vector<double> ReducedOrderModel::initial_history() const { return impl_->points->initial_history(); }
std::vector<double> ReducedOrderModel::history_scalars(const std::vector<double>& history) const {
  return impl_->points->history_scalars(history);
}
int ReducedOrderModel::element_of_point(int i) const { return impl_->points->element(i); }
void ReducedOrderModel::gather_history(const Assembler& full, std::span<const double> full_state, std::vector<double>& kept) const {
  kept.resize(history_size());
  impl_->points->gather_history(full, full_state, kept);
}

Eigen::VectorXd ReducedOrderModel::displacement(const ReducedCoordinates& z) const {
  const int k = path_segment_index(basis_.theta, z.theta);
  const Hermite h((z.theta - basis_.theta[k]) / (basis_.theta[k + 1] - basis_.theta[k]), basis_.theta[k + 1] - basis_.theta[k]);
  Eigen::VectorXd u = h.value<Eigen::VectorXd>(basis_.U.col(k), basis_.U.col(k + 1), basis_.dU.col(k), basis_.dU.col(k + 1));
  if (z.q.size() > 0) u.noalias() += basis_.Phi * z.q;
  return u;
}

double ReducedOrderModel::angle_deg(const ReducedCoordinates& z, double previous_deg, double* plane_rms_m) const {
  const AngleResult a = bending_angle(model_, displacement(z));
  if (plane_rms_m) *plane_rms_m = a.plane_rms_m;
  return unwrap_deg(a.angle_deg, previous_deg);
}

double ReducedOrderModel::cavity_volume(const ReducedCoordinates& z) const {
  const std::vector<double>& th = basis_.theta;
  const int k = path_segment_index(th, z.theta);
  const Hermite h((z.theta - th[k]) / (th[k + 1] - th[k]), th[k + 1] - th[k]);
  double V = h.value(basis_.V[k], basis_.V[k + 1], basis_.dV[k], basis_.dV[k + 1]);
  if (z.q.size() > 0) {
    // V(u_el + d) = V + g.d + d^T H_V d / 2 + g2[d, d, d] / 6: to second order in q (the third is
    // ~|d|/L of the second).
    const Eigen::MatrixXd Hq = h.value(basis_.H[k], basis_.H[k + 1], impl_->dH[k], impl_->dH[k + 1]);
    V += spline_at(basis_.b, impl_->db, k, h).v.dot(z.q) + 0.5 * z.q.dot(Hq * z.q);
  }
  return V;
}

// One function (~110 lines) on purpose: the terms of the header's equation in its order (E, gravity,
// the hyper-reduced bracket, P, the gauge), then their Jacobian blocks in the same order, from the
// same splined values.
Eigen::VectorXd ReducedOrderModel::residual(const ReducedCoordinates& z, double p_Pa, const TimeStep& ts,
                                            const std::vector<double>& history_old, std::vector<double>& history_new,
                                            Eigen::MatrixXd* jacobian) const {
  const ReducedBasis& B = basis_;
  const int r = B.num_modes(), n1 = r + 1;
  const std::vector<double>& th = B.theta;
  const int k = path_segment_index(th, z.theta);
  const double dth = th[k + 1] - th[k];
  const Hermite h((z.theta - th[k]) / dth, dth);
  const Eigen::VectorXd& q = z.q;

  // The exact reference, linearised in q about the path.
  double dpel = 0.0;
  const double pel = h(B.p[k], B.p[k + 1], impl_->dp[k], impl_->dp[k + 1], &dpel);
  const double Vp = h.value(B.wg[k], B.wg[k + 1], impl_->dwg[k], impl_->dwg[k + 1]);
  const double Vpp = h.slope(B.wg[k], B.wg[k + 1], impl_->dwg[k], impl_->dwg[k + 1]);
  const Splined b = spline_at(B.b, impl_->db, k, h), c = spline_at(B.c, impl_->dc, k, h), hh = spline_at(B.h, impl_->dh, k, h);
  const Splined gt = spline_at(B.gt, impl_->dgt, k, h), gauge = spline_at(B.gauge, impl_->dgauge, k, h);
  const Eigen::MatrixXd Kq = h.value(B.K[k], B.K[k + 1], impl_->dK[k], impl_->dK[k + 1]);
  const Eigen::MatrixXd Hq = h.value(B.H[k], B.H[k + 1], impl_->dH[k], impl_->dH[k + 1]);
  const double dp = pel - p_Pa;
  Eigen::VectorXd R = Eigen::VectorXd::Zero(n1 + 1);
  R[0] = dp * Vp + (c.v + dp * hh.v).dot(q);
  R.segment(1, r) = dp * b.v + (Kq + dp * Hq) * q;

  // Gravity: -J^T f_g (f_g linear in the acceleration).
  const Eigen::Vector3d& gvec = impl_->gravity;
  if (!gvec.isZero()) {
    R[0] -= gt.v.dot(gvec);
    R.segment(1, r) -= B.gq * gvec;
  }

  // The hyper-reduced departure from the reference: G_hat(z) - G_hat_ref(theta) - K_hat_ref(theta) q.
  Eigen::VectorXd G;
  Eigen::MatrixXd JG;
  impl_->points->force(z.theta, q, ts, history_old, history_new, G, jacobian ? &JG : nullptr);
  // G_hat_ref on the fine grid (linear between its points); outside the path, extrapolated from the
  // end interval, as G_hat's path gradients are extrapolated by the end segment's spline. (Held at
  // its end value, it left G_hat(theta, 0) - G_hat_ref a first-order force in theta - 0 below the
  // path, small for the silicone but not for the fabric in the bracket: no equilibrium at
  // theta = -0.29 deg in a rest at 0 kPa, bench/results/rom_h6_ceiling section 10.)
  const int nsub = ReducedBasis::kRefSub;
  const double x = h.a * nsub;
  const int j = std::clamp(static_cast<int>(std::floor(x)), 0, nsub - 1);
  const Eigen::Index col = static_cast<Eigen::Index>(k) * (nsub + 1) + j;
  const Eigen::VectorXd Gref = B.Gref.col(col) + (x - j) * (B.Gref.col(col + 1) - B.Gref.col(col));
  const Eigen::VectorXd dGref = (B.Gref.col(col + 1) - B.Gref.col(col)) * (nsub / dth);
  const Eigen::MatrixXd Kref = h.value(B.Kref[k], B.Kref[k + 1], impl_->dKref[k], impl_->dKref[k + 1]);
  R.head(n1) += G - Gref - Kref.rightCols(r) * q;
  // The follower load's second order in q (ReducedBasis::pq, pw): -p/2 T^T g2[Phi q, Phi q].
  const Eigen::Index rr = static_cast<Eigen::Index>(r) * r;
  Splined pw2;
  Eigen::VectorXd qq;
  if (r > 0) {
    qq.resize(rr);
    for (int l = 0; l < r; ++l) qq.segment(static_cast<Eigen::Index>(r) * l, r) = q[l] * q;
    pw2 = spline_at(B.pw, impl_->dpw, k, h);
    R[0] -= 0.5 * p_Pa * pw2.v.dot(qq);
    R.segment(1, r).noalias() -= (0.5 * p_Pa) * (B.pq * qq);
  }

  // Gauge: q is mass-orthogonal to u_el'(theta); multiplier lambda (see galerkin_theta_row in Impl).
  // A basis without a gauge (tangent_free_modes) keeps lambda at 0 (its row lambda = 0).
  if (impl_->gauge_free) {
    R[n1] = z.lambda;
  } else {
    if (impl_->galerkin_theta_row) R[0] += z.lambda * gauge.d.dot(q);
    R.segment(1, r) += z.lambda * gauge.v;
    R[n1] = gauge.v.dot(q);
  }

  if (jacobian) {
    Eigen::MatrixXd& Jm = *jacobian;
    Jm = Eigen::MatrixXd::Zero(n1 + 1, n1 + 1);
    // d/dtheta of the linearised reference.
    const Eigen::MatrixXd dKq = h.slope(B.K[k], B.K[k + 1], impl_->dK[k], impl_->dK[k + 1]);
    const Eigen::MatrixXd dHq = h.slope(B.H[k], B.H[k + 1], impl_->dH[k], impl_->dH[k + 1]);
    Jm(0, 0) = dpel * Vp + dp * Vpp + (c.d + dpel * hh.v + dp * hh.d).dot(q);
    Jm.block(1, 0, r, 1) = dpel * b.v + dp * b.d + (dKq + dpel * Hq + dp * dHq) * q;
    Jm.block(0, 1, 1, r) = (c.v + dp * hh.v).transpose();
    Jm.block(1, 1, r, r) = Kq + dp * Hq;
    if (!gvec.isZero()) {
      Jm(0, 0) -= gt.d.dot(gvec);
    }
    // The load's second order: d/dq of -p/2 q^T A q is -p A q (A = w^T g2 symmetric), of
    // -p/2 pq (q x q) is -p sum_l q_l pq(:, r l .. r l + r).
    if (r > 0) {
      const Eigen::Map<const Eigen::MatrixXd> A2(pw2.v.data(), r, r);
      Jm(0, 0) -= 0.5 * p_Pa * pw2.d.dot(qq);
      Jm.block(0, 1, 1, r) -= p_Pa * (A2 * q).transpose();
      for (int l = 0; l < r; ++l) Jm.block(1, 1, r, r) -= (p_Pa * q[l]) * B.pq.middleCols(static_cast<Eigen::Index>(r) * l, r);
    }
    // Hyper-reduced part.
    const Eigen::MatrixXd dKref = h.slope(B.Kref[k], B.Kref[k + 1], impl_->dKref[k], impl_->dKref[k + 1]);
    Jm.topLeftCorner(n1, n1) += JG;
    Jm.block(0, 0, n1, 1) -= dGref + dKref.rightCols(r) * q;
    Jm.block(0, 1, n1, r) -= Kref.rightCols(r);
    // Gauge.
    const Eigen::VectorXd ddgauge = h.curvature<Eigen::VectorXd>(B.gauge.col(k), B.gauge.col(k + 1), impl_->dgauge.col(k),
                                                                 impl_->dgauge.col(k + 1));
    if (impl_->gauge_free) {
      Jm(n1, n1) = 1.0;
    } else {
      if (impl_->galerkin_theta_row) {
        Jm(0, 0) += z.lambda * ddgauge.dot(q);
        Jm.block(0, 1, 1, r) += z.lambda * gauge.d.transpose();
        Jm.block(0, n1, 1, 1)(0, 0) = gauge.d.dot(q);
      }
      Jm.block(1, 0, r, 1) += z.lambda * gauge.d;
      Jm.block(1, n1, r, 1) = gauge.v;
      Jm(n1, 0) = gauge.d.dot(q);
      Jm.block(n1, 1, 1, r) = gauge.v.transpose();
    }
  }
  return R;
}

// ================================================================ ReducedRun
struct ReducedRun::Segment {
  int trial;
  double t0, t1, g0, g1, p0, p1;
  bool report;
};

ReducedRun::ReducedRun(const ReducedOrderModel& rom, QuasiStaticOptions options) : rom_(rom), opt_(options) {
  // The reduced run has no linear-drive control (it compares the kept points' history scalars
  // only): "drive" keeps the error control it refines, as before the choice existed.
  if (opt_.time_control == TimeControl::Drive) opt_.time_control = TimeControl::Error;
  z_.q = Eigen::VectorXd::Zero(rom.num_modes());
  hist_ = rom.initial_history();
  trial_ = hist_;
  rate_dependent_ = !hist_.empty();
}

// Newton in the reduced coordinates, with the Jacobian kept from earlier iterations and steps while
// it contracts (a modified Newton, or chord, method: Dennis & Schnabel 1996, section 5.4; the
// default of the full FEM codes for quasi-static holds, e.g. Abaqus's and FEBio's quasi-Newton).
// An iteration with a kept Jacobian costs one residual at the kept points instead of a residual and
// a tangent (the tangent is ~2/3 of the work of an evaluation, r ~ 16-32). It is refreshed when the
// step does not contract by half (|dz_k| > 0.5 |dz_(k-1)| in the Jacobian's own row scaling), when
// the scaled residual does not fall, or after kMaxReuse iterations; near the solution a contraction
// rho < 1/2 bounds the remaining error by rho/(1 - rho) |dz| <= |dz|, so the step test below is as
// strict as with Newton's own Jacobian. The converged state satisfies the same residual equations
// to the same tolerance; only the path of iterates differs (deterministic for any thread count).
// One function (~120 lines) on purpose: the iteration, its line search and the rules that keep or
// refresh the Jacobian all read and change the same iterate, factor, row scaling and freshness;
// split, they would pass these back and forth.
void ReducedRun::equilibrium(double p, double t, double dt) {
  const TimeStep ts{t, dt};
  const int n = rom_.num_modes() + 2;
  // A kept Jacobian is used for at most kMaxReuse iterations, and only while every iteration cuts
  // the scaled residual to kContract of its value (measured on a 15-chamber story at h = 4, three
  // trials: 0.25 took 10 % fewer evaluations than 0.5 or 0.1, with the same angles to 1e-3 deg).
  constexpr int kMaxReuse = 8;
  constexpr double kContract = 0.25;
  // Converged when the Newton step is below 1e-6 (1 + |theta|) deg in theta (1e-4 deg at 100 deg:
  // 100x below the 0.01 deg the reports are written with) and 1e-8 of the path's largest RMS
  // displacement in q.
  constexpr double kTolTheta = 1e-6, kTolQ = 1e-8;
  // Newton starts from z_ (solve_segment sets it to its predictor).
  ReducedCoordinates z = z_;
  Eigen::VectorXd dz = Eigen::VectorXd::Zero(n);
  const ReducedBasis& B = rom_.basis();
  const double q_scale = std::sqrt(B.U.col(B.num_samples() - 1).squaredNorm() / std::max<double>(1.0, B.dofs())) + 1e-12;
  Eigen::MatrixXd Jm;
  Eigen::VectorXd R;
  auto apply = [&](ReducedCoordinates& y, const Eigen::VectorXd& d, double s) {
    y.theta += s * d[0];
    y.q += s * d.segment(1, n - 2);
    y.lambda += s * d[n - 1];
  };
  bool converged = false;
  // The Jacobian in use: evaluated at the current iterate (fresh) or kept from before (stale).
  bool fresh = false;
  int reused = 0;
  Eigen::PartialPivLU<Eigen::MatrixXd> lu;
  Eigen::VectorXd scale;
  auto factor = [&] {
    lu.compute(Jm);
    scale = Jm.rowwise().norm().cwiseMax(1e-300).cwiseInverse();
  };
  auto refresh = [&] {
    R = rom_.residual(z, p, ts, hist_, trial_, &Jm);
    ++stats_.residuals;
    ++stats_.tangents;
    fresh = true;
    reused = 0;
    factor();
    jacobian_ = Jm;
  };
  if (reuse_jacobian_ && jacobian_.rows() == n) {
    Jm = jacobian_;
    factor();
    R = rom_.residual(z, p, ts, hist_, trial_, nullptr);
    ++stats_.residuals;
  } else {
    refresh();
  }
  const double span = B.theta.back() - B.theta.front();
  int it = 0;
  for (; it < 30; ++it) {
    dz = -lu.solve(R);
    if (!dz.allFinite()) {
      if (fresh) break;
      refresh();
      continue;
    }
    if (std::abs(dz[0]) <= kTolTheta * (1.0 + std::abs(z.theta)) && dz.segment(1, n - 2).lpNorm<Eigen::Infinity>() <= kTolQ * q_scale) {
      apply(z, dz, 1.0);  // converged: the last (tiny) step, and the trial history of its state
      rom_.residual(z, p, ts, hist_, trial_, nullptr);
      ++stats_.residuals;
      converged = true;
      break;
    }
    // The scaled residual (rows scaled by the Jacobian's row norms) must fall: with a fresh
    // Jacobian by a damped step; with a kept one by half in a full step, else it is refreshed.
    const double f0 = R.cwiseProduct(scale).norm();
    double s = 1.0;
    // Keep theta steps moderate: a tenth of the path's span at most.
    if (std::abs(dz[0]) > 0.1 * span) s = 0.1 * span / std::abs(dz[0]);
    ReducedCoordinates y = z;
    apply(y, dz, s);
    bool accepted = false;
    double f1 = f0;
    Eigen::VectorXd R1;
    for (int ls = 0; ls < 8; ++ls) {
      try {
        R1 = rom_.residual(y, p, ts, hist_, trial_, nullptr);
        ++stats_.residuals;
        f1 = R1.cwiseProduct(scale).norm();
        if (f1 < (1.0 - 1e-4 * s) * f0 || (fresh && ls == 7)) {
          accepted = true;
          break;
        }
      } catch (const PhysicsError&) {
      }
      if (!fresh) break;
      s *= 0.5;
      y = z;
      apply(y, dz, s);
    }
    if (!accepted) {
      if (fresh) break;
      refresh();  // a kept Jacobian whose step does not lower the residual: evaluate it here
      continue;
    }
    z = y;
    R = R1;
    ++stats_.newton_iterations;
    if (fresh) {
      fresh = false;  // kept for the next iteration
    } else {
      ++reused;
      ++stats_.reused_tangents;
    }
    if (!reuse_jacobian_ || reused >= kMaxReuse || f1 > kContract * f0) refresh();  // contracting too slowly with the kept one
  }
  if (!converged) {
    std::ostringstream m;
    m << "reduced model: no equilibrium at p = " << p * 1e-3 << " kPa, t = " << t << " s after " << it
      << " Newton iterations (theta " << z.theta << " deg); the model may be past its limit point";
    throw PhysicsError(m.str(), -1, t);
  }
  z_ = z;
  if (z.theta > B.theta.back() || z.theta < B.theta.front()) stats_.beyond_path = true;
}

void ReducedRun::commit(double t, double dt, double p, bool report) {
  hist_.swap(trial_);
  trial_ = hist_;
  ++stats_.states;
  record_step({t, dt, p, z_, report ? 0 : -1});
}

void ReducedRun::record_step(const ReducedStep& step) {
  steps_.push_back(step);
  if (!corrector_) return;
  corrector_(steps_.back(), hist_);
  trial_ = hist_;
  // The step control keeps comparing the reduced run's own trial histories (hist_cur_ stays the
  // step's own): the corrected history's increment differs from the own one by O(dt), which in a
  // second difference that mixes the two would read as a first-order error and shrink the steps
  // without end (measured: 5000 steps in a 13.5 s hold of the h = 6 story's trial 7).
}

void ReducedRun::solve_instantaneous(const Segment& s) {
  const double span = s.g1 - s.g0;
  if (span > 0.0 || s.p0 != s.p1) {
    // Elastic or instantaneous: pressure continuation in zero time (history frozen) when a direct
    // solve fails; the end state does not depend on the way (rate-independent laws only load up).
    const ReducedCoordinates z0 = z_;
    const double t = s.g1, dt = span;
    // A release to zero pressure in zero time starts from the undeformed state, as the FEM's does
    // (StaticSolver::advance): Newton from the loaded state can reach another root of the reduced
    // equations. Measured: with modes of strongly softened states in the basis, a vent from
    // 45 kPa of a 3-chamber actuator stopped at theta = -1.5 deg with a large correction and
    // stayed on that branch through the next trial (bench_rom, 2026-11-27).
    bool released = false;
    if (span <= 0.0 && s.p1 == 0.0 && s.p0 > 0.0) {
      try {
        z_.theta = 0.0;
        z_.q.setZero();
        jacobian_.resize(0, 0);
        z_.lambda = 0.0;
        equilibrium(0.0, t, dt);
        released = true;
      } catch (const PhysicsError&) {
        ++stats_.rejected_steps;
      }
    }
    int pieces = 1;
    while (!released) {
      try {
        z_ = z0;
        for (int i = 1; i <= pieces; ++i) {
          const double p = s.p0 + (s.p1 - s.p0) * i / pieces;
          equilibrium(p, t, i == pieces ? dt : 0.0);
          if (i < pieces) {
            hist_.swap(trial_);  // a rate-independent law's loading in zero time is committed as it goes
            trial_ = hist_;
          }
        }
        break;
      } catch (const PhysicsError&) {
        if (pieces >= 64) throw;
        pieces *= 4;
        ++stats_.rejected_steps;
      }
    }
    commit(t, dt, s.p1, s.report);
  }
  hist_prev_.clear();
  hist_cur_.clear();
}

void ReducedRun::solve_segment(const Segment& s) {
  const double span = s.g1 - s.g0;
  if (!rate_dependent_ || span <= 0.0) {
    solve_instantaneous(s);
    return;
  }
  auto p_at = [&](double g) { return s.p0 + (s.p1 - s.p0) * (g - s.g0) / span; };
  if (dt_suggest_ <= 0.0) dt_suggest_ = std::clamp(0.1, opt_.min_dt_s, opt_.max_dt_s);
  const bool error_control = opt_.time_control == TimeControl::Error;
  const double rate = (s.p1 - s.p0) / span;
  const bool kink = std::abs(rate - rate_prev_) > 1e-9 * (std::abs(rate) + std::abs(rate_prev_));
  if (kink) hist_prev_.clear();
  double t = s.g0;
  long steps = 0;
  seg_steps_ = 0;
  while (t < s.g1 - 1e-12 * (1.0 + std::abs(s.g1))) {
    if (++steps > opt_.max_segment_steps) {
      std::ostringstream m;
      m << "reduced model: physical time stepping stalled: " << opt_.max_segment_steps << " steps in the load segment "
        << s.g0 << " -> " << s.g1 << " s reached only t = " << t << " s";
      throw PhysicsError(m.str(), -1, t);
    }
    const bool minimal = dt_suggest_ <= opt_.min_dt_s * (1.0 + 1e-9);
    double hstep = std::min(dt_suggest_, s.g1 - t);
    if (s.g1 - (t + hstep) < 0.25 * hstep) hstep = s.g1 - t;
    const ReducedCoordinates z_saved = z_;
    // Predictor: within a segment (one ramp or one hold) the state moves smoothly, so Newton starts
    // from the linear extrapolation of the last two committed states (the converged state does not
    // depend on the start; from a start that fails, Newton runs again from the committed state).
    const bool predict = seg_steps_ > 0;
    if (predict) {
      const double ratio = hstep / h_seg_prev_;
      z_.theta += ratio * (z_saved.theta - z_prev_.theta);
      z_.q += ratio * (z_saved.q - z_prev_.q);
      z_.lambda += ratio * (z_saved.lambda - z_prev_.lambda);
    }
    try {
      try {
        equilibrium(p_at(t + hstep), t + hstep, hstep);
      } catch (const PhysicsError&) {
        if (!predict) throw;
        z_ = z_saved;
        equilibrium(p_at(t + hstep), t + hstep, hstep);
      }
    } catch (const PhysicsError&) {
      if (minimal || hstep <= opt_.min_dt_s * (1.0 + 1e-9)) throw;
      z_ = z_saved;
      dt_suggest_ = std::max(opt_.min_dt_s, 0.25 * hstep);
      ++stats_.rejected_steps;
      continue;
    }
    std::vector<double> hist_new = rom_.history_scalars(trial_);
    if (hist_cur_.empty()) hist_cur_ = rom_.history_scalars(hist_);
    const bool estimate = error_control && !hist_prev_.empty() && h_prev_ > 0.0;
    static const std::vector<double> kNoPrevious;
    const HistoryStep hs = history_step(estimate ? hist_prev_ : kNoPrevious, hist_cur_, hist_new, estimate ? hstep / h_prev_ : 0.0);
    const double measure = estimate ? hs.error : hs.change, order = estimate ? 2.0 : 1.0;
    const bool reject = measure > 2.0 * opt_.time_tol && !minimal && hstep > opt_.min_dt_s * (1.0 + 1e-9);
    if (reject) {
      z_ = z_saved;
      dt_suggest_ = std::max(opt_.min_dt_s, hstep * std::max(0.2, std::pow(0.9 * opt_.time_tol / measure, 1.0 / order)));
      ++stats_.rejected_steps;
      continue;
    }
    const double grow = measure > 0.0 ? std::clamp(std::pow(0.9 * opt_.time_tol / measure, 1.0 / order), 0.5, 2.0) : 2.0;
    dt_suggest_ = std::clamp(hstep * grow, opt_.min_dt_s, opt_.max_dt_s);
    if (error_control) {
      hist_prev_ = std::move(hist_cur_);
      h_prev_ = hstep;
    }
    hist_cur_ = std::move(hist_new);
    rate_prev_ = rate;
    z_prev_ = z_saved;
    h_seg_prev_ = hstep;
    ++seg_steps_;
    t += hstep;
    const bool last = !(t < s.g1 - 1e-12 * (1.0 + std::abs(s.g1)));
    commit(t, hstep, p_at(t), last && s.report);
  }
}

void ReducedRun::run(const LoadHistory& load, const Observer& observer) {
  const auto wall0 = std::chrono::steady_clock::now();
  // The segments of QuasiStaticRun: each trial's breakpoints and reports, the release to zero and
  // the rest before every trial but the first.
  std::vector<Segment> segs;
  double g = 0.0;
  for (std::size_t k = 0; k < load.trials.size(); ++k) {
    const TrialLoad& tl = load.trials[k];
    const int tr = static_cast<int>(k);
    if (k > 0) {
      segs.push_back({tr, 0, 0, g, g, load.trials[k - 1].pressure_Pa.back(), 0.0, false});
      if (load.rest_between_trials_s > 0) {
        segs.push_back({tr, 0, 0, g, g + load.rest_between_trials_s, 0.0, 0.0, false});
        g += load.rest_between_trials_s;
      }
      segs.push_back({tr, 0, 0, g, g, 0.0, tl.pressure(0.0), false});
    }
    std::vector<double> times = tl.time_s;
    times.insert(times.end(), tl.output_s.begin(), tl.output_s.end());
    std::sort(times.begin(), times.end());
    times.erase(std::unique(times.begin(), times.end(), [](double a, double b) { return std::abs(a - b) < 1e-12; }), times.end());
    auto is_output = [&](double t) {
      return std::any_of(tl.output_s.begin(), tl.output_s.end(), [&](double o) { return std::abs(o - t) < 1e-12; });
    };
    if (is_output(times.front())) {
      const double t = times.front();
      segs.push_back({tr, t, t, g + t, g + t, tl.pressure(t), tl.pressure(t), true});
    }
    for (std::size_t i = 1; i < times.size(); ++i)
      segs.push_back({tr, times[i - 1], times[i], g + times[i - 1], g + times[i], tl.pressure(times[i - 1]),
                      tl.pressure(times[i]), is_output(times[i])});
    g += tl.duration();
  }
  if (!segs.empty() && (segs.front().p0 != 0.0 || !rom_.model().gravity_m_s2.isZero())) {
    const Segment& s0 = segs.front();
    Segment first{s0.trial, s0.t0, s0.t0, s0.g0, s0.g0, 0.0, s0.p0, false};
    const bool rd = rate_dependent_;
    rate_dependent_ = false;
    if (s0.p0 == 0.0) {
      equilibrium(0.0, s0.g0, 0.0);
      hist_.swap(trial_);
      trial_ = hist_;
      record_step({s0.g0, 0.0, 0.0, z_, -1});
    } else {
      solve_segment(first);
    }
    rate_dependent_ = rd;
  }
  int reports = 0;
  for (const Segment& s : segs) {
    if (s.g1 == s.g0 && s.p0 == s.p1) {
      // A report at a breakpoint without a step: the current state.
    } else {
      solve_segment(s);
    }
    if (!s.report) continue;
    if (!steps_.empty() && steps_.back().time_s == s.g1) steps_.back().report = reports;
    else steps_.push_back({s.g1, 0.0, s.p1, z_, reports});
    StateRecord rec;
    rec.trial = s.trial + 1;
    rec.time_s = s.t1;
    rec.global_time_s = s.g1;
    rec.pressure_Pa = s.p1;
    const Eigen::VectorXd u = rom_.displacement(z_);
    const AngleResult a = bending_angle(rom_.model(), u);
    rec.angle_deg = unwrap_deg(a.angle_deg, last_angle_);
    last_angle_ = rec.angle_deg;
    rec.plane_rms_m = a.plane_rms_m;
    rec.cavity_volume_m3 = rom_.cavity_volume(z_);
    ++reports;
    if (observer) observer(rec, z_, u);
  }
  stats_.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
}

}  // namespace pneufem
