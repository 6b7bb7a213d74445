#pragma once
// The BLAS thread count of the direct solver (engine/linear_solver.h), fixed for the process.

namespace pneufem {

/// The number of BLAS threads inside every CHOLMOD factorisation and solve, process-wide; 1
/// unless set. A supernodal factor's bits depend on it (OpenBLAS 0.3.21 partitions its dense
/// kernels by it: tests/engine/test_linear_solver.cpp), so it is fixed here, set before every
/// factorisation, and never follows pneufem's TBB threads (--threads) or OPENBLAS_NUM_THREADS:
/// results are bit-identical for any --threads. 1 because a second BLAS thread made the
/// factorisation slower on the shared 2-core machine (BENCHMARKS.md, "Direct-solver threading").
/// A BLAS without openblas_set_num_threads keeps its own threading.
void set_factorisation_blas_threads(int threads);
int factorisation_blas_threads();

}  // namespace pneufem
