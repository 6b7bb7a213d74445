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

}  // namespace pneufem
