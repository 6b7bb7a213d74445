#include "engine/linear_solver.h"

#include "engine/factorisation_threads.h"

#include <malloc.h>

#include <atomic>
#include <cstdlib>
#include <mutex>
#include <stdexcept>

#include <Eigen/CholmodSupport>

// Optional runtime hooks of the OpenMP and OpenBLAS libraries CHOLMOD is linked against. Weak, so
// pneufem still links and runs against another BLAS or a CHOLMOD without OpenMP (then they are null).
extern "C" {
void omp_set_max_active_levels(int) __attribute__((weak));
void openblas_set_num_threads(int) __attribute__((weak));
}

namespace pneufem {
namespace {

// Process settings that make the direct solver fast on a small machine. Measured on 2 cores
// (BENCHMARKS.md, "direct solver threading"): the elastic path trace of diagnose went from 71 s to
// 27 s, with system time from 65 s to 2 s.
//  * Debian's CHOLMOD opens OpenMP regions with an explicit num_threads(4) and OpenBLAS starts its
//    own pthreads; next to our TBB workers on 2 cores they oversubscribe the machine and spend most
//    of the time spinning and in futex calls. pneufem's parallelism is TBB (elements, sweep
//    points), so CHOLMOD's OpenMP regions are serialised (max active levels 0; an explicit
//    num_threads clause ignores OMP_NUM_THREADS; setting OMP_NUM_THREADS keeps the user's) and
//    OpenBLAS runs factorisation_blas_threads() threads (1 unless set), whatever
//    OPENBLAS_NUM_THREADS says: the factor's bits depend on that count. The OpenMP setting is per
//    thread in libgomp (a TBB worker starts from the global defaults), so it is applied on the
//    calling thread before every CHOLMOD call, and the BLAS count with it (another library in the
//    process, numpy say, may have changed it).
//  * Every numeric factorisation allocates the permuted matrix afresh. Blocks above glibc's mmap
//    threshold (at most 32 MiB by default) are mmapped and unmapped each time, so every
//    factorisation page-faults its whole working set; raising the thresholds keeps the memory in
//    the heap for reuse.
bool serialise_openmp = false;
std::atomic<int> blas_threads{1};

void configure_process() {
  serialise_openmp = !std::getenv("OMP_NUM_THREADS") && omp_set_max_active_levels;
  mallopt(M_MMAP_THRESHOLD, 512 << 20);
  mallopt(M_TRIM_THRESHOLD, 1 << 30);
}

/// Before every CHOLMOD call: OpenMP serialised on this thread, OpenBLAS at the fixed count.
void fix_threading_on_this_thread() {
  if (serialise_openmp) omp_set_max_active_levels(0);
  if (openblas_set_num_threads) openblas_set_num_threads(blas_threads.load());
}

}  // namespace

void set_factorisation_blas_threads(int threads) {
  if (threads < 1) throw std::invalid_argument("set_factorisation_blas_threads: threads must be >= 1");
  blas_threads.store(threads);
}

int factorisation_blas_threads() { return blas_threads.load(); }

struct LinearSolver::Impl {
  Eigen::CholmodSupernodalLLT<SparseMatrix, Eigen::Lower> llt;
};

LinearSolver::LinearSolver() : impl_(std::make_unique<Impl>()) {
  static std::once_flag once;
  std::call_once(once, configure_process);
  // Do not let CHOLMOD print or abort on a non-positive-definite matrix; we check info().
  impl_->llt.cholmod().print = 0;
  impl_->llt.cholmod().quick_return_if_not_posdef = 1;
}
LinearSolver::~LinearSolver() = default;

bool LinearSolver::factorize(const SparseMatrix& K) {
  fix_threading_on_this_thread();
  if (!analysed_) {
    impl_->llt.analyzePattern(K);
    analysed_ = true;
  }
  impl_->llt.factorize(K);
  ++factorizations_;
  has_factor_ = impl_->llt.info() == Eigen::Success;
  return has_factor_;
}

Eigen::VectorXd LinearSolver::solve(const Eigen::VectorXd& b) const {
  fix_threading_on_this_thread();
  return impl_->llt.solve(b);
}

}  // namespace pneufem
