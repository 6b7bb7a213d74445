// engine/relaxation.h: dynamic relaxation reaches the equilibrium Newton's method reaches, on a
// cantilever at large deflection.
#include "engine/relaxation.h"

#include <cstdio>

#include <gtest/gtest.h>

#include "core/errors.h"
#include "engine/static_solver.h"
#include "tests/engine/cantilever.h"
#include "tests/engine/test_meshes.h"

namespace pneufem {
namespace {

using namespace testing;

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

}  // namespace
}  // namespace pneufem
