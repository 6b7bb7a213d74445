// System tests of the solvers against analytic solutions (STYLE practice 6): finite-strain patch
// test, thick-walled cylinder inflation by follower pressure vs the incompressible solution,
// cantilever vs beam theory, observed convergence order, dynamic relaxation = Newton, explicit
// energy balance and static limit, and the unstable-step error.
#include <cmath>
#include <numbers>
#include <random>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include "engine/explicit.h"
#include "engine/relaxation.h"
#include "engine/static_solver.h"
#include "core/errors.h"
#include "tests/engine/test_meshes.h"
#include "tests/engine/thick_cylinder.h"

// OpenBLAS's own setter, weak as in engine/linear_solver.cpp (null under another BLAS).
extern "C" void openblas_set_num_threads(int) __attribute__((weak));

namespace pneufem {
namespace {

using namespace testing;

// ---------------------------------------------------------------- patch test
TEST(PatchTest, HomogeneousFiniteDeformationIsReproducedExactly) {
  for (ElementType type : {ElementType::Tet4, ElementType::Tet10}) {
    // Distorted (curved for Tet10) mesh of the unit cube: the bump vanishes on the boundary.
    Mesh mesh = mapped_grid(3, 3, 3, type, [](const Eigen::Vector3d& s) {
      const double b = 0.08 * std::sin(std::numbers::pi * s.x()) * std::sin(std::numbers::pi * s.y()) *
                       std::sin(std::numbers::pi * s.z());
      return Eigen::Vector3d(s.x() + b, s.y() + 0.5 * b, s.z() - b);
    });
    Model model = single_part_model(mesh, ecoflex());
    Eigen::Matrix3d F0;
    F0 << 1.3, 0.2, 0.0, -0.1, 0.8, 0.15, 0.05, 0.0, 1.1;
    Eigen::VectorXd u_exact(model.num_dofs()), u = Eigen::VectorXd::Zero(model.num_dofs());
    for (int i = 0; i < model.mesh.num_nodes(); ++i) {
      const Eigen::Vector3d& X = model.mesh.X[i];
      u_exact.segment<3>(3 * i) = (F0 - Eigen::Matrix3d::Identity()) * X;
      const bool on_boundary = (X.array() < 1e-12).any() || (X.array() > 1 - 1e-12).any();
      if (on_boundary) fix(model, {i}, {true, true, true});
      // Prescribed dofs keep their initial value; interior nodes start from a perturbed guess
      // (starting them at zero would invert the boundary layer of elements).
      u.segment<3>(3 * i) = u_exact.segment<3>(3 * i) + (on_boundary ? 0.0 : 0.01) * Eigen::Vector3d(std::sin(7.0 * i), std::cos(3.0 * i), std::sin(5.0 * i));
    }
    Assembler A(model);
    StaticSolver solver(A, StaticOptions{.rel_tol = 1e-12});
    const NewtonReport r = solver.solve(0.0, {}, {}, {}, u);
    ASSERT_TRUE(r.converged) << r.failure;
    // A linear field lies in the element space and satisfies equilibrium exactly, so only the
    // solver tolerance (1e-12 relative) and round-off remain.
    EXPECT_LT((u - u_exact).lpNorm<Eigen::Infinity>(), 1e-9) << (type == ElementType::Tet4 ? "Tet4" : "Tet10");
  }
}

// ---------------------------------------------------------------- thick cylinder
struct CylinderResult {
  double a_fe, a_exact, h;
};
CylinderResult inflate_cylinder(int nr, int nt, double p, double K_over_mu) {
  const double A = 0.01, B = 0.02, H = 0.004;
  Mesh mesh = mapped_grid(nr, nt, 1, ElementType::Tet10, [=](const Eigen::Vector3d& s) {
    const double r = A + (B - A) * s.x(), t = 0.5 * std::numbers::pi * s.y();
    return Eigen::Vector3d(r * std::cos(t), r * std::sin(t), H * s.z());
  });
  Model model = single_part_model(mesh, ecoflex(K_over_mu));
  for (int i = 0; i < model.mesh.num_nodes(); ++i) {
    const Eigen::Vector3d& X = model.mesh.X[i];
    model.fixed[3 * i + 2] = 1;                         // plane strain
    if (std::abs(X.y()) < 1e-12) model.fixed[3 * i + 1] = 1;  // symmetry y = 0
    if (std::abs(X.x()) < 1e-12) model.fixed[3 * i + 0] = 1;  // symmetry x = 0
  }
  model.pressure_faces = faces_where(model.mesh, [=](const Eigen::Vector3d& X) {
    return std::abs(std::hypot(X.x(), X.y()) - A) < 1e-9;
  });
  Assembler asmb(model);
  StaticSolver solver(asmb, StaticOptions{.rel_tol = 1e-10, .max_increment_Pa = p / 4});
  std::vector<double> state = asmb.initial_state();
  Eigen::VectorXd u = Eigen::VectorXd::Zero(model.num_dofs());
  solver.advance(0.0, p, 0.0, 1.0, state, u);
  // Mean deformed radius of the inner-surface nodes.
  double sum = 0.0;
  int cnt = 0;
  for (int i = 0; i < model.mesh.num_nodes(); ++i) {
    const Eigen::Vector3d& X = model.mesh.X[i];
    if (std::abs(std::hypot(X.x(), X.y()) - A) < 1e-9) {
      const Eigen::Vector3d x = X + u.segment<3>(3 * i);
      sum += std::hypot(x.x(), x.y());
      ++cnt;
    }
  }
  return {sum / cnt, cylinder_inner_radius(p, A, B), (B - A) / nr};
}

TEST(CylinderInflation, MatchesIncompressibleAnalyticSolutionAtLargeStrain) {
  // p = 20 kPa opens the bore by ~40 % (hoop stretch 1.4) for Ecoflex 00-50.
  const double p = 2.0e4;
  const CylinderResult r = inflate_cylinder(4, 6, p, 1000.0);
  ASSERT_GT(r.a_exact / 0.01, 1.3);  // genuinely large strain
  // Discretisation (Tet10, 4 x 6 cells, curved-edge elements) and compressibility (K/mu = 1000:
  // relative volume change ~ p/K ~ 5e-4) each contribute < 0.3 % of the bore displacement.
  EXPECT_NEAR(r.a_fe, r.a_exact, 0.005 * (r.a_exact - 0.01)) << "a_fe=" << r.a_fe << " a_exact=" << r.a_exact;
}

TEST(CylinderInflation, ObservedConvergenceOrderOfTet10) {
  // Error in the bore displacement vs the analytic solution under uniform refinement. For Tet10
  // the displacement error converges at O(h^2) or better in the energy-norm sense and O(h^3)
  // pointwise for smooth solutions; we require an observed order >= 1.8 over two refinements.
  // K/mu = 1e4 keeps the compressibility error (~p/K ~ 5e-5 relative) below the finest mesh error.
  const double p = 1.5e4;
  std::vector<CylinderResult> res;
  for (int n : {1, 2, 4}) res.push_back(inflate_cylinder(n, 2 * n, p, 1e4));
  std::vector<double> err;
  for (const auto& r : res) err.push_back(std::abs(r.a_fe - r.a_exact) / (r.a_exact - 0.01));
  const double order1 = std::log(err[0] / err[1]) / std::log(2.0);
  const double order2 = std::log(err[1] / err[2]) / std::log(2.0);
  RecordProperty("errors", std::to_string(err[0]) + "," + std::to_string(err[1]) + "," + std::to_string(err[2]));
  std::printf("cylinder bore error: %.3e %.3e %.3e, observed orders %.2f %.2f\n", err[0], err[1], err[2], order1, order2);
  EXPECT_GT(order1, 1.8);
  EXPECT_GT(order2, 1.8);
  EXPECT_LT(err[2], 2e-3);
}

// ---------------------------------------------------------------- cantilever
struct Beam {
  Model model;
  double L = 0.1, b = 0.01, h = 0.01, E, nu, q;
};
Beam cantilever(int nx, int nyz, ElementType type) {
  Beam beam;
  const double mu = 1e6, K = 2.1667e6;  // nu = (3K - 2mu) / (2 (3K + mu)) = 0.3000
  beam.E = 9 * K * mu / (3 * K + mu);
  beam.nu = (3 * K - 2 * mu) / (2 * (3 * K + mu));
  beam.model = single_part_model(box(beam.L, beam.b, beam.h, nx, nyz, nyz, type), neo_hookean(mu, K), 1000.0);
  fix(beam.model, nodes_on_plane(beam.model.mesh, 0, 0.0), {true, true, true});
  beam.model.gravity_m_s2 = Eigen::Vector3d(0, 0, -0.5);  // tip deflection ~ 1e-4 L: linear regime
  beam.q = 1000.0 * 0.5 * beam.b * beam.h;                // N/m
  return beam;
}
double tip_deflection(const Model& model, const Eigen::VectorXd& u, double L) {
  double sum = 0;
  int n = 0;
  for (int i = 0; i < model.mesh.num_nodes(); ++i)
    if (std::abs(model.mesh.X[i].x() - L) < 1e-12) {
      sum += u[3 * i + 2];
      ++n;
    }
  return -sum / n;
}
double timoshenko_tip(const Beam& bm) {
  const double I = bm.b * std::pow(bm.h, 3) / 12, Ar = bm.b * bm.h, G = bm.E / (2 * (1 + bm.nu));
  const double kappa = 10 * (1 + bm.nu) / (12 + 11 * bm.nu);
  return bm.q * std::pow(bm.L, 4) / (8 * bm.E * I) + bm.q * bm.L * bm.L / (2 * kappa * G * Ar);
}

TEST(Cantilever, SmallDeflectionMatchesBeamTheory) {
  Beam bm = cantilever(20, 2, ElementType::Tet10);
  Assembler asmb(bm.model);
  StaticSolver solver(asmb, StaticOptions{.rel_tol = 1e-9});
  Eigen::VectorXd u = Eigen::VectorXd::Zero(bm.model.num_dofs());
  const NewtonReport rep = solver.solve(0.0, {}, {}, {}, u);
  ASSERT_TRUE(rep.converged) << rep.failure << " it=" << rep.iterations << " res=" << rep.residual_N << " ref=" << rep.reference_N;
  const double d = tip_deflection(bm.model, u, bm.L), d_beam = timoshenko_tip(bm);
  // L/h = 10: Timoshenko theory with a fully clamped 3-D root differs from the 3-D solution by
  // ~1 % (root warping restraint, anticlastic effects); Tet10 with 2 cells through the depth is
  // converged to < 1 % in bending. Allow 2.5 %.
  EXPECT_NEAR(d / d_beam, 1.0, 0.025) << "FE " << d << " beam " << d_beam;
}

// ---------------------------------------------------------------- dynamic relaxation
TEST(DynamicRelaxation, ConvergesToTheNewtonEquilibrium) {
  Beam bm = cantilever(10, 1, ElementType::Tet10);
  bm.model.gravity_m_s2 = Eigen::Vector3d(0, 0, -200.0);  // large deflection (~20 % of L)
  Assembler asmb(bm.model);
  Eigen::VectorXd u_newton = Eigen::VectorXd::Zero(bm.model.num_dofs());
  // Gravity is not ramped by the pressure path, so Newton must reach the 20 % deflection in one
  // increment from u = 0: allow more than the default 12 iterations (tuned for small pressure steps).
  StaticSolver solver(asmb, StaticOptions{.rel_tol = 1e-9, .max_iterations = 40});
  std::vector<double> st;
  solver.advance(0.0, 0.0, 0.0, 0.0, st, u_newton);
  Eigen::VectorXd u_dr = Eigen::VectorXd::Zero(bm.model.num_dofs());
  const RelaxationReport r = relax(asmb, 0.0, {}, {}, {}, u_dr, RelaxationOptions{.rel_tol = 1e-9});
  ASSERT_TRUE(r.converged) << r.iterations << " iterations, residual " << r.residual_N;
  std::printf("dynamic relaxation: %ld iterations, %ld kinetic peaks\n", r.iterations, r.kinetic_peaks);
  // Both satisfy ||R|| <= 1e-10 ||f||; the tangent's condition number (~1e4 here) bounds the
  // displacement difference by ~1e-6 of the displacement.
  ASSERT_GT(tip_deflection(bm.model, u_newton, bm.L), 0.01);
  EXPECT_LT((u_dr - u_newton).norm(), 1e-6 * u_newton.norm());
}

// ---------------------------------------------------------------- explicit dynamics
// First bending frequency of the cantilever (Euler-Bernoulli): omega_1 = 1.875^2 sqrt(EI / (rho A L^4)).
double omega1(const Beam& bm) {
  const double I = bm.b * std::pow(bm.h, 3) / 12;
  return 3.516 * std::sqrt(bm.E * I / (1000.0 * bm.b * bm.h * std::pow(bm.L, 4)));
}

TEST(Explicit, UndampedFreeVibrationConservesEnergyWithoutDrift) {
  // Release the beam from its static deflection under gravity (then switched off): free
  // vibration of the low modes. Central differences conserve a discrete energy that differs from
  // KE + IE (KE from averaged half-step velocities) by O((omega dt)^2) of each mode's energy; the
  // static shape also holds a little high-mode energy, for which that is larger: ~1e-3 observed.
  // We allow 3e-3 and require no secular drift (last period no worse than the first).
  Beam loaded = cantilever(10, 1, ElementType::Tet10);
  loaded.model.gravity_m_s2 = Eigen::Vector3d(0, 0, -20.0);
  Assembler asm_loaded(loaded.model);
  Eigen::VectorXd u0 = Eigen::VectorXd::Zero(loaded.model.num_dofs());
  ASSERT_TRUE(StaticSolver(asm_loaded).solve(0.0, {}, {}, {}, u0).converged);
  Beam bm = cantilever(10, 1, ElementType::Tet10);
  bm.model.gravity_m_s2.setZero();
  Assembler asmb(bm.model);
  ExplicitIntegrator ex(asmb, ExplicitOptions{});
  ex.u() = u0;
  double E0 = 0.0;
  asmb.internal(u0, {}, {}, {}, nullptr, nullptr, &E0);
  ASSERT_GT(E0, 0.0);
  const double periods = 3.0, T = 2 * std::numbers::pi / omega1(bm);
  double dev_first = 0.0, dev_last = 0.0, max_ke = 0.0;
  ex.run(periods * T, [](double) { return 0.0; }, 10, [&](double t, const Eigen::VectorXd&, const Eigen::VectorXd&) {
    const double dev = std::abs(ex.energy().kinetic_J + ex.energy().internal_J - E0) / E0;
    (t < T ? dev_first : dev_last) = std::max(t < T ? dev_first : dev_last, t < T ? dev : (t > (periods - 1) * T ? dev : 0.0));
    max_ke = std::max(max_ke, ex.energy().kinetic_J);
  });
  std::printf("energy deviation: first period %.3e, last period %.3e\n", dev_first, dev_last);
  EXPECT_GT(max_ke, 0.5 * E0);  // the energy really sloshes between kinetic and strain energy
  EXPECT_LT(dev_first, 3e-3);
  EXPECT_LT(dev_last, 1.2 * dev_first);  // no secular drift
}

TEST(Explicit, SuddenLoadEnergyBalanceAndDampedStaticLimit) {
  Beam bm = cantilever(10, 1, ElementType::Tet10);
  bm.model.gravity_m_s2 = Eigen::Vector3d(0, 0, -20.0);
  Assembler asmb(bm.model);
  Eigen::VectorXd u_static = Eigen::VectorXd::Zero(bm.model.num_dofs());
  ASSERT_TRUE(StaticSolver(asmb).solve(0.0, {}, {}, {}, u_static).converged);
  // Critical damping of the first mode, a = 2 omega_1; after 12/omega_1 the transient has
  // decayed by ~e^-12 (higher modes are over-damped and decay even faster in amplitude).
  const double w1 = omega1(bm);
  ExplicitIntegrator ex(asmb, ExplicitOptions{.damping_alpha_1_s = 2 * w1});
  ex.run(12.0 / w1, [](double) { return 0.0; }, 1000, nullptr);
  const double d = tip_deflection(bm.model, ex.u(), bm.L), ds = tip_deflection(bm.model, u_static, bm.L);
  EXPECT_NEAR(d, ds, 1e-3 * ds);
  EXPECT_GT(ex.energy().damping_J, 0.0);
  // The suddenly applied load excites high modes whose discrete energy differs from KE + IE by
  // O(1) of their (small) share; the global balance holds to a few percent.
  EXPECT_LT(ex.energy().relative_error(), 3e-2);
}

TEST(Explicit, StiffLayerMassScalingDoesNotChangeTheEquilibrium) {
  // A soft cantilever with a thin stiff bottom layer, the pneu-net's fabric in miniature
  // (E_layer / mu_soft ~ 1e4). The layer limits the explicit step; selective mass scaling raises
  // only its nodes' masses so the step becomes that of the soft material. Masses do not enter
  // equilibrium, so the damped run must settle on the Newton deflection: the issue asks < 0.5 %.
  const double L = 0.02, b = 0.006, h = 0.006, t = 0.0004;
  Mesh mesh = mapped_grid(6, 1, 3, ElementType::Tet10, [=](const Eigen::Vector3d& s) {
    // z: one layer of thickness t at the bottom, two soft layers above
    const double z = s.z() < 1.0 / 3.0 + 1e-12 ? 3.0 * s.z() * t : t + (s.z() - 1.0 / 3.0) * 1.5 * h;
    return Eigen::Vector3d(L * s.x(), b * s.y(), z);
  });
  Model model;
  model.mesh = mesh;
  model.parts.push_back(Part{"soft", neo_hookean(1e5, 1e6), 1000.0});
  model.parts.push_back(Part{"layer", std::make_shared<SaintVenantKirchhoff>(1e9, 0.2), 1000.0});
  model.element_part.resize(model.mesh.num_elements());
  for (int e = 0; e < model.mesh.num_elements(); ++e) {
    const int* n = model.mesh.element(e);
    double zc = 0;
    for (int a = 0; a < 4; ++a) zc += 0.25 * model.mesh.X[n[a]].z();
    model.element_part[e] = zc < t ? 1 : 0;
  }
  model.fixed.assign(3 * model.mesh.num_nodes(), 0);
  fix(model, nodes_on_plane(model.mesh, 0, 0.0), {true, true, true});
  model.gravity_m_s2 = Eigen::Vector3d(0, 0, -30.0);
  Assembler asmb(model);
  Eigen::VectorXd u_static = Eigen::VectorXd::Zero(model.num_dofs());
  ASSERT_TRUE(StaticSolver(asmb).solve(0.0, {}, {}, {}, u_static).converged);
  const double d_static = tip_deflection(model, u_static, L);
  ExplicitIntegrator probe(asmb, ExplicitOptions{});
  const double dt_layer = probe.estimate_stable_dt();
  // Step of the soft material alone: same mesh, soft everywhere.
  Model soft = model;
  soft.element_part.assign(soft.mesh.num_elements(), 0);
  Assembler asoft(soft);
  const double dt_soft = ExplicitIntegrator(asoft, ExplicitOptions{}).estimate_stable_dt();
  ASSERT_GT(dt_soft, 10.0 * dt_layer);  // the layer really does dictate the step
  ExplicitOptions opt{.target_dt_s = dt_soft, .adaptive_damping = true};  // critical damping of the moving mode
  ExplicitIntegrator ex(asmb, opt);
  // Adaptive damping makes the approach monotone; 0.1 s is ~10 time constants of the slowest mode.
  ex.run(0.1, [](double) { return 0.0; }, 1 << 30, nullptr);
  const double d = tip_deflection(model, ex.u(), L);
  std::printf("stiff layer: dt %.3g s -> %.3g s with %.0f %% added mass, %ld steps; tip %.6e vs static %.6e\n",
              dt_layer, ex.stats().dt_s, 100 * ex.stats().added_mass_kg / ex.stats().physical_mass_kg,
              ex.stats().steps, d, d_static);
  EXPECT_GE(ex.stats().dt_s, 0.99 * dt_soft);
  EXPECT_NEAR(d, d_static, 5e-3 * d_static);
}

TEST(Explicit, TooLargeStepStopsWithAClearError) {
  Beam bm = cantilever(6, 1, ElementType::Tet10);
  Assembler asmb(bm.model);
  ExplicitIntegrator probe(asmb, ExplicitOptions{});
  const double dt_stable = probe.estimate_stable_dt();
  ExplicitIntegrator ex(asmb, ExplicitOptions{.fixed_dt_s = 4.0 * dt_stable});
  try {
    ex.run(2000 * dt_stable, [](double) { return 0.0; }, 1, nullptr);
    FAIL() << "expected the instability to be detected";
  } catch (const PhysicsError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("unstable"), std::string::npos) << msg;
    EXPECT_NE(msg.find("t = "), std::string::npos) << msg;
    EXPECT_NE(msg.find("Hint"), std::string::npos) << msg;
    EXPECT_GT(e.time_s(), 0.0);
  }
}

TEST(Explicit, SelectiveMassScalingReachesTheTargetStepAndReportsAddedMass) {
  Beam bm = cantilever(6, 1, ElementType::Tet10);
  Assembler asmb(bm.model);
  ExplicitIntegrator probe(asmb, ExplicitOptions{});
  const double dt0 = probe.estimate_stable_dt();
  ExplicitIntegrator ex(asmb, ExplicitOptions{.target_dt_s = 5 * dt0});
  const double dt = ex.estimate_stable_dt();
  EXPECT_GE(dt, 5 * dt0 * (1 - 1e-12));
  EXPECT_GT(ex.stats().added_mass_kg, 0.0);
  EXPECT_NEAR(ex.nodal_mass().sum(), ex.stats().physical_mass_kg + ex.stats().added_mass_kg, 1e-12);
}

// The BLAS inside CHOLMOD is set to the TBB thread count before each solve, as a BLAS that
// followed --threads (or OPENBLAS_NUM_THREADS, or numpy in the same process) would be: the factor's
// bits depend on the BLAS's count (tests/engine/test_linear_solver.cpp), so the solve must fix its own.
TEST(Determinism, QuasiStaticSolveIsBitIdenticalFor1And2ThreadsWhateverTheBlasIsSetTo) {
  auto run = [](int threads) {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, threads);
    if (openblas_set_num_threads) openblas_set_num_threads(threads);
    Beam bm = cantilever(8, 2, ElementType::Tet10);
    bm.model.gravity_m_s2 = Eigen::Vector3d(0, 0, -100.0);
    Assembler asmb(bm.model);
    StaticSolver solver(asmb);
    Eigen::VectorXd u = Eigen::VectorXd::Zero(bm.model.num_dofs());
    solver.solve(0.0, {}, {}, {}, u);
    return u;
  };
  const Eigen::VectorXd u1 = run(1), u2 = run(2);
  EXPECT_TRUE((u1.array() == u2.array()).all());
}

}  // namespace
}  // namespace pneufem
