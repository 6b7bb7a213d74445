#include "engine/nnls.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <Eigen/QR>

namespace pneufem {

namespace {

/// Least squares on the passive columns P: z_P = argmin ||A_P z - b||.
Eigen::VectorXd passive_solve(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, const std::vector<int>& P) {
  Eigen::MatrixXd AP(A.rows(), static_cast<Eigen::Index>(P.size()));
  for (std::size_t j = 0; j < P.size(); ++j) AP.col(static_cast<Eigen::Index>(j)) = A.col(P[j]);
  return AP.colPivHouseholderQr().solve(b);
}

}  // namespace

NnlsResult nnls(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, double rel_tol, int max_iterations) {
  const Eigen::Index n = A.cols();
  NnlsResult out;
  out.x = Eigen::VectorXd::Zero(n);
  const double bnorm = b.norm();
  const double target = rel_tol * bnorm;
  if (max_iterations <= 0) max_iterations = static_cast<int>(3 * n);
  std::vector<char> passive(static_cast<std::size_t>(n), 0);
  // A column that enters with a non-positive least-squares weight leaves again at once (the
  // degenerate case of Lawson-Hanson); it may not be chosen again until the solution changes.
  std::vector<char> tabu(static_cast<std::size_t>(n), 0);
  Eigen::VectorXd r = b;
  out.residual = bnorm;
  if (bnorm == 0.0 || n == 0) {
    out.converged = true;
    return out;
  }
  const double eps = 1e-12 * A.cwiseAbs().maxCoeff() * bnorm;
  while (out.iterations < max_iterations && out.residual > target) {
    // The column with the largest (positive) gradient of -||r||^2/2 among the active (zero) ones.
    const Eigen::VectorXd w = A.transpose() * r;
    Eigen::Index best = -1;
    for (Eigen::Index j = 0; j < n; ++j)
      if (!passive[j] && !tabu[j] && w[j] > eps && (best < 0 || w[j] > w[best])) best = j;
    if (best < 0) {  // Kuhn-Tucker conditions hold: the NNLS optimum
      out.converged = true;
      break;
    }
    passive[best] = 1;
    ++out.iterations;
    // Inner loop: move towards the unconstrained solution on the passive set, dropping columns
    // whose weight would turn negative.
    for (int inner = 0; inner <= n; ++inner) {
      std::vector<int> P;
      for (Eigen::Index j = 0; j < n; ++j)
        if (passive[j]) P.push_back(static_cast<int>(j));
      const Eigen::VectorXd z = passive_solve(A, b, P);
      bool feasible = true;
      for (Eigen::Index i = 0; i < z.size(); ++i) feasible = feasible && z[i] > 0.0;
      if (feasible) {
        out.x.setZero();
        for (std::size_t j = 0; j < P.size(); ++j) out.x[P[j]] = z[static_cast<Eigen::Index>(j)];
        break;
      }
      double alpha = 1.0;
      for (std::size_t j = 0; j < P.size(); ++j) {
        const double zj = z[static_cast<Eigen::Index>(j)], xj = out.x[P[j]];
        if (zj <= 0.0) alpha = std::min(alpha, xj / (xj - zj));
      }
      for (std::size_t j = 0; j < P.size(); ++j) {
        double& xj = out.x[P[j]];
        xj += alpha * (z[static_cast<Eigen::Index>(j)] - xj);
        if (xj <= 1e-15 * (1.0 + std::abs(xj))) {
          xj = 0.0;
          passive[P[j]] = 0;
        }
      }
    }
    if (!passive[best] && out.x[best] == 0.0) {
      tabu[best] = 1;
    } else {
      std::fill(tabu.begin(), tabu.end(), 0);
    }
    r = b - A * out.x;
    out.residual = r.norm();
  }
  if (out.residual <= target) out.converged = true;
  return out;
}

}  // namespace pneufem
