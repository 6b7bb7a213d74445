#pragma once
// Non-negative least squares, min ||A x - b||_2 subject to x >= 0, by the active-set method of
// Lawson & Hanson ("Solving Least Squares Problems", 1974, ch. 23, algorithm NNLS), stopped early
// once ||A x - b|| <= tol ||b|| as the energy-conserving sampling and weighting (ECSW) of a reduced
// model uses it (Farhat, Chapman & Avery 2015, IJNME 102, "Structure-preserving, stability, and
// accuracy properties of the energy-conserving sampling and weighting method for the hyper
// reduction of nonlinear finite element dynamic models", algorithm 1): every column is an element,
// every row a component of a training snapshot's reduced force, and the few columns with x > 0 are
// the sampled elements, x their weights.
//
// Deterministic: ties are broken by the lowest column index, and the least-squares subproblems are
// solved by a column-pivoting QR of the passive columns in index order.
#include <Eigen/Core>

namespace pneufem {

struct NnlsResult {
  Eigen::VectorXd x;      ///< the solution (x >= 0)
  double residual = 0.0;  ///< ||A x - b||
  int iterations = 0;     ///< outer iterations (columns brought in)
  bool converged = false; ///< residual <= tol ||b|| (or the exact NNLS optimum was reached)
};

/// Lawson-Hanson NNLS with the early stop ||A x - b|| <= rel_tol ||b||; at most max_iterations
/// outer iterations (0 = 3 * columns).
NnlsResult nnls(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, double rel_tol, int max_iterations = 0);

/// The same problem given by its normal equations, AtA = A^T A, Atb = A^T b, btb = b^T b (the
/// fast NNLS of Bro & De Jong 1997, "A fast non-negativity-constrained least squares algorithm",
/// J. Chemometrics 11, 393-401): the active-set steps of Lawson-Hanson above, with the passive
/// least squares solved by a Cholesky factor of AtA's passive block that grows by one row per column
/// brought in (O(k^2)) and is rebuilt only when columns leave, and the residual from
/// ||A x - b||^2 = btb - 2 Atb.x + x.AtA x. After the Gram matrix (O(m n^2), once) a fit of k columns
/// costs O(n k^2), where the QR form costs O(m k^3): what lets ECSW fit a block of thousands of
/// elements against 10^4-10^5 training rows. A column whose passive block would be singular (its
/// Cholesky pivot below 1e-10 of its diagonal: numerically a combination of the passive columns)
/// is not brought in. The Gram form squares the condition number: fine for ECSW's tolerances
/// (1e-2-1e-4), not for rel_tol near machine precision (use nnls there).
NnlsResult nnls_normal(const Eigen::MatrixXd& AtA, const Eigen::VectorXd& Atb, double btb, double rel_tol, int max_iterations = 0);

}  // namespace pneufem
