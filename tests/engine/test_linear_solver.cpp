// engine/linear_solver.h: the CHOLMOD wrapper's contract with Newton — a solve to rounding, only the
// lower triangle read, false (not an abort or a garbage factor) for a matrix that is not positive
// definite, and a later factorisation of the same pattern (Newton's regularised retry) succeeding.
#include "engine/linear_solver.h"

#include <vector>

#include <gtest/gtest.h>

namespace {

using namespace pneufem;

/// The 1-D Laplacian (2 on the diagonal, -1 beside it) plus `shift` on the diagonal; `upper` is
/// written into the upper triangle (the symmetric value is -1).
SparseMatrix tridiagonal(int n, double shift, double upper = -1.0) {
  std::vector<Eigen::Triplet<double>> t;
  for (int i = 0; i < n; ++i) {
    t.emplace_back(i, i, 2.0 + shift);
    if (i + 1 < n) t.emplace_back(i + 1, i, -1.0), t.emplace_back(i, i + 1, upper);
  }
  SparseMatrix K(n, n);
  K.setFromTriplets(t.begin(), t.end());
  return K;
}

TEST(LinearSolver, SolvesASymmetricPositiveDefiniteSystemToRounding) {
  const SparseMatrix K = tridiagonal(50, 0.0);
  Eigen::VectorXd x_true(50);
  for (int i = 0; i < 50; ++i) x_true[i] = 1.0 + 0.1 * i * i;
  const Eigen::VectorXd b = K * x_true;
  LinearSolver solver;
  EXPECT_FALSE(solver.has_factor());
  ASSERT_TRUE(solver.factorize(K));
  EXPECT_TRUE(solver.has_factor());
  EXPECT_LT((solver.solve(b) - x_true).norm(), 1e-9 * x_true.norm());
}

TEST(LinearSolver, ReadsOnlyTheLowerTriangle) {
  const SparseMatrix symmetric = tridiagonal(20, 0.5);
  const SparseMatrix garbage_above = tridiagonal(20, 0.5, 7.0);  // the upper triangle is not the lower's mirror
  const Eigen::VectorXd b = Eigen::VectorXd::LinSpaced(20, -1.0, 1.0);
  LinearSolver a, c;
  ASSERT_TRUE(a.factorize(symmetric));
  ASSERT_TRUE(c.factorize(garbage_above));
  EXPECT_EQ(a.solve(b), c.solve(b));
}

TEST(LinearSolver, NotPositiveDefiniteIsFalseAndTheSamePatternFactorisesAfter) {
  // A shift of -3 puts eigenvalues (2 - 2 cos(k pi / (n + 1)) - 3) below zero; +1 is positive definite.
  const SparseMatrix indefinite = tridiagonal(30, -3.0);
  const SparseMatrix shifted = tridiagonal(30, 1.0);
  LinearSolver solver;
  EXPECT_FALSE(solver.factorize(indefinite));
  EXPECT_FALSE(solver.has_factor());
  ASSERT_TRUE(solver.factorize(shifted));  // Newton's regularised retry: the symbolic analysis is reused
  const Eigen::VectorXd b = Eigen::VectorXd::Ones(30);
  EXPECT_LT((shifted * solver.solve(b) - b).norm(), 1e-12 * b.norm());
  EXPECT_EQ(solver.factorizations(), 2);  // failed attempts count too
  solver.forget_factor();
  EXPECT_FALSE(solver.has_factor());
  EXPECT_EQ(solver.factorizations(), 2);
}

}  // namespace
