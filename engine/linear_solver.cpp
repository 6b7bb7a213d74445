#include "engine/linear_solver.h"

#include <Eigen/CholmodSupport>

namespace pneufem {

struct LinearSolver::Impl {
  Eigen::CholmodSupernodalLLT<SparseMatrix, Eigen::Lower> llt;
};

LinearSolver::LinearSolver() : impl_(std::make_unique<Impl>()) {
  // Do not let CHOLMOD print or abort on a non-positive-definite matrix; we check info().
  impl_->llt.cholmod().print = 0;
  impl_->llt.cholmod().quick_return_if_not_posdef = 1;
}
LinearSolver::~LinearSolver() = default;

bool LinearSolver::factorize(const SparseMatrix& K) {
  if (!analysed_) {
    impl_->llt.analyzePattern(K);
    analysed_ = true;
  }
  impl_->llt.factorize(K);
  ++factorizations_;
  has_factor_ = impl_->llt.info() == Eigen::Success;
  return has_factor_;
}

Eigen::VectorXd LinearSolver::solve(const Eigen::VectorXd& b) const { return impl_->llt.solve(b); }

}  // namespace pneufem
