// engine/linear_solver.h: the CHOLMOD wrapper's contract with Newton — a solve to rounding, only the
// lower triangle read, false (not an abort or a garbage factor) for a matrix that is not positive
// definite, and a later factorisation of the same pattern (Newton's regularised retry) succeeding.
#include "engine/factorisation_threads.h"
#include "engine/linear_solver.h"

#include <cmath>
#include <cstring>
#include <stdexcept>
#include <vector>

#include <gtest/gtest.h>

// OpenBLAS's own setter, weak as in engine/linear_solver.cpp (null under another BLAS).
extern "C" void openblas_set_num_threads(int) __attribute__((weak));

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

/// A 3-D grid of n^3 nodes, 3 unknowns each, coupled to its 26 neighbours (the pattern of a
/// hexahedral mesh's stiffness): supernodes big enough that CHOLMOD calls dense BLAS kernels.
SparseMatrix grid_stiffness(int n) {
  std::vector<Eigen::Triplet<double>> t;
  auto node = [n](int i, int j, int k) { return (k * n + j) * n + i; };
  for (int k = 0; k < n; ++k)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i)
        for (int dk = -1; dk <= 1; ++dk)
          for (int dj = -1; dj <= 1; ++dj)
            for (int di = -1; di <= 1; ++di) {
              const int ii = i + di, jj = j + dj, kk = k + dk;
              if (ii < 0 || jj < 0 || kk < 0 || ii >= n || jj >= n || kk >= n) continue;
              const int a = node(i, j, k), b = node(ii, jj, kk);
              for (int p = 0; p < 3; ++p)
                for (int q = 0; q < 3; ++q) {
                  const int r = 3 * b + q, c = 3 * a + p;
                  // Diagonally dominant, entries of no special form (rounding differs with the order of sums).
                  t.emplace_back(r, c, r == c ? 200.0 : 0.5 * std::sin(0.37 * r + 0.61 * c) + 0.1 * std::cos(0.11 * (r + c)));
                }
            }
  SparseMatrix K(3 * n * n * n, 3 * n * n * n);
  K.setFromTriplets(t.begin(), t.end());
  return K;
}

/// The solution of K x = 1 with `factor_threads` BLAS threads in the factorisation, after the
/// process's BLAS was set to `outside_threads` (as --threads, numpy or OPENBLAS_NUM_THREADS might).
Eigen::VectorXd solve_with_blas_threads(const SparseMatrix& K, int factor_threads, int outside_threads) {
  set_factorisation_blas_threads(factor_threads);
  openblas_set_num_threads(outside_threads);
  LinearSolver solver;
  EXPECT_TRUE(solver.factorize(K));
  const Eigen::VectorXd x = solver.solve(Eigen::VectorXd::Ones(K.rows()));
  set_factorisation_blas_threads(1);
  return x;
}

bool same_bits(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), sizeof(double) * a.size()) == 0;
}

TEST(LinearSolver, TheFactorsBitsDependOnTheFixedBlasThreadsNotOnTheProcesssSetting) {
  if (!openblas_set_num_threads) GTEST_SKIP() << "the BLAS is not OpenBLAS: no thread count to fix";
  const SparseMatrix K = grid_stiffness(8);  // 1 536 unknowns
  const Eigen::VectorXd one = solve_with_blas_threads(K, 1, 1);
  // The premise: OpenBLAS's partition of its kernels changes the factor's rounding, so a count
  // that followed --threads would change results.
  EXPECT_FALSE(same_bits(one, solve_with_blas_threads(K, 2, 1)));
  // The fixed count wins over whatever the process's BLAS was set to.
  EXPECT_TRUE(same_bits(one, solve_with_blas_threads(K, 1, 2)));
  EXPECT_TRUE(same_bits(one, solve_with_blas_threads(K, 1, 4)));
  const Eigen::VectorXd two = solve_with_blas_threads(K, 2, 2);
  EXPECT_TRUE(same_bits(two, solve_with_blas_threads(K, 2, 1)));
  EXPECT_EQ(factorisation_blas_threads(), 1);
}

TEST(LinearSolver, FactorisationBlasThreadsBelowOneAreRefused) {
  EXPECT_THROW(set_factorisation_blas_threads(0), std::invalid_argument);
  EXPECT_EQ(factorisation_blas_threads(), 1);
}

}  // namespace
