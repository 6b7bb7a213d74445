#include "engine/static_solver.h"

#include <chrono>
#include <cstdio>
#include <cmath>
#include <limits>
#include <sstream>

#include "core/errors.h"

namespace pneufem {

namespace {
double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}
}  // namespace

namespace {
// True when the follower-pressure load is conservative, f_p = p dV/du with V the cavity volume of
// Assembler::cavity_volume: a closed cavity, or one closed by symmetry planes through the origin.
// Checked once, at the reference state, along a fixed pseudo-random direction of the free dofs: an
// open cavity (a deck's surface with a hole) differs by a boundary term of the order of f_p itself.
// Tolerance 1e-6: the central difference of a cubic in the step is exact up to round-off (~1e-12
// relative at the step used); a mismatch below 1e-6 would not mislead an Armijo test.
bool pressure_is_conservative(const Assembler& a) {
  const Model& m = a.model();
  if (m.pressure_faces.empty()) return true;
  const int n = a.num_dofs();
  const Eigen::VectorXd zero = Eigen::VectorXd::Zero(n);
  Eigen::VectorXd f = Eigen::VectorXd::Zero(n), d = Eigen::VectorXd::Zero(n);
  a.add_pressure(zero, 1.0, f, nullptr);
  for (int i = 0; i < n; ++i)
    if (!m.fixed[i]) d[i] = std::sin(12.9898 * i + 78.233);
  const MeshStats st = compute_stats(m.mesh);
  const double eps = 1e-6 * (st.bbox_max - st.bbox_min).norm();  // step (m): small against the body
  const double dV = (a.cavity_volume(eps * d) - a.cavity_volume(-eps * d)) / (2.0 * eps);
  const double fd = f.dot(d);
  double scale = 0.0;
  for (int i = 0; i < n; ++i) scale += std::abs(f[i] * d[i]);
  return std::abs(dV - fd) <= 1e-6 * scale;
}
}  // namespace

StaticSolver::StaticSolver(const Assembler& assembler, StaticOptions options)
    : asm_(assembler), opt_(options), K_(assembler.tangent_pattern()) {
  force_floor_ = reference_force_floor(assembler);
  gravity_load_ = Eigen::VectorXd::Zero(assembler.num_dofs());
  assembler.add_gravity(gravity_load_);
  // Material history (damage, viscosity) makes the incremental problem non-potential in general.
  has_potential_ = assembler.state_size() == 0 && pressure_is_conservative(assembler);
  if (opt_.stiff_relaxation_steps <= 0) return;
  // The stiff layer: every node of an element whose material is stiff_modulus_ratio times stiffer
  // (initial shear modulus) than the softest part. Nodes it shares with the soft body belong to it
  // too: they carry its stretch. A fabric modelled as a membrane is deliberately not included:
  // relaxing its triangles' nodes moved the h = 4 membrane actuator onto a different equilibrium
  // (0.3 % in angle at 10 kPa) from the small-increment load path, and plain Newton already converges
  // it within max_iterations (BENCHMARKS.md §6).
  const Model& m = assembler.model();
  double mu_min = std::numeric_limits<double>::infinity();
  for (const Part& part : m.parts) mu_min = std::min(mu_min, part.material->initial_shear_modulus());
  std::vector<unsigned char> stiff_node(m.mesh.num_nodes(), 0);
  for (int e = 0; e < m.mesh.num_elements(); ++e)
    if (m.material_of(e).initial_shear_modulus() > opt_.stiff_modulus_ratio * mu_min)
      for (int a = 0; a < m.mesh.npe(); ++a) stiff_node[m.mesh.element(e)[a]] = 1;
  stiff_index_.assign(m.num_dofs(), -1);
  for (int i = 0; i < m.num_dofs(); ++i)
    if (stiff_node[i / 3] && !m.fixed[i]) {
      stiff_index_[i] = static_cast<int>(stiff_dofs_.size());
      stiff_dofs_.push_back(i);
    }
  if (stiff_dofs_.empty()) stiff_index_.clear();
}

void StaticSolver::relax_stiff_layer(double p, const TimeStep& ts, std::span<const double> s_old,
                                     std::span<double> s_new, Eigen::VectorXd& u, Eigen::VectorXd& R,
                                     double* potential) {
  const int ns = static_cast<int>(stiff_dofs_.size());
  if (!stiff_factor_current_) {
    // The layer's block of the current tangent (its own stiffness plus the soft elements on its
    // nodes): a thin-layer matrix, far cheaper to factorise than the whole tangent. It is the
    // tangent at the start of this Newton iteration, so the relaxation is a chord method; the
    // layer is linear elastic in its own frame, which is why that suffices.
    std::vector<Eigen::Triplet<double>> entries;
    for (int c : stiff_dofs_)
      for (SparseMatrix::InnerIterator it(K_, c); it; ++it)
        if (const int r = stiff_index_[it.row()]; r >= 0) entries.emplace_back(r, stiff_index_[c], it.value());
    SparseMatrix Kss(ns, ns);
    Kss.setFromTriplets(entries.begin(), entries.end());
    ++stats_.stiff_factorizations;
    if (!stiff_linear_.factorize(Kss)) return;  // not positive definite: no elimination this iteration
    stiff_factor_current_ = true;
  }
  Eigen::VectorXd rs(ns), u1;
  for (int k = 0; k < opt_.stiff_relaxation_steps; ++k) {
    for (int i = 0; i < ns; ++i) rs[i] = R[stiff_dofs_[i]];
    if (rs.norm() <= 0.1 * R.norm()) return;  // the layer is in equilibrium; the rest is the soft body's
    const Eigen::VectorXd ds = stiff_linear_.solve(rs);
    u1 = u;
    for (int i = 0; i < ns; ++i) u1[stiff_dofs_[i]] -= ds[i];
    Eigen::VectorXd R1;
    double Pi1 = 0.0;
    try {
      R1 = residual(p, ts, s_old, s_new, u1, potential ? &Pi1 : nullptr);
    } catch (const PhysicsError&) {
      return;  // the relaxed state inverts an element: keep u
    }
    if (opt_.verbose)
      std::fprintf(stderr, "      stiff-layer relaxation %d: |R| %.3e -> %.3e (layer part %.3e)\n", k, R.norm(),
                   R1.norm(), rs.norm());
    if (!(R1.norm() < R.norm())) return;
    u.swap(u1);
    R.swap(R1);
    if (potential) *potential = Pi1;
    ++stats_.stiff_relaxations;
  }
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

double StaticSolver::potential_from(double W, double p, const Eigen::VectorXd& u) const {
  return W - p * asm_.cavity_volume(u) - gravity_scale_ * gravity_load_.dot(u);
}

Eigen::VectorXd StaticSolver::residual(double p, const TimeStep& ts, std::span<const double> s_old,
                                       std::span<double> s_new, const Eigen::VectorXd& u, double* potential) {
  Eigen::VectorXd f_int, f_ext = Eigen::VectorXd::Zero(asm_.num_dofs());
  double W = 0.0;
  asm_.internal(u, ts, s_old, s_new, &f_int, nullptr, potential ? &W : nullptr);
  if (potential) *potential = potential_from(W, p, u);
  asm_.add_pressure(u, p, f_ext, nullptr);
  asm_.add_gravity(f_ext, gravity_scale_);
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
  double previous_residual = std::numeric_limits<double>::infinity();
  const bool energy_search = has_potential_ && opt_.energy_line_search;
  last_step_krylov_ = false;
  force_factor_ = false;
  solve_give_ups_ = 0;
  for (int it = 0; it <= opt_.max_iterations; ++it) {
    // Residual and tangent at u.
    auto t0 = std::chrono::steady_clock::now();
    f_ext.setZero(n);
    double W0 = 0.0;
    try {
      asm_.internal(u, ts, s_old, s_new, &f_int, &K_, energy_search ? &W0 : nullptr);
    } catch (const PhysicsError& e) {
      rep.failure = e.what();
      return rep;
    }
    asm_.add_pressure(u, p, f_ext, &K_);
    asm_.add_gravity(f_ext, gravity_scale_);
    stats_.assembly_s += seconds_since(t0);
    R = f_int - f_ext;
    // Force scale of the criterion: the applied load, or the reactions when the loading is by
    // prescribed displacement, never below the structural floor. It is evaluated at the current
    // iterate and not accumulated, so a poor trial state cannot loosen the tolerance.
    double reactions2 = 0.0;
    for (int i = 0; i < n; ++i)
      if (asm_.model().fixed[i]) reactions2 += f_int[i] * f_int[i];
    rep.reference_N = std::max({f_ext.norm(), std::sqrt(reactions2), force_floor_});
    asm_.zero_fixed(R);
    rep.residual_N = R.norm();
    rep.iterations = it;
    if (!std::isfinite(rep.residual_N)) {
      rep.failure = "non-finite residual";
      return rep;
    }
    if (opt_.verbose)
      std::fprintf(stderr, "    newton p=%.4g kPa it=%d |R|=%.3e ref=%.3e cuts=%d chords=%ld\n", p * 1e-3, it,
                   rep.residual_N, rep.reference_N, rep.line_search_cuts, stats_.chord_steps);
    const double tol = opt_.rel_tol * rep.reference_N + opt_.abs_tol_N;
    // Converged; or stagnating within 100x the tolerance, which is the round-off floor of the
    // residual (the stiff fabric's internal forces carry ~1e-16 relative error).
    // A stall after an inexact step (CG with an old factor, krylov_on_ramps) is not that floor: the
    // contraction rule below factorises instead.
    const bool inexact = ramp_rules_ && last_step_krylov_;
    if (rep.residual_N <= tol ||
        (rep.residual_N <= 100.0 * tol && rep.residual_N >= 0.5 * previous_residual && !inexact)) {
      rep.converged = true;
      return rep;
    }
    // Give-up of the Krylov steps (krylov_on_ramps): a CG step with an old factor that did not at
    // least halve the residual (line search and chord steps included) says the old factor's tangent
    // is too far from this one for an inexact step to be worth it: factorise in this iteration.
    if (inexact && !(rep.residual_N <= 0.5 * previous_residual)) {
      force_factor_ = true;
      ++stats_.contraction_refactors;
    }
    previous_residual = rep.residual_N;
    if (it == opt_.max_iterations) break;
    ++stats_.iterations;

    t0 = std::chrono::steady_clock::now();
    double mean_diag = 0.0;
    for (int i = 0; i < n; ++i) mean_diag += std::abs(K_.coeff(i, i));
    mean_diag /= n;
    asm_.apply_constraints(K_, mean_diag);
    stiff_factor_current_ = false;
    Eigen::VectorXd du;
    const bool ok = linear_step(R, du, rep);
    stats_.factor_s += seconds_since(t0);
    if (!ok) return rep;

    const Eigen::VectorXd u_try = line_search(p, ts, s_old, s_new, u, du, R, W0, tol, rep);
    u = u_try;
    chord_steps(p, ts, s_old, s_new, u, rep);
  }
  std::ostringstream s;
  s << "no convergence in " << opt_.max_iterations << " iterations (residual " << rep.residual_N << " N, reference "
    << rep.reference_N << " N)";
  rep.failure = s.str();
  return rep;
}

Eigen::VectorXd StaticSolver::line_search(double p, const TimeStep& ts, std::span<const double> s_old,
                                          std::span<double> s_new, const Eigen::VectorXd& u, const Eigen::VectorXd& du,
                                          const Eigen::VectorXd& R, double W0, double tol, NewtonReport& rep) {
  const bool energy_search = has_potential_ && opt_.energy_line_search;
  // Line search on s(alpha) = du . R(u + alpha du) (works for the non-potential follower load).
  // With a stiff layer, R is taken at the state relaxed in the layer (stiff-layer elimination):
  // s(alpha) is then the slope of the energy with the layer in equilibrium, so the step is not cut
  // for the layer's spurious stretch. With a potential, the step must first lower it (Armijo,
  // sufficient-decrease constant 1e-4, the usual choice); not in the last iterations (within 100x
  // the tolerance), where Pi changes by less than its round-off.
  const double s0 = du.dot(R);
  if (opt_.verbose) std::fprintf(stderr, "      |du|=%.3e max|du|=%.3e decrement du.R=%.3e\n", du.norm(), du.lpNorm<Eigen::Infinity>(), s0);
  const bool armijo = energy_search && s0 < 0.0 && rep.residual_N > 100.0 * tol;
  const double Pi0 = armijo ? potential_from(W0, p, u) : 0.0;
  double alpha = 1.0;
  Eigen::VectorXd u_try;
  for (int ls = 0; ls < 8; ++ls) {
    u_try = u + alpha * du;
    Eigen::VectorXd R1;
    double Pi1 = 0.0;
    try {
      R1 = residual(p, ts, s_old, s_new, u_try, armijo ? &Pi1 : nullptr);
    } catch (const PhysicsError&) {
      alpha *= 0.5;
      ++rep.line_search_cuts;
      continue;
    }
    if (!stiff_dofs_.empty()) relax_stiff_layer(p, ts, s_old, s_new, u_try, R1, armijo ? &Pi1 : nullptr);
    const double s1 = du.dot(R1);
    if (!std::isfinite(s1)) {
      alpha *= 0.5;
      ++rep.line_search_cuts;
      continue;
    }
    if (armijo && !(Pi1 <= Pi0 + 1e-4 * alpha * s0)) {
      // The energy rose: go to the minimum of the parabola through Pi0, slope s0 and Pi1, kept
      // within [0.1, 0.5] of alpha (a rise means the minimum lies well inside the step).
      const double c = (Pi1 - Pi0 - s0 * alpha) / (alpha * alpha);
      const double a_min = c > 0.0 ? -s0 / (2.0 * c) : 0.5 * alpha;
      if (opt_.verbose)
        std::fprintf(stderr, "      alpha=%.3g: potential %+.3e J (Armijo bound %+.3e J), |R| %.3e\n", alpha, Pi1 - Pi0,
                     1e-4 * alpha * s0, R1.norm());
      alpha = std::clamp(a_min, 0.1 * alpha, 0.5 * alpha);
      ++rep.line_search_cuts;
      ++stats_.energy_cuts;
      continue;
    }
    if (s0 >= 0.0 || std::abs(s1) <= 0.8 * std::abs(s0) || s1 < 0.0) break;
    // Root of the secant through (0, s0) and (alpha, s1), kept in [0.1, 1] of the current alpha.
    const double a_new = alpha * std::clamp(s0 / (s0 - s1), 0.1, 1.0);
    if (a_new >= alpha * 0.999) break;
    alpha = a_new;
    ++rep.line_search_cuts;
  }
  return u_try;
}

void StaticSolver::chord_steps(double p, const TimeStep& ts, std::span<const double> s_old, std::span<double> s_new,
                               Eigen::VectorXd& u, const NewtonReport& rep) {
  // Chord steps with the factor just computed (Shamanskii's method). A stiff inextensible layer
  // makes every Newton step that bends the structure stretch the layer to second order in the
  // rotation increment, which shows as a large but "stiff" residual; one back-substitution with
  // the same factor removes it at a fraction of a new factorisation's cost. Steps continue while
  // they at least halve the residual.
  if (linear_->has_factor()) {
    Eigen::VectorXd Rc;
    try {
      Rc = residual(p, ts, s_old, s_new, u);
    } catch (const PhysicsError&) {
      return;  // the next Newton iteration starts from u
    }
    for (int c = 0; c < opt_.chord_steps; ++c) {
      const double r0 = Rc.norm();
      if (r0 <= opt_.rel_tol * rep.reference_N + opt_.abs_tol_N) break;
      const Eigen::VectorXd dc = -linear_->solve(Rc);
      Eigen::VectorXd R2;
      try {
        R2 = residual(p, ts, s_old, s_new, u + dc);
      } catch (const PhysicsError&) {
        break;
      }
      if (!(R2.norm() <= 0.5 * r0)) break;
      u += dc;
      Rc.swap(R2);
      ++stats_.chord_steps;
    }
  }
}

bool StaticSolver::factorize_current(NewtonReport& rep) {
  bool ok = spare_->factorize(K_);
  ++stats_.factorizations;
  if (ok) {
    std::swap(linear_, spare_);
    return true;
  }
  // Not positive definite (past a limit point, or a poor trial state).
  ++rep.regularised;
  if (opt_.indefinite == StaticOptions::Indefinite::LastFactor && linear_->has_factor()) {
    // Modified-Newton step with the last positive-definite tangent (see the class comment).
    ++stats_.last_factor_steps;
    if (opt_.verbose) std::fprintf(stderr, "      tangent not positive definite: step with the last factor\n");
    return true;
  }
  // No factor yet (or Indefinite::Shift): shift the diagonal (Levenberg-style) until the
  // factorisation succeeds.
  const int n = asm_.num_dofs();
  SparseMatrix Ks = K_;
  const Eigen::VectorXd d = K_.diagonal().cwiseAbs();
  for (double beta = 1e-6; beta <= 10.0 && !ok; beta *= 10.0) {
    for (int i = 0; i < n; ++i) Ks.coeffRef(i, i) = K_.coeff(i, i) + beta * d[i];
    ok = spare_->factorize(Ks);
    ++stats_.factorizations;
    if (opt_.verbose)
      std::fprintf(stderr, "      tangent not positive definite; shift beta=%.0e: %s\n", beta, ok ? "ok" : "not PD");
  }
  if (ok) std::swap(linear_, spare_);
  if (!ok) rep.failure = "tangent could not be factorised even with a diagonal shift";
  return ok;
}

bool StaticSolver::linear_step(const Eigen::VectorXd& R, Eigen::VectorXd& du, NewtonReport& rep) {
  // Inexact Newton-Krylov: conjugate gradients on the current tangent, preconditioned by the
  // Cholesky factor of an earlier tangent. Between nearby states (load sub-increments, time steps,
  // later Newton iterations) that factor is an excellent preconditioner, so a few CG iterations
  // (each one sparse product and two triangular solves) replace a new factorisation, which costs
  // ~40 triangular solves. CG stops at a relative residual of krylov_rel_tol, enough for
  // superlinear Newton convergence; on breakdown or slow convergence we re-factorise.
  //
  // With krylov_on_ramps (load increments too, where the old factor is one of another pressure)
  // four rules bound the cost of a poor preconditioner (at most one abandoned, short CG attempt per
  // load increment, and one Newton iteration per Krylov step that does not pay):
  //  * CG is abandoned as soon as its observed mean contraction per iteration, continued over the
  //    remaining allowance, would not reach the tolerance (instead of running out the allowance);
  //  * after one abandoned CG the rest of the Newton solve factorises (the tangent changes too fast
  //    between iterates for an older factor: a lagged factor of the same solve fails as well);
  //  * a Krylov step after which the Newton residual did not halve forces a factorisation in the
  //    next iteration (solve());
  //  * negative curvature p.Kp <= 0 met by CG proves the tangent is not positive definite, so its
  //    Cholesky factorisation would fail: with Indefinite::LastFactor the step is then the
  //    last-factor step that the failed factorisation would have led to, without that factorisation.
  // The converged answer is the same: the Newton residual test does not change, only the iterates.
  const bool ramp_rules = ramp_rules_;
  last_step_krylov_ = false;
  if (krylov_allowed_ && !force_factor_ && !(ramp_rules && solve_give_ups_ > 0) && opt_.krylov_max_iterations > 0 &&
      linear_->has_factor()) {
    const Eigen::VectorXd b = -R;
    du = Eigen::VectorXd::Zero(b.size());
    Eigen::VectorXd r = b, z = linear_->solve(r), pdir = z, Kp;
    double rz = r.dot(z);
    const double b_norm = b.norm(), target = opt_.krylov_rel_tol * b_norm;
    for (int k = 0; k < opt_.krylov_max_iterations; ++k) {
      Kp = K_ * pdir;
      const double pKp = pdir.dot(Kp);
      if (!(pKp > 0.0)) {  // not positive definite along p
        if (ramp_rules && opt_.indefinite == StaticOptions::Indefinite::LastFactor) {
          ++rep.regularised;
          ++stats_.last_factor_steps;
          ++stats_.indefinite_by_cg;
          if (opt_.verbose) std::fprintf(stderr, "      CG: tangent not positive definite: step with the last factor\n");
          du = -linear_->solve(R);
          return true;
        }
        break;  // use a factorisation
      }
      const double alpha = rz / pKp;
      du += alpha * pdir;
      r -= alpha * Kp;
      ++stats_.krylov_iterations;
      const double r_norm = r.norm();
      if (r_norm <= target) {
        ++stats_.krylov_steps;
        last_step_krylov_ = true;
        return true;
      }
      if (ramp_rules && k >= 1) {
        // Mean contraction so far; give up when the allowance left cannot reach the target at it.
        const double rate = std::pow(r_norm / b_norm, 1.0 / (k + 1));
        const int left = opt_.krylov_max_iterations - (k + 1);
        if (!(rate < 1.0) || r_norm * std::pow(rate, left) > target) break;
      }
      z = linear_->solve(r);
      const double rz_new = r.dot(z);
      pdir = z + (rz_new / rz) * pdir;
      rz = rz_new;
    }
    if (ramp_rules) {
      ++stats_.krylov_give_ups;
      ++solve_give_ups_;
    }
  }
  force_factor_ = false;
  if (!factorize_current(rep)) return false;
  du = -linear_->solve(R);
  return true;
}

NewtonReport StaticSolver::solve_first_with_weight(double p, const TimeStep& ts, std::span<const double> s_old,
                                                   std::span<double> s_new, Eigen::VectorXd& u) {
  const Eigen::VectorXd u0 = u;
  NewtonReport r = solve(p, ts, s_old, s_new, u);
  if (r.converged || has_equilibrium_ || asm_.model().gravity_m_s2.isZero()) return r;
  // The full weight in one Newton solve from the unloaded state fails for a long soft actuator
  // lying on its side (the default 126 mm pneu-net sags ~18 deg). Ramp it in: the fraction grows by
  // df, halved after a failed solve (restarting from the last equilibrium), doubled after a
  // success; a weight the structure cannot carry fails below 1/1024 of a step with the original
  // report. Same equilibrium as one solve would find (the ramp only supplies the start).
  u = u0;
  double f = 0.0, df = 0.125;
  while (f < 1.0) {
    const double f1 = std::min(1.0, f + df);
    gravity_scale_ = f1;
    Eigen::VectorXd u1 = u;
    const NewtonReport r1 = solve(p, ts, s_old, s_new, u1);
    if (!r1.converged) {
      df *= 0.5;
      if (df < 1.0 / 1024.0) {
        gravity_scale_ = 1.0;
        return r;
      }
      continue;
    }
    u = u1;
    f = f1;
    df = std::min(0.5, 2.0 * df);
    if (f1 == 1.0) {
      gravity_scale_ = 1.0;
      return r1;
    }
  }
  gravity_scale_ = 1.0;
  return r;
}

// An instantaneous release to zero pressure (t1 == t0, as between the trials of a staircase) leaves
// the history where it is: no rate law evolves in zero time, and a Prony term's overstress changes by
// gamma times the change of the stress whatever the path (Q += gamma (S - S_old) telescopes), so the
// end state does not depend on the way down (only a Mullins point whose energy rose above its
// maximum part-way down and fell again would notice; a release unloads the walls). Continuation
// back down from the top of the staircase retraces the hardest part of the climb, near the limit
// point: with the rest that follows, 40-50 % of each trial's wall time in the ten-trial story
// (BENCHMARKS §7). At zero load the reference configuration is the natural start: one Newton solve
// from it, and the caller continues along the path as before when it does not converge (it does not
// when the released actuator keeps a large bend from a Prony overstress: 1 of 3 releases converged in
// a four-trial A/B of the story, so the gain is a few percent so far).
bool StaticSolver::release_from_reference(double p0, double t, std::vector<double>& state,
                                          std::vector<double>& trial, Eigen::VectorXd& u) {
  if (p0 == 0.0 || !has_equilibrium_) return false;
  Eigen::VectorXd u_try = Eigen::VectorXd::Zero(u.size());  // fixed dofs are prescribed zero (model.h)
  const NewtonReport r = solve(0.0, TimeStep{t, 0.0}, state, trial, u_try);
  ++stats_.release_attempts;
  if (!r.converged) return false;
  ++stats_.increments;
  ++stats_.direct_releases;
  u = u_try;
  state.swap(trial);
  asm_.update_nonlocal(u, state);
  path_p_.assign(1, 0.0);  // the path down was not followed: extrapolate from here only
  path_u_.assign(1, u);
  return true;
}

void StaticSolver::advance_in_time(double p1, double t0, double t1, std::vector<double>& state,
                                   std::vector<double>& trial, Eigen::VectorXd& u) {
  // Pure time increment at constant pressure (rate laws evolve): the tangent changes little
  // from one time step to the next, so the last factorisation preconditions CG well.
  TimeStep ts{t1, t1 - t0};
  krylov_allowed_ = true;
  NewtonReport r = solve_first_with_weight(p1, ts, state, trial, u);
  krylov_allowed_ = false;
  ++stats_.increments;
  if (!r.converged) {
    std::ostringstream s;
    s << "static solve failed at p = " << p1 * 1e-3 << " kPa, t = " << t1 << " s: " << r.failure;
    throw PhysicsError(s.str(), -1, t1);
  }
  has_equilibrium_ = true;
  state.swap(trial);
  asm_.update_nonlocal(u, state);
}

Eigen::VectorXd StaticSolver::predictor(double pa, double pb, double ta, double tb, std::span<const double> state,
                                        std::span<double> trial, const Eigen::VectorXd& u) {
  // Start from the polynomial extrapolation of the last equilibria (quadratic through three,
  // else linear through two) when it balances the new load better than the previous
  // equilibrium does. Quadratic extrapolation follows the arc of a bending actuator, so the
  // stiff fabric is not stretched by a tangent-line predictor.
  Eigen::VectorXd u_try = u;
  const std::size_t m = path_p_.size();
  if (m >= 2 && path_p_.back() == pa) {
    Eigen::VectorXd u_pred;
    if (m >= 3) {
      const double x0 = path_p_[m - 3], x1 = path_p_[m - 2], x2 = path_p_[m - 1];
      const double l0 = (pb - x1) * (pb - x2) / ((x0 - x1) * (x0 - x2));
      const double l1 = (pb - x0) * (pb - x2) / ((x1 - x0) * (x1 - x2));
      const double l2 = (pb - x0) * (pb - x1) / ((x2 - x0) * (x2 - x1));
      u_pred = l0 * path_u_[m - 3] + l1 * path_u_[m - 2] + l2 * path_u_[m - 1];
    } else {
      const double x0 = path_p_[0], x1 = path_p_[1];
      u_pred = path_u_[1] + (path_u_[1] - path_u_[0]) * ((pb - x1) / (x1 - x0));
    }
    const TimeStep ts{tb, tb - ta};
    try {
      if (residual(pb, ts, state, trial, u_pred).norm() < residual(pb, ts, state, trial, u).norm()) u_try = u_pred;
    } catch (const PhysicsError&) {
      // the extrapolated state inverts an element: keep the warm start
    }
  }
  return u_try;
}

PhysicsError StaticSolver::stalled_continuation(double pa, double ta, const NewtonReport& r) const {
  // The hint depends on what Newton saw: a tangent that had to be regularised (not positive
  // definite) means the structure is at or past a limit point; a positive-definite tangent
  // with a residual still falling means Newton merely ran out of iterations.
  std::ostringstream s;
  std::string why = r.failure;  // a sentence of its own (an element's message): its full stop is ours below
  if (!why.empty() && why.back() == '.') why.pop_back();
  s << "static continuation stalled at p = " << pa * 1e-3 << " kPa (t = " << ta << " s): " << why;
  if (r.regularised > 0)
    // Only what works: past a limit point under a pressure load there is no nearby
    // equilibrium (the wall balloons or the softened part gives way), so explicit dynamics,
    // which this hint once suggested, runs away into an inverted element (issue 30 item 6).
    s << ". Hint: the tangent stiffness is not positive definite there, so the actuator is at a limit "
         "point (ballooning, or a softened part giving way): above about "
      << pa * 1e-3
      << " kPa it has no equilibrium near this one, and no solver follows it (explicit dynamics "
         "runs away into an inverted element). Keep the pressure below it (load.max_kPa, or the recording's "
         "peak), or make the actuator stiffer: thicker walls (geometry.*) or a stiffer silicone.";
  else
    s << ". Hint: the tangent stayed positive definite (no limit point detected) and Newton did not converge "
         "within solver.max_iterations = "
      << opt_.max_iterations
      << "; strongly nonlinear states (a membrane fabric, softened damage) can need 30-40 iterations: raise "
         "solver.max_iterations, or reduce solver.max_increment_kPa.";
  return PhysicsError(s.str(), -1, ta);
}

void StaticSolver::advance(double p0, double p1, double t0, double t1, std::vector<double>& state,
                           Eigen::VectorXd& u) {
  const double span = p1 - p0;
  std::vector<double> trial(state.size());
  if (std::abs(span) < 1e-12) return advance_in_time(p1, t0, t1, state, trial, u);
  if (p1 == 0.0 && t1 == t0 && release_from_reference(p0, t1, state, trial, u)) return;
  double s_done = 0.0;  // fraction of the increment completed
  double ds = std::min(1.0, opt_.max_increment_Pa / std::abs(span));
  while (s_done < 1.0 - 1e-12) {
    ds = std::min(ds, 1.0 - s_done);
    const double pa = p0 + s_done * span, pb = p0 + (s_done + ds) * span;
    const double ta = t0 + s_done * (t1 - t0), tb = t0 + (s_done + ds) * (t1 - t0);
    Eigen::VectorXd u_try = predictor(pa, pb, ta, tb, state, trial, u);
    // Newton-Krylov on the load increment (krylov_on_ramps), with the give-ups of linear_step. The
    // time steps at constant pressure keep their plain Krylov steps (advance_in_time): there the
    // give-ups cost factorisations (measured on the h = 6 story's rests: 66 against 32).
    krylov_allowed_ = ramp_rules_ = opt_.krylov_on_ramps;
    NewtonReport r = solve(pb, TimeStep{tb, tb - ta}, state, trial, u_try);
    krylov_allowed_ = ramp_rules_ = false;
    if (!r.converged) {
      ++stats_.cutbacks;
      ds *= 0.5;
      if (ds * std::abs(span) < opt_.min_increment_Pa) throw stalled_continuation(pa, ta, r);
      continue;
    }
    ++stats_.increments;
    has_equilibrium_ = true;
    if (path_p_.empty() || path_p_.back() != pa) {
      path_p_.assign(1, pa);
      path_u_.assign(1, u);
    }
    path_p_.push_back(pb);
    path_u_.push_back(u_try);
    if (path_p_.size() > 3) {
      path_p_.erase(path_p_.begin());
      path_u_.erase(path_u_.begin());
    }
    u = u_try;
    state.swap(trial);
    asm_.update_nonlocal(u, state);
    s_done += ds;
    // Aim at ~4-6 iterations per increment.
    if (r.iterations <= 4)
      ds *= 1.5;
    else if (r.iterations >= 8)
      ds *= 0.7;
  }
}

}  // namespace pneufem
