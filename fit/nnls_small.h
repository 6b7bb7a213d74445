#pragma once
// min ||A x - b||^2 subject to x >= 0 for A with at most 3 columns, exactly: the optimum is the
// unconstrained least-squares solution on its support (the KKT conditions), so trying every support
// and keeping the best one whose solution is positive finds it. Used for Ogden's moduli (fit.cpp) and
// the Prony g_i (inelastic.cpp) at fixed exponents / relaxation times.
#include <Eigen/Core>

namespace pneufem::fit::detail {

struct Nnls {
  Eigen::VectorXd x;
  double rss;  ///< ||A x - b||^2
};

Nnls nnls_small(const Eigen::MatrixXd& A, const Eigen::VectorXd& b);

}  // namespace pneufem::fit::detail
