// Quasi-static mode on a small pneu-net (2 chambers, coarse): the staircase driver with warm
// starts gives the same equilibrium angle whether each state is solved by Newton or by dynamic
// relaxation (explicit pseudo-dynamics with per-node fictitious masses and kinetic damping).
// Relaxation is slow here (the 6.5 GPa fabric makes the pseudo-dynamic system stiff: ~10^4-10^5
// iterations per state), which is why Newton is the default; BENCHMARKS.md has the numbers.
#include <cmath>
#include <functional>

#include <gtest/gtest.h>

#include "core/errors.h"
#include "engine/angle.h"
#include "engine/assembly.h"
#include "engine/quasi_static.h"
#include "engine/static_solver.h"
#include "scenes/build_model.h"
#include "tests/engine/test_meshes.h"

namespace pneufem {
namespace {

const std::vector<std::string> kSmall = {"geometry.chambers=2", "mesh.h_mm=6.0", "load.max_kPa=10.0"};

// A load history that starts loaded (a recording's first frame at t = 0 under pressure or on a rig
// with gravity) reports its first state solved: the same elastic equilibrium as a second report at
// the same load, not the unloaded shape (which it was until 2026-11-25: angle 0 at t = 0 and a
// ramp to the sag over the first 0.25 s of every gravity recording).
TEST(PneuNetSolvers, AReportAtTimeZeroIsAnEquilibriumUnderLoadOrGravity) {
  struct Case {
    std::string gravity;
    double p_Pa;
  };
  for (const Case& c : {Case{"[0.0, 0.0, -9.81]", 0.0}, Case{"[0.0, 0.0, 0.0]", 4e3}, Case{"[0.0, 0.0, -9.81]", 4e3}}) {
    std::vector<std::string> sets = kSmall;
    sets.push_back("gravity.g_m_s2=" + c.gravity);
    auto bm = build_model(Scene::load("", sets));
    Assembler A(bm->model);
    LoadHistory load;
    TrialLoad tl;
    tl.time_s = {0.0, 1.0};
    tl.pressure_Pa = {c.p_Pa, c.p_Pa};
    tl.output_s = {0.0, 1.0};
    load.trials.push_back(tl);
    QuasiStaticRun run(A, bm->solver.quasi_static);
    std::vector<double> angles;
    run.run(load, [&](const StateRecord& r, const Eigen::VectorXd&, const std::vector<double>&) { angles.push_back(r.angle_deg); });
    ASSERT_EQ(angles.size(), 2u);
    EXPECT_GT(std::abs(angles[1]), 0.01) << c.gravity << " " << c.p_Pa;  // the load bends it measurably
    // Both are equilibria of the same elastic problem to rel_tol 1e-8 (the second from the first as
    // its warm start): equal far below 1e-6 of the angle.
    EXPECT_NEAR(angles[0], angles[1], 1e-6 * std::abs(angles[1])) << c.gravity << " " << c.p_Pa;
  }
}

TEST(PneuNetSolvers, QuasiStaticDriverGivesTheSameAngleWithEitherMethod) {
  // The whole quasi-static driver (staircase, warm starts) with Newton and with relaxation.
  auto angle_at_top = [](const std::string& method) {
    std::vector<std::string> sets = kSmall;
    sets.push_back("solver.method=\"" + method + "\"");
    sets.push_back("load.max_kPa=5.0");
    auto bm = build_model(Scene::load("", sets));
    Assembler A(bm->model);
    QuasiStaticRun run(A, bm->solver.quasi_static);
    double last = 0.0;
    run.run(bm->load, [&](const StateRecord& r, const Eigen::VectorXd&, const std::vector<double>&) { last = r.angle_deg; });
    return last;
  };
  const double a_n = angle_at_top("newton"), a_r = angle_at_top("relaxation");
  EXPECT_GT(a_n, 0.05);
  // rel_tol 1e-8 on both: agreement to 1e-3 of the angle is conservative.
  EXPECT_NEAR(a_r, a_n, 1e-3 * a_n);
}

// A stall with a positive-definite tangent is Newton running out of iterations, not a limit
// point: the error must say which key to raise instead of blaming the design. Two Newton
// iterations without chord steps to a zero tolerance fail at every increment size while the
// tangent of this barely loaded actuator stays positive definite.
TEST(PneuNetSolvers, StallWithoutLimitPointPointsToMaxIterations) {
  std::vector<std::string> sets = kSmall;
  sets.insert(sets.end(), {"solver.max_iterations=2", "load.max_kPa=5.0"});
  auto bm = build_model(Scene::load("", sets));
  Assembler A(bm->model);
  StaticOptions opt = bm->solver.quasi_static.newton;
  opt.rel_tol = 0.0;
  opt.abs_tol_N = 0.0;
  opt.chord_steps = 0;
  StaticSolver solver(A, opt);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(bm->model.num_dofs());
  std::vector<double> state;
  std::string msg;
  try {
    solver.advance(0.0, 5e3, 0.0, 0.0, state, u);
  } catch (const PhysicsError& e) {
    msg = e.what();
  }
  EXPECT_NE(msg.find("static continuation stalled"), std::string::npos) << msg;
  EXPECT_NE(msg.find("no limit point detected"), std::string::npos) << msg;
  EXPECT_NE(msg.find("solver.max_iterations = 2"), std::string::npos) << msg;
}

// Issue 30 item 6: at a limit point the hint recommends only what works. It suggested explicit
// dynamics "beyond it", which on the same actuator runs away into an inverted element (past a limit
// point under pressure there is no equilibrium near the last one). Driven far past its ballooning
// pressure, the small actuator stalls with a tangent that is not positive definite.
TEST(PneuNetSolvers, ALimitPointHintRecommendsOnlyWhatWorks) {
  auto bm = build_model(Scene::load("", kSmall));
  Assembler A(bm->model);
  StaticSolver solver(A, bm->solver.quasi_static.newton);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(bm->model.num_dofs());
  std::vector<double> state = A.initial_state();
  std::string msg;
  try {
    solver.advance(0.0, 400e3, 0.0, 0.0, state, u);
  } catch (const PhysicsError& e) {
    msg = e.what();
  }
  ASSERT_NE(msg.find("limit point"), std::string::npos) << msg;
  EXPECT_EQ(msg.find("solver.mode = \"explicit\""), std::string::npos) << msg;
  EXPECT_NE(msg.find("load.max_kPa"), std::string::npos) << msg;
  EXPECT_NE(msg.find("stiffer"), std::string::npos) << msg;
}

// Stiff-layer elimination (StaticSolver): the 6.5 GPa fabric makes plain Newton wander on a
// bending actuator, and with 5 kPa increments a wandering iterate can land on another equilibrium
// branch. The reference path is plain Newton (elimination off) in 1 kPa increments, which is small
// enough to follow the branch (0.25 kPa gives the same angles to 1e-7). The defaults (elimination
// on, 5 kPa increments) must stay on that path at every level.
struct PathRun {
  std::vector<double> angles_deg;
  StaticStats stats;
};

PathRun run_path(const std::vector<std::string>& sets, double top_kPa, int relaxation_steps,
                 double max_increment_Pa, const std::function<void(StaticOptions&)>& tweak = nullptr) {
  auto bm = build_model(Scene::load("", sets));
  Assembler A(bm->model);
  StaticOptions opt = bm->solver.quasi_static.newton;
  opt.stiff_relaxation_steps = relaxation_steps;
  opt.max_increment_Pa = max_increment_Pa;
  if (tweak) tweak(opt);
  StaticSolver solver(A, opt);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(bm->model.num_dofs());
  std::vector<double> state(A.state_size(), 0.0);
  PathRun out;
  for (double p = 5.0; p <= top_kPa + 1e-9; p += 5.0) {
    solver.advance((p - 5.0) * 1e3, p * 1e3, 0.0, 0.0, state, u);
    out.angles_deg.push_back(bending_angle(bm->model, u).angle_deg);
  }
  out.stats = solver.stats();
  return out;
}

TEST(StiffLayerElimination, FollowsTheLoadPathOfSmallIncrements) {
  const std::vector<std::string> sets = {"geometry.chambers=5", "mesh.h_mm=6.0"};
  const PathRun ref = run_path(sets, 40.0, 0, 1e3);
  const PathRun on = run_path(sets, 40.0, 3, 5e3);
  ASSERT_EQ(on.angles_deg.size(), ref.angles_deg.size());
  for (size_t i = 0; i < ref.angles_deg.size(); ++i) {
    std::printf("  %4.0f kPa: reference %.9f deg, defaults %.9f deg\n", 5.0 * (i + 1), ref.angles_deg[i],
                on.angles_deg[i]);
    // Both converge to rel_tol 1e-8 on the residual: the same equilibrium agrees to ~1e-8 of the
    // angle; another branch differs by ~1e-2 (7.00 vs 7.06 deg at 35 kPa). 1e-6 separates the two.
    EXPECT_NEAR(on.angles_deg[i], ref.angles_deg[i], 1e-6 * std::abs(ref.angles_deg[i])) << 5.0 * (i + 1) << " kPa";
  }
  EXPECT_GT(on.stats.stiff_relaxations, 0);
  std::printf("  Newton iterations: reference %ld, defaults %ld\n", ref.stats.iterations,
              on.stats.iterations);
}

// Globalisation of Newton (StaticSolver class comment): steps with the last positive-definite
// factor when the tangent is not positive definite, and an Armijo line search on the potential
// energy. The potential must be the one whose gradient is the residual, or the line search would
// reject good steps; central differences along a generic direction check it at a deformed state
// with pressure and gravity.
TEST(Globalisation, PotentialGradientIsTheResidual) {
  // A heavy rig (10 g) so that the weight's work is a sizeable part of the potential.
  std::vector<std::string> sets = kSmall;
  sets.push_back("gravity.g_m_s2=[0.0, 30.0, -98.1]");
  auto bm = build_model(Scene::load("", sets));
  Assembler A(bm->model);
  StaticSolver solver(A, bm->solver.quasi_static.newton);
  ASSERT_TRUE(solver.has_potential());
  Eigen::VectorXd u_eq = Eigen::VectorXd::Zero(bm->model.num_dofs());
  std::vector<double> state;
  const double p = 8e3;
  solver.advance(0.0, p, 0.0, 0.0, state, u_eq);
  // Direction: the deformation itself (bending and sagging, a soft mode), from a state 5 % beyond
  // the equilibrium. There R . d is small next to each of its parts (internal work, pressure work
  // p dV, weight), so dropping or mis-signing any one of them in Pi would be an O(1) error.
  const Eigen::VectorXd d = u_eq, u = 1.05 * u_eq;
  const double h = 1e-4;
  double Pp = 0.0, Pm = 0.0;
  const Eigen::VectorXd R = solver.residual(p, {}, state, state, u);
  solver.residual(p, {}, state, state, u + h * d, &Pp);
  solver.residual(p, {}, state, state, u - h * d, &Pm);
  Eigen::VectorXd fg = Eigen::VectorXd::Zero(u.size()), fp = Eigen::VectorXd::Zero(u.size());
  A.add_gravity(fg);
  A.add_pressure(u, p, fp, nullptr);
  const double fd = (Pp - Pm) / (2.0 * h), exact = R.dot(d);
  std::printf("  dPi/dt: central difference %.9e, R.d %.9e (weight term %.3e, pressure term %.3e)\n", fd, exact,
              fg.dot(d), fp.dot(d));
  ASSERT_GT(std::abs(exact), 0.0);
  ASSERT_GT(std::abs(fg.dot(d)), 0.1 * std::abs(exact));  // the weight is not negligible here
  // Central difference error O(h^2) ~1e-8 relative; round-off of Pi ~1e-16 |Pi| / h. 1e-5 leaves
  // room for both and is far below the size of any one term.
  EXPECT_NEAR(fd, exact, 1e-5 * std::abs(exact));
}

// The energy line search needs a conservative load and no material history; otherwise the solver
// must fall back to the derivative-only search rather than use a wrong "energy".
TEST(Globalisation, NoPotentialForAnOpenCavityOrMaterialHistory) {
  using namespace testing;
  Model open = single_part_model(box(0.01, 0.01, 0.01, 2, 2, 2, ElementType::Tet10), ecoflex());
  fix(open, nodes_on_plane(open.mesh, 2, 0.0), {true, true, true});
  // Pressure on the top face alone: an open surface, whose load is not p times a volume gradient.
  open.pressure_faces = faces_where(open.mesh, [](const Eigen::Vector3d& x) { return x.z() > 0.01 - 1e-12; });
  ASSERT_FALSE(open.pressure_faces.empty());
  const Assembler A_open(open);
  EXPECT_FALSE(StaticSolver(A_open).has_potential());

  // The built-in actuator (a closed cavity, closed by the symmetry plane in the half model) has one...
  auto bm = build_model(Scene::load("", kSmall));
  const Assembler A(bm->model);
  EXPECT_TRUE(StaticSolver(A).has_potential());
  // ...but not with a history-dependent silicone.
  std::vector<std::string> sets = kSmall;
  sets.push_back("materials.silicone.mullins.enabled=true");
  auto bm_h = build_model(Scene::load("", sets));
  const Assembler A_h(bm_h->model);
  EXPECT_FALSE(StaticSolver(A_h).has_potential());
}

// Same equilibria as the previous strategy (diagonal shift, derivative-only search) at every level
// up to 40 kPa on the 5-chamber actuator, with fewer factorisations (the point of the change;
// BENCHMARKS.md section 3 has the default actuator's numbers).
TEST(Globalisation, LastFactorAndEnergySearchGiveTheSameEquilibriaWithFewerFactorisations) {
  const std::vector<std::string> sets = {"geometry.chambers=5", "mesh.h_mm=6.0"};
  const PathRun old = run_path(sets, 40.0, 3, 5e3, [](StaticOptions& o) {
    o.indefinite = StaticOptions::Indefinite::Shift;
    o.energy_line_search = false;
  });
  const PathRun now = run_path(sets, 40.0, 3, 5e3);
  ASSERT_EQ(now.angles_deg.size(), old.angles_deg.size());
  for (size_t i = 0; i < old.angles_deg.size(); ++i)
    // Both converge to rel_tol 1e-8 (see FollowsTheLoadPathOfSmallIncrements for the 1e-6 bound).
    EXPECT_NEAR(now.angles_deg[i], old.angles_deg[i], 1e-6 * std::abs(old.angles_deg[i])) << 5.0 * (i + 1) << " kPa";
  std::printf("  factorisations: shift %ld, last factor %ld (%ld last-factor steps, %ld energy cuts); iterations %ld vs %ld\n",
              old.stats.factorizations, now.stats.factorizations, now.stats.last_factor_steps, now.stats.energy_cuts,
              old.stats.iterations, now.stats.iterations);
  EXPECT_LT(now.stats.factorizations, old.stats.factorizations);
  EXPECT_GT(now.stats.energy_cuts, 0);
}

// Newton-Krylov on pressure ramps (StaticOptions::krylov_on_ramps, StaticSolver::linear_step): CG
// preconditioned by the factor of an earlier tangent replaces factorisations on the load increments,
// with give-ups. The Newton residual test is unchanged, so every equilibrium must be the one plain
// Newton (a factorisation every iteration) finds, within the solver tolerance: rel_tol 1e-8 on the
// residual, ~1e-8 of the angle (another branch differs by ~1e-2, FollowsTheLoadPathOfSmallIncrements).
TEST(NewtonKrylovOnRamps, SameEquilibriaAsPlainNewtonWithFewerFactorisations) {
  const std::vector<std::string> sets = {"geometry.chambers=5", "mesh.h_mm=6.0"};
  const PathRun plain = run_path(sets, 40.0, 3, 5e3);
  const PathRun krylov = run_path(sets, 40.0, 3, 5e3, [](StaticOptions& o) { o.krylov_on_ramps = true; });
  ASSERT_EQ(krylov.angles_deg.size(), plain.angles_deg.size());
  for (size_t i = 0; i < plain.angles_deg.size(); ++i) {
    std::printf("  %4.0f kPa: plain Newton %.9f deg, Newton-Krylov %.9f deg\n", 5.0 * (i + 1), plain.angles_deg[i],
                krylov.angles_deg[i]);
    EXPECT_NEAR(krylov.angles_deg[i], plain.angles_deg[i], 1e-6 * std::abs(plain.angles_deg[i])) << 5.0 * (i + 1) << " kPa";
  }
  const StaticStats &a = plain.stats, &b = krylov.stats;
  std::printf("  factorisations %ld -> %ld, Newton iterations %ld -> %ld, Krylov steps %ld (%ld CG iterations), "
              "give-ups %ld, forced by contraction %ld, indefinite found by CG %ld\n",
              a.factorizations, b.factorizations, a.iterations, b.iterations, b.krylov_steps, b.krylov_iterations,
              b.krylov_give_ups, b.contraction_refactors, b.indefinite_by_cg);
  EXPECT_EQ(a.krylov_iterations, 0);  // off: the ramps factorise every iteration, as before
  EXPECT_GT(b.krylov_steps, 0);
  EXPECT_LT(b.factorizations, a.factorizations);
}

// The give-up: a solver whose stored factor belongs to a far-away state (the 5-chamber actuator bent
// at 40 kPa) is sent back to the unloaded actuator and ramped to 10 kPa; and one whose CG can never
// reach its tolerance (one CG iteration allowed, tolerance 1e-14). Both must converge to the
// equilibria of a fresh plain-Newton solver, and the second must have abandoned every CG attempt
// for a factorisation.
TEST(NewtonKrylovOnRamps, GiveUpRefactorisesWhenTheOldFactorIsUseless) {
  const std::vector<std::string> sets = {"geometry.chambers=5", "mesh.h_mm=6.0"};
  auto bm = build_model(Scene::load("", sets));
  Assembler A(bm->model);
  const int n = bm->model.num_dofs();
  auto climb = [&](StaticSolver& solver, double top_kPa) {
    Eigen::VectorXd u = Eigen::VectorXd::Zero(n);
    std::vector<double> state(A.state_size(), 0.0);
    std::vector<double> angles;
    for (double p = 5.0; p <= top_kPa + 1e-9; p += 5.0) {
      solver.advance((p - 5.0) * 1e3, p * 1e3, 0.0, 0.0, state, u);
      angles.push_back(bending_angle(bm->model, u).angle_deg);
    }
    return angles;
  };
  StaticSolver plain(A, bm->solver.quasi_static.newton);
  const std::vector<double> ref = climb(plain, 10.0);

  StaticOptions o = bm->solver.quasi_static.newton;
  o.krylov_on_ramps = true;
  StaticSolver far(A, o);
  climb(far, 40.0);  // leaves the factor of a tangent at 40 kPa
  StaticSolver::Path empty;
  far.set_path(empty);  // no predictor from the 40 kPa path
  const StaticStats before = far.stats();
  const std::vector<double> back = climb(far, 10.0);
  StaticOptions hopeless = o;
  hopeless.krylov_max_iterations = 1;
  hopeless.krylov_rel_tol = 1e-14;
  StaticSolver never(A, hopeless);
  const std::vector<double> none = climb(never, 10.0);
  ASSERT_EQ(back.size(), ref.size());
  ASSERT_EQ(none.size(), ref.size());
  for (size_t i = 0; i < ref.size(); ++i) {
    std::printf("  %4.0f kPa: fresh plain Newton %.9f deg, after 40 kPa %.9f deg, CG never converging %.9f deg\n",
                5.0 * (i + 1), ref[i], back[i], none[i]);
    EXPECT_NEAR(back[i], ref[i], 1e-6 * std::abs(ref[i]));
    EXPECT_NEAR(none[i], ref[i], 1e-6 * std::abs(ref[i]));
  }
  const StaticStats& s = far.stats();
  std::printf("  after 40 kPa: %ld factorisations, %ld Krylov steps, %ld give-ups, %ld forced by contraction\n",
              s.factorizations - before.factorizations, s.krylov_steps - before.krylov_steps,
              s.krylov_give_ups - before.krylov_give_ups, s.contraction_refactors - before.contraction_refactors);
  const StaticStats& t = never.stats();
  std::printf("  CG never converging: %ld factorisations (plain %ld), %ld give-ups, %ld Krylov steps\n", t.factorizations,
              plain.stats().factorizations, t.krylov_give_ups, t.krylov_steps);
  EXPECT_EQ(t.krylov_steps, 0);
  EXPECT_GT(t.krylov_give_ups, 0);
}

}  // namespace
}  // namespace pneufem
