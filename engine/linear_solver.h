#pragma once
// Sparse symmetric direct solver (CHOLMOD supernodal Cholesky, METIS/AMD ordering) with the
// symbolic analysis kept between factorisations, since the pattern never changes.
// When the matrix is not positive definite (past a limit point, or a bad line-search
// state) factorize() returns false and the caller regularises.
#include <memory>

#include <Eigen/Core>

#include "engine/assembly.h"

namespace pneufem {

class LinearSolver {
 public:
  LinearSolver();
  ~LinearSolver();
  LinearSolver(const LinearSolver&) = delete;
  LinearSolver& operator=(const LinearSolver&) = delete;

  /// Factorises K (lower triangle used). Returns false when K is not positive definite.
  bool factorize(const SparseMatrix& K);
  /// Solves K x = b with the last successful factorisation.
  Eigen::VectorXd solve(const Eigen::VectorXd& b) const;
  bool has_factor() const { return has_factor_; }
  /// Drops the numeric factor (the symbolic analysis stays): solve() is invalid until the next
  /// successful factorize().
  void forget_factor() { has_factor_ = false; }
  int factorizations() const { return factorizations_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  bool analysed_ = false;
  bool has_factor_ = false;
  int factorizations_ = 0;
};

}  // namespace pneufem
