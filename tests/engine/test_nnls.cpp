// engine/nnls.h: Lawson-Hanson non-negative least squares (the reduced model's element sampling)
// against its truths: a case solved by hand, the exact optimum of an enumeration of every active
// set, the recovery of a sparse non-negative solution, and the early stop at rel_tol; and its
// normal-equations form (nnls_normal) against the QR form on the same problems.
#include "engine/nnls.h"

#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <Eigen/QR>
#include <gtest/gtest.h>

namespace pneufem {
namespace {

Eigen::MatrixXd random_matrix(int rows, int cols, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::MatrixXd A(rows, cols);
  for (int j = 0; j < cols; ++j)
    for (int i = 0; i < rows; ++i) A(i, j) = u(rng);
  return A;
}

TEST(Nnls, ACaseSolvedByHand) {
  // A = I: x_j = max(b_j, 0), and the residual is the norm of the negative part of b.
  const Eigen::MatrixXd A = Eigen::MatrixXd::Identity(3, 3);
  const Eigen::Vector3d b(1.0, -2.0, 3.0);
  const NnlsResult r = nnls(A, b, 0.0);
  EXPECT_TRUE(r.converged);
  EXPECT_NEAR(r.x[0], 1.0, 1e-14);
  EXPECT_EQ(r.x[1], 0.0);
  EXPECT_NEAR(r.x[2], 3.0, 1e-14);
  EXPECT_NEAR(r.residual, 2.0, 1e-14);
  EXPECT_EQ(r.iterations, 2);  // two columns brought in
}

TEST(Nnls, TheOptimumOfEveryActiveSet) {
  // 25 x 9: the NNLS optimum is the least-squares solution on one set of columns with all weights
  // > 0; enumerating the 2^9 sets gives the smallest such residual, which nnls must reach.
  const int m = 25, n = 9;
  const Eigen::MatrixXd A = random_matrix(m, n, 7);
  std::mt19937 rng(8);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  Eigen::VectorXd b(m);
  for (int i = 0; i < m; ++i) b[i] = u(rng);

  double best = b.norm();
  for (int mask = 1; mask < (1 << n); ++mask) {
    std::vector<int> cols;
    for (int j = 0; j < n; ++j)
      if (mask & (1 << j)) cols.push_back(j);
    Eigen::MatrixXd As(m, static_cast<int>(cols.size()));
    for (std::size_t c = 0; c < cols.size(); ++c) As.col(static_cast<int>(c)) = A.col(cols[c]);
    const Eigen::VectorXd z = As.colPivHouseholderQr().solve(b);
    if (z.minCoeff() > 0.0) best = std::min(best, (As * z - b).norm());
  }

  const NnlsResult r = nnls(A, b, 0.0);
  EXPECT_TRUE(r.converged);
  EXPECT_GE(r.x.minCoeff(), 0.0);
  // Both are QR solutions of the same subproblem: agreement to rounding of O(1) numbers.
  EXPECT_NEAR(r.residual, best, 1e-12);
  EXPECT_NEAR(r.residual, (A * r.x - b).norm(), 1e-12);
  // Kuhn-Tucker: the gradient A^T (b - A x) is zero on the weights > 0 and <= 0 on the others.
  const Eigen::VectorXd w = A.transpose() * (b - A * r.x);
  for (int j = 0; j < n; ++j) {
    if (r.x[j] > 0.0)
      EXPECT_NEAR(w[j], 0.0, 1e-11) << j;  // nnls's own threshold is 1e-12 max|A| ||b||
    else
      EXPECT_LE(w[j], 1e-11) << j;
  }
}

TEST(Nnls, RecoversASparseNonNegativeSolution) {
  // b = A x* with x* >= 0 on three of eight columns of a full-rank 20 x 8 A: x* is the unique
  // optimum (residual 0), found to rounding (the QR of a well-conditioned 20 x 3 system).
  const Eigen::MatrixXd A = random_matrix(20, 8, 11);
  Eigen::VectorXd xs = Eigen::VectorXd::Zero(8);
  xs[1] = 2.0;
  xs[3] = 0.5;
  xs[6] = 1.0;
  const NnlsResult r = nnls(A, A * xs, 0.0);
  EXPECT_TRUE(r.converged);
  EXPECT_LT((r.x - xs).norm(), 1e-12);
  EXPECT_LT(r.residual, 1e-12);
}

TEST(Nnls, StopsEarlyAtTheRelativeTolerance) {
  const Eigen::MatrixXd A = random_matrix(40, 30, 3);
  Eigen::VectorXd xs = Eigen::VectorXd::Zero(30);
  for (int j = 0; j < 30; j += 2) xs[j] = 1.0 + 0.1 * j;
  const Eigen::VectorXd b = A * xs;
  const NnlsResult full = nnls(A, b, 0.0);
  const NnlsResult early = nnls(A, b, 0.3);
  EXPECT_TRUE(early.converged);
  EXPECT_LE(early.residual, 0.3 * b.norm());
  EXPECT_LT(early.iterations, full.iterations);
  EXPECT_LT((early.x.array() > 0.0).count(), (full.x.array() > 0.0).count());  // fewer sampled elements

  const NnlsResult one = nnls(A, b, 0.0, 1);  // max_iterations = 1: one column, not converged
  EXPECT_EQ(one.iterations, 1);
  EXPECT_EQ((one.x.array() > 0.0).count(), 1);
  EXPECT_FALSE(one.converged);
}

TEST(Nnls, AZeroRightHandSideIsSolvedByZero) {
  const NnlsResult r = nnls(random_matrix(5, 4, 1), Eigen::VectorXd::Zero(5), 0.0);
  EXPECT_TRUE(r.converged);
  EXPECT_EQ(r.x, Eigen::VectorXd::Zero(4));
  EXPECT_EQ(r.iterations, 0);
}

// Moved from test_rom.cpp (the reduced model's hyper-reduction uses NNLS).

/// KKT conditions of min |Ax - b| s.t. x >= 0: x >= 0, w = A^T (b - A x) <= 0 where x = 0 and
/// w = 0 where x > 0 (tolerance: round-off of the QR subproblems, ~1e-10 of |A^T b|).
TEST(Nnls, ReachesTheKktPointOfRandomProblems) {
  std::mt19937_64 rng(5);
  std::normal_distribution<double> N;
  for (int trial = 0; trial < 40; ++trial) {
    const int m = 6 + trial % 13, n = 3 + (trial * 7) % 17;
    Eigen::MatrixXd A(m, n);
    Eigen::VectorXd b(m);
    for (int i = 0; i < m; ++i) {
      b[i] = N(rng);
      for (int j = 0; j < n; ++j) A(i, j) = N(rng);
    }
    const NnlsResult r = nnls(A, b, 1e-14);
    ASSERT_EQ(r.x.size(), n);
    const Eigen::VectorXd w = A.transpose() * (b - A * r.x);
    const double scale = (A.transpose() * b).norm() + 1.0;
    for (int j = 0; j < n; ++j) {
      EXPECT_GE(r.x[j], 0.0);
      if (r.x[j] > 0.0)
        EXPECT_NEAR(w[j], 0.0, 1e-10 * scale) << "trial " << trial << " column " << j;
      else
        EXPECT_LE(w[j], 1e-10 * scale) << "trial " << trial << " column " << j;
    }
    EXPECT_NEAR(r.residual, (A * r.x - b).norm(), 1e-12 * (1.0 + b.norm()));
  }
}

/// A target that is a non-negative combination of 3 of 40 columns is met exactly, and the early
/// stop returns as soon as the residual falls below the tolerance, with fewer columns.
TEST(Nnls, RecoversASparseNonNegativeCombinationAndStopsEarly) {
  std::mt19937_64 rng(9);
  std::uniform_real_distribution<double> U(0.0, 1.0);
  Eigen::MatrixXd A(60, 40);
  for (int i = 0; i < A.rows(); ++i)
    for (int j = 0; j < A.cols(); ++j) A(i, j) = U(rng);
  Eigen::VectorXd x0 = Eigen::VectorXd::Zero(40);
  x0[4] = 1.5, x0[17] = 0.25, x0[31] = 2.0;
  const Eigen::VectorXd b = A * x0;
  const NnlsResult exact = nnls(A, b, 1e-13);
  EXPECT_TRUE(exact.converged);
  EXPECT_LT((exact.x - x0).norm(), 1e-9);
  const NnlsResult early = nnls(A, b, 0.2);
  EXPECT_TRUE(early.converged);
  EXPECT_LE(early.residual, 0.2 * b.norm());
  EXPECT_LE((early.x.array() > 0.0).count(), 3);
}

/// nnls_normal is the same algorithm on A^T A: on well-conditioned random problems it reaches the
/// same KKT point as nnls (weights to 1e-8: the Gram matrix squares the condition number, ~1e2
/// here, so its solves lose ~4 more digits than the QR's), with the same columns in, and the same
/// early stop (the same columns picked while the residual falls to the tolerance).
TEST(Nnls, TheNormalEquationsFormReachesTheSamePoint) {
  std::mt19937_64 rng(17);
  std::normal_distribution<double> N;
  for (int trial = 0; trial < 30; ++trial) {
    const int m = 20 + trial % 11, n = 4 + (trial * 5) % 15;
    Eigen::MatrixXd A(m, n);
    Eigen::VectorXd b(m);
    for (int i = 0; i < m; ++i) {
      b[i] = N(rng);
      for (int j = 0; j < n; ++j) A(i, j) = N(rng);
    }
    const NnlsResult qr = nnls(A, b, 1e-14);
    const NnlsResult ne = nnls_normal(A.transpose() * A, A.transpose() * b, b.squaredNorm(), 1e-14);
    ASSERT_EQ(ne.x.size(), n);
    EXPECT_LT((ne.x - qr.x).norm(), 1e-8 * (1.0 + qr.x.norm())) << "trial " << trial;
    for (int j = 0; j < n; ++j) EXPECT_EQ(ne.x[j] > 0.0, qr.x[j] > 0.0) << "trial " << trial << " column " << j;
    EXPECT_NEAR(ne.residual, (A * ne.x - b).norm(), 1e-8 * (1.0 + b.norm())) << "trial " << trial;
  }
  // A non-negative combination of 3 of 40 columns, and the early stop: the same picks as the QR form.
  std::uniform_real_distribution<double> U(0.0, 1.0);
  Eigen::MatrixXd A(60, 40);
  for (int i = 0; i < A.rows(); ++i)
    for (int j = 0; j < A.cols(); ++j) A(i, j) = U(rng);
  Eigen::VectorXd x0 = Eigen::VectorXd::Zero(40);
  x0[4] = 1.5, x0[17] = 0.25, x0[31] = 2.0;
  const Eigen::VectorXd b = A * x0;
  const Eigen::MatrixXd AtA = A.transpose() * A;
  const Eigen::VectorXd Atb = A.transpose() * b;
  const NnlsResult exact = nnls_normal(AtA, Atb, b.squaredNorm(), 1e-9);
  EXPECT_TRUE(exact.converged);
  EXPECT_LT((exact.x - x0).norm(), 1e-6);  // the Gram form's accuracy: cond(A)^2 ~1e4 times eps, times |x|
  for (double tol : {0.3, 0.1, 0.02}) {
    const NnlsResult early = nnls_normal(AtA, Atb, b.squaredNorm(), tol), early_qr = nnls(A, b, tol);
    EXPECT_TRUE(early.converged);
    EXPECT_LE((A * early.x - b).norm(), tol * b.norm() * (1.0 + 1e-9));
    EXPECT_EQ(early.iterations, early_qr.iterations) << tol;
    for (int j = 0; j < 40; ++j) EXPECT_EQ(early.x[j] > 0.0, early_qr.x[j] > 0.0) << tol << " column " << j;
  }
}

/// A column that is a combination of the passive ones is not brought in (its Cholesky pivot
/// vanishes), and the fit still reaches the optimum of the independent columns.
TEST(Nnls, TheNormalEquationsFormSkipsADependentColumn) {
  Eigen::MatrixXd A = random_matrix(12, 4, 21);
  A.col(3) = 0.5 * A.col(0) + 0.5 * A.col(1);  // dependent on columns 0 and 1
  Eigen::VectorXd x0(4);
  x0 << 1.0, 1.0, 0.5, 0.0;
  const Eigen::VectorXd b = A * x0;
  const NnlsResult r = nnls_normal(A.transpose() * A, A.transpose() * b, b.squaredNorm(), 1e-10);
  EXPECT_TRUE(r.converged);
  EXPECT_GE(r.x.minCoeff(), 0.0);
  EXPECT_LT((A * r.x - b).norm(), 1e-7 * b.norm());
  EXPECT_LE((r.x.array() > 0.0).count(), 3);  // never all four: the fourth adds nothing independent
}

}  // namespace
}  // namespace pneufem
