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

/// Lawson-Hanson's inner step on the passive columns P, z their least-squares weights: with every
/// z > 0, x = z on P (0 elsewhere) and true; else x moves towards z as far as every weight stays
/// >= 0, the columns whose weight reaches 0 leave the passive set, and false.
bool step_towards(const Eigen::VectorXd& z, const std::vector<int>& P, Eigen::VectorXd& x, std::vector<char>& passive) {
  if (z.size() == 0 || z.minCoeff() > 0.0) {
    x.setZero();
    for (std::size_t j = 0; j < P.size(); ++j) x[P[j]] = z[static_cast<Eigen::Index>(j)];
    return true;
  }
  double alpha = 1.0;
  for (std::size_t j = 0; j < P.size(); ++j) {
    const double zj = z[static_cast<Eigen::Index>(j)], xj = x[P[j]];
    if (zj <= 0.0) alpha = std::min(alpha, xj / (xj - zj));
  }
  for (std::size_t j = 0; j < P.size(); ++j) {
    double& xj = x[P[j]];
    xj += alpha * (z[static_cast<Eigen::Index>(j)] - xj);
    if (xj <= 1e-15 * (1.0 + std::abs(xj))) {
      xj = 0.0;
      passive[static_cast<std::size_t>(P[j])] = 0;
    }
  }
  return false;
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
      if (step_towards(passive_solve(A, b, P), P, out.x, passive)) break;
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

namespace pneufem {

namespace {

/// A lower Cholesky factor L of AtA's passive block, its columns in the order they came in.
class PassiveCholesky {
 public:
  explicit PassiveCholesky(const Eigen::MatrixXd& AtA) : AtA_(AtA) {}

  const std::vector<int>& columns() const { return cols_; }

  /// Brings column j in; false (nothing changed) if the block would be numerically singular.
  bool add(int j) {
    const Eigen::Index k = static_cast<Eigen::Index>(cols_.size());
    if (L_.rows() <= k) {
      const Eigen::Index cap = std::max<Eigen::Index>(16, 2 * k);
      L_.conservativeResize(cap, cap);
    }
    Eigen::VectorXd l(k);
    for (Eigen::Index i = 0; i < k; ++i) l[i] = AtA_(cols_[static_cast<std::size_t>(i)], j);
    if (k > 0) L_.topLeftCorner(k, k).triangularView<Eigen::Lower>().solveInPlace(l);
    const double d2 = AtA_(j, j) - l.squaredNorm();
    if (!(d2 > 1e-10 * AtA_(j, j))) return false;
    L_.block(k, 0, 1, k) = l.transpose();
    L_(k, k) = std::sqrt(d2);
    cols_.push_back(j);
    return true;
  }

  /// Keeps only the columns for which keep(j) holds (the factor rebuilt in their order).
  template <class Keep>
  void retain(Keep keep) {
    std::vector<int> old;
    old.swap(cols_);
    for (int j : old)
      if (keep(j)) add(j);
  }

  /// z_P = (AtA_PP)^-1 Atb_P, in the order of columns().
  Eigen::VectorXd solve(const Eigen::VectorXd& Atb) const {
    const Eigen::Index k = static_cast<Eigen::Index>(cols_.size());
    Eigen::VectorXd z(k);
    for (Eigen::Index i = 0; i < k; ++i) z[i] = Atb[cols_[static_cast<std::size_t>(i)]];
    const auto Lk = L_.topLeftCorner(k, k);
    Lk.triangularView<Eigen::Lower>().solveInPlace(z);
    Lk.transpose().triangularView<Eigen::Upper>().solveInPlace(z);
    return z;
  }

 private:
  const Eigen::MatrixXd& AtA_;
  Eigen::MatrixXd L_;
  std::vector<int> cols_;
};

}  // namespace

NnlsResult nnls_normal(const Eigen::MatrixXd& AtA, const Eigen::VectorXd& Atb, double btb, double rel_tol, int max_iterations) {
  const Eigen::Index n = AtA.cols();
  NnlsResult out;
  out.x = Eigen::VectorXd::Zero(n);
  const double bnorm = std::sqrt(std::max(btb, 0.0));
  const double target = rel_tol * bnorm;
  if (max_iterations <= 0) max_iterations = static_cast<int>(3 * n);
  out.residual = bnorm;
  if (bnorm == 0.0 || n == 0) {
    out.converged = true;
    return out;
  }
  std::vector<char> passive(static_cast<std::size_t>(n), 0), tabu(static_cast<std::size_t>(n), 0);
  PassiveCholesky chol(AtA);
  const double eps = 1e-12 * std::sqrt(AtA.diagonal().maxCoeff()) * bnorm;  // as nnls's 1e-12 max|A| ||b||
  Eigen::VectorXd w = Atb;  // A^T (b - A x)
  while (out.iterations < max_iterations && out.residual > target) {
    Eigen::Index best = -1;
    for (Eigen::Index j = 0; j < n; ++j)
      if (!passive[j] && !tabu[j] && w[j] > eps && (best < 0 || w[j] > w[best])) best = j;
    if (best < 0) {
      out.converged = true;
      break;
    }
    ++out.iterations;
    if (!chol.add(static_cast<int>(best))) {  // dependent on the passive columns: it cannot lower the residual
      tabu[best] = 1;
      continue;
    }
    passive[best] = 1;
    for (int inner = 0; inner <= n; ++inner) {
      const std::vector<int>& P = chol.columns();
      if (step_towards(chol.solve(Atb), P, out.x, passive)) break;
      chol.retain([&](int j) { return passive[static_cast<std::size_t>(j)] != 0; });
      std::vector<char> kept(static_cast<std::size_t>(n), 0);
      for (int j : chol.columns()) kept[static_cast<std::size_t>(j)] = 1;
      for (Eigen::Index j = 0; j < n; ++j)  // a column the rebuilt factor refused is out as well
        if (passive[j] && !kept[static_cast<std::size_t>(j)]) {
          passive[j] = 0;
          out.x[j] = 0.0;
        }
    }
    if (!passive[best] && out.x[best] == 0.0) {
      tabu[best] = 1;
    } else {
      std::fill(tabu.begin(), tabu.end(), 0);
    }
    // w = Atb - AtA x over the passive columns; the residual from the normal equations.
    const std::vector<int>& P = chol.columns();
    w = Atb;
    double xAtb = 0.0;
    for (int j : P) {
      w.noalias() -= AtA.col(j) * out.x[j];
      xAtb += out.x[j] * Atb[j];
    }
    // ||Ax - b||^2 = btb - 2 x.Atb + x.AtA x = btb - x.Atb - x.w
    double xw = 0.0;
    for (int j : P) xw += out.x[j] * w[j];
    out.residual = std::sqrt(std::max(btb - xAtb - xw, 0.0));
  }
  if (out.residual <= target) out.converged = true;
  return out;
}

}  // namespace pneufem
