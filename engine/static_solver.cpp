#include "engine/static_solver.h"

#include <chrono>
#include <cstdio>
#include <cmath>
#include <limits>
#include <sstream>

#include "materials/errors.h"

namespace pneufem {

namespace {
double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

StaticSolver::StaticSolver(const Assembler& assembler, StaticOptions options)
    : asm_(assembler), opt_(options), K_(assembler.tangent_pattern()) {
  force_floor_ = reference_force_floor(assembler);
}

double reference_force_floor(const Assembler& a) {
  // Force of a 1e-6 strain in the softest material over the body's bounding-box area: a scale
  // that keeps the relative criterion meaningful when the loads vanish (unloaded states). The
  // softest material governs how far the structure moves for a given force.
  const Model& m = a.model();
  double mu = std::numeric_limits<double>::infinity();
  for (const Part& p : m.parts) mu = std::min(mu, p.material->initial_shear_modulus());
  const MeshStats st = compute_stats(m.mesh);
  const double L = (st.bbox_max - st.bbox_min).norm();
  return 1e-6 * mu * L * L;
}

Eigen::VectorXd StaticSolver::residual(double p, const TimeStep& ts, std::span<const double> s_old,
                                       std::span<double> s_new, const Eigen::VectorXd& u) {
  Eigen::VectorXd f_int, f_ext = Eigen::VectorXd::Zero(asm_.num_dofs());
  asm_.internal(u, ts, s_old, s_new, &f_int, nullptr, nullptr);
  asm_.add_pressure(u, p, f_ext, nullptr);
  asm_.add_gravity(f_ext);
  ++stats_.residual_evaluations;
  Eigen::VectorXd R = f_int - f_ext;
  asm_.zero_fixed(R);
  return R;
}

NewtonReport StaticSolver::solve(double p, const TimeStep& ts, std::span<const double> s_old,
                                 std::span<double> s_new, Eigen::VectorXd& u) {
  NewtonReport rep;
  const int n = asm_.num_dofs();
  Eigen::VectorXd f_int, f_ext;
  Eigen::VectorXd R;
  for (int it = 0; it <= opt_.max_iterations; ++it) {
    // Residual and tangent at u.
    auto t0 = std::chrono::steady_clock::now();
    f_ext.setZero(n);
    try {
      asm_.internal(u, ts, s_old, s_new, &f_int, &K_, nullptr);
    } catch (const PhysicsError& e) {
      rep.failure = e.what();
      return rep;
    }
    asm_.add_pressure(u, p, f_ext, &K_);
    asm_.add_gravity(f_ext);
    stats_.assembly_s += seconds_since(t0);
    R = f_int - f_ext;
    asm_.zero_fixed(R);
    rep.reference_N = std::max({f_ext.norm(), f_int.norm(), rep.reference_N, force_floor_});
    rep.residual_N = R.norm();
    rep.iterations = it;
    if (!std::isfinite(rep.residual_N)) {
      rep.failure = "non-finite residual";
      return rep;
    }
    if (opt_.verbose)
      std::fprintf(stderr, "    newton p=%.4g kPa it=%d |R|=%.3e ref=%.3e cuts=%d\n", p * 1e-3, it, rep.residual_N,
                   rep.reference_N, rep.line_search_cuts);
    if (rep.residual_N <= opt_.rel_tol * rep.reference_N + opt_.abs_tol_N) {
      rep.converged = true;
      return rep;
    }
    if (it == opt_.max_iterations) break;
    ++stats_.iterations;

    // Factorise; if not positive definite, shift the diagonal (Levenberg-style) and retry.
    t0 = std::chrono::steady_clock::now();
    double mean_diag = 0.0;
    for (int i = 0; i < n; ++i) mean_diag += std::abs(K_.coeff(i, i));
    mean_diag /= n;
    asm_.apply_constraints(K_, mean_diag);
    bool ok = linear_.factorize(K_);
    ++stats_.factorizations;
    if (!ok) {
      SparseMatrix Ks = K_;
      const Eigen::VectorXd d = Ks.diagonal().cwiseAbs();
      for (double beta = 1e-6; beta <= 10.0 && !ok; beta *= 10.0) {
        for (int i = 0; i < n; ++i) Ks.coeffRef(i, i) = K_.coeff(i, i) + beta * d[i];
        ok = linear_.factorize(Ks);
        ++stats_.factorizations;
      }
      ++rep.regularised;
      if (!ok) {
        rep.failure = "tangent could not be factorised even with a diagonal shift";
        return rep;
      }
    }
    stats_.factor_s += seconds_since(t0);
    const Eigen::VectorXd du = -linear_.solve(R);

    // Line search on s(alpha) = du . R(u + alpha du) (works for the non-potential follower load).
    const double s0 = du.dot(R);
    double alpha = 1.0;
    Eigen::VectorXd u_try;
    for (int ls = 0; ls < 8; ++ls) {
      u_try = u + alpha * du;
      Eigen::VectorXd R1;
      try {
        R1 = residual(p, ts, s_old, s_new, u_try);
      } catch (const PhysicsError&) {
        alpha *= 0.5;
        ++rep.line_search_cuts;
        continue;
      }
      const double s1 = du.dot(R1);
      if (!std::isfinite(s1)) {
        alpha *= 0.5;
        ++rep.line_search_cuts;
        continue;
      }
      if (s0 >= 0.0 || std::abs(s1) <= 0.8 * std::abs(s0) || s1 < 0.0) break;
      // Root of the secant through (0, s0) and (alpha, s1), kept in [0.1, 1] of the current alpha.
      const double a_new = alpha * std::clamp(s0 / (s0 - s1), 0.1, 1.0);
      if (a_new >= alpha * 0.999) break;
      alpha = a_new;
      ++rep.line_search_cuts;
    }
    u = u_try;
  }
  std::ostringstream s;
  s << "no convergence in " << opt_.max_iterations << " iterations (residual " << rep.residual_N << " N, reference "
    << rep.reference_N << " N)";
  rep.failure = s.str();
  return rep;
}

void StaticSolver::advance(double p0, double p1, double t0, double t1, std::vector<double>& state,
                           Eigen::VectorXd& u) {
  const double span = p1 - p0;
  std::vector<double> trial(state.size());
  if (std::abs(span) < 1e-12) {
    // Pure time increment at constant pressure (rate laws evolve).
    TimeStep ts{t1, t1 - t0};
    NewtonReport r = solve(p1, ts, state, trial, u);
    ++stats_.increments;
    if (!r.converged) {
      std::ostringstream s;
      s << "static solve failed at p = " << p1 * 1e-3 << " kPa, t = " << t1 << " s: " << r.failure;
      throw PhysicsError(s.str(), -1, t1);
    }
    state.swap(trial);
    return;
  }
  double s_done = 0.0;  // fraction of the increment completed
  double ds = std::min(1.0, opt_.max_increment_Pa / std::abs(span));
  if (last_du_per_Pa_.size() != u.size()) last_du_per_Pa_ = Eigen::VectorXd::Zero(u.size());
  while (s_done < 1.0 - 1e-12) {
    ds = std::min(ds, 1.0 - s_done);
    const double pa = p0 + s_done * span, pb = p0 + (s_done + ds) * span;
    const double ta = t0 + s_done * (t1 - t0), tb = t0 + (s_done + ds) * (t1 - t0);
    Eigen::VectorXd u_try = u + last_du_per_Pa_ * (pb - pa);  // secant predictor
    NewtonReport r = solve(pb, TimeStep{tb, tb - ta}, state, trial, u_try);
    if (!r.converged) {
      // A bad predictor can fail where the plain warm start would not: retry once without it.
      u_try = u;
      r = solve(pb, TimeStep{tb, tb - ta}, state, trial, u_try);
    }
    if (!r.converged) {
      ++stats_.cutbacks;
      ds *= 0.5;
      last_du_per_Pa_.setZero();
      if (ds * std::abs(span) < opt_.min_increment_Pa) {
        std::ostringstream s;
        s << "static continuation stalled at p = " << pa * 1e-3 << " kPa (t = " << ta << " s): " << r.failure
          << ". Hint: the actuator may be at a ballooning limit point, where a load-controlled static "
             "solve cannot continue; use solver.mode = \"explicit\" (dynamic) beyond it, or a stiffer/thicker design.";
        throw PhysicsError(s.str(), -1, ta);
      }
      continue;
    }
    ++stats_.increments;
    last_du_per_Pa_ = (u_try - u) / (pb - pa);
    u = u_try;
    state.swap(trial);
    s_done += ds;
    if (r.iterations <= 4) ds *= 1.5;
  }
}

}  // namespace pneufem
