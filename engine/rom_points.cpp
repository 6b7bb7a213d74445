// The reduced model's kept quadrature points and their hyper-reduced force (engine/rom_points.h).
#include "engine/rom_points.h"

#include <algorithm>
#include <atomic>
#include <climits>
#include <cmath>
#include <sstream>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "engine/path_spline.h"
#include "engine/tet_element.h"
#include "core/errors.h"

// BLAS's dgemm for the chunks' tangent products, when the BLAS is OpenBLAS (its weak hook is then
// found): its kernels are picked for the CPU at run time (AVX2/AVX-512), where Eigen's are compiled
// for generic x86-64 (SSE2): measured 3.3x faster on the chunk's 172 x 288 x 172 product, which
// held ~2/3 of a reduced run's time (bench/results/rom_h6_ceiling section 12). Against a reference
// BLAS (no hook) Eigen's product stays, faster than that BLAS.
extern "C" {
void dgemm_(const char* transa, const char* transb, const int* m, const int* n, const int* k, const double* alpha, const double* a,
            const int* lda, const double* b, const int* ldb, const double* beta, double* c, const int* ldc);
void openblas_set_num_threads(int) __attribute__((weak));
}

namespace pneufem {

namespace rom_detail {

KeptPoints::KeptPoints(const Model& model, const ReducedBasis& basis) : basis_(basis) {
  r_ = basis.num_modes();
  ns_ = basis.num_samples();
  const Mesh& mesh = model.mesh;
  const ElementGeometry geom = compute_geometry(mesh);
  const int nqp = geom.nqp, npe = geom.npe;
  nqp_ = nqp;
  // Points grouped by material (one batched evaluate per chunk of a group), elements in order.
  std::vector<std::pair<int, int>> order;  // (part, position in basis.elements)
  for (std::size_t i = 0; i < basis.elements.size(); ++i)
    order.emplace_back(model.element_part[basis.elements[i]], static_cast<int>(i));
  std::stable_sort(order.begin(), order.end(), [](auto& a, auto& b) { return a.first < b.first; });
  for (auto [part, pos] : order) {
    const int e = basis.elements[pos];
    const Material* m = &model.material_of(e);
    if (groups_.empty() || groups_.back().material != m) {
      const int begin = size();
      groups_.push_back({m, begin, begin, history_size_, m->state_size()});
    }
    for (int q = 0; q < nqp; ++q) {
      element_.push_back(e);
      weight_.push_back(basis.weights[pos] * geom.w(e, q));
    }
    groups_.back().end = size();
    history_size_ += static_cast<std::size_t>(nqp) * m->state_size();
  }
  const int np = size();
  F_.resize(static_cast<std::size_t>(ns_) * np);
  dF_.resize(F_.size());
  T_.resize(F_.size());
  B_.assign(static_cast<std::size_t>(np) * 9 * r_, 0.0);
  for (int i = 0; i < np; ++i) {
    const int e = element_[i], q = i % nqp;  // points of an element are consecutive, nqp each
    const int* n = mesh.element(e);
    const double* g = geom.grad(e, q);
    for (int k = 0; k < ns_; ++k) {
      Mat3 F = Mat3::Identity(), dF = Mat3::Zero(), T = Mat3::Zero();
      for (int a = 0; a < npe; ++a) {
        const Eigen::Map<const Eigen::RowVector3d> ga(g + 3 * a);
        F += basis.U.col(k).segment<3>(3 * n[a]) * ga;
        dF += basis.dU.col(k).segment<3>(3 * n[a]) * ga;
        T += basis.W.col(k).segment<3>(3 * n[a]) * ga;
      }
      F_[static_cast<std::size_t>(k) * np + i] = F;
      dF_[static_cast<std::size_t>(k) * np + i] = dF;
      T_[static_cast<std::size_t>(k) * np + i] = T;
    }
    {
      const std::vector<Mat3> m = spline_slopes<Mat3>(basis.theta, [&](std::size_t k) { return T_[k * np + i]; });
      if (dT_.empty()) dT_.resize(T_.size());
      for (int k = 0; k < ns_; ++k) dT_[static_cast<std::size_t>(k) * np + i] = m[static_cast<std::size_t>(k)];
    }
    double* B = B_.data() + static_cast<std::size_t>(i) * 9 * r_;
    for (int j = 0; j < r_; ++j) {
      Mat3 Bj = Mat3::Zero();
      for (int a = 0; a < npe; ++a)
        Bj += basis.Phi.col(j).segment<3>(3 * n[a]) * Eigen::Map<const Eigen::RowVector3d>(g + 3 * a);
      for (int c = 0; c < 9; ++c) B[c * r_ + j] = Bj(c);
    }
  }
}

std::vector<double> KeptPoints::initial_history() const {
  std::vector<double> h(history_size_, 0.0);
  for (const Group& gr : groups_)
    for (int i = gr.begin; i < gr.end; ++i)
      gr.material->init_state(std::span<double>(h).subspan(gr.state_offset + static_cast<std::size_t>(i - gr.begin) * gr.state_size,
                                                            gr.state_size));
  return h;
}

void KeptPoints::gather_history(const Assembler& full, std::span<const double> full_state, std::span<double> kept) const {
  for (const Group& gr : groups_) {
    const std::size_t ss = static_cast<std::size_t>(gr.state_size);
    if (ss == 0) continue;
    for (int i = gr.begin; i < gr.end; ++i) {
      const std::span<const double> es = full.element_state(full_state, element_[i]);
      const std::size_t q = static_cast<std::size_t>(i % nqp_);  // points of an element are consecutive
      std::copy_n(es.begin() + static_cast<std::ptrdiff_t>(q * ss), ss,
                  kept.begin() + static_cast<std::ptrdiff_t>(gr.state_offset + static_cast<std::size_t>(i - gr.begin) * ss));
    }
  }
}

std::vector<double> KeptPoints::history_scalars(const std::vector<double>& history) const {
  std::vector<double> out(2 * static_cast<std::size_t>(size()), 0.0);
  for (const Group& gr : groups_) {
    if (gr.state_size == 0) continue;
    for (int i = gr.begin; i < gr.end; ++i) {
      const PointFields f = gr.material->fields(std::span<const double>(history).subspan(
          gr.state_offset + static_cast<std::size_t>(i - gr.begin) * gr.state_size, gr.state_size));
      out[2 * i] = f.fatigue_damage;
      out[2 * i + 1] = f.viscous_strain;
    }
  }
  return out;
}

// One function (~110 lines) on purpose: the chunked, deterministic parallel loop (evaluate the
// material in batches, accumulate each chunk's force and Jacobian, sum the chunks in order) is read
// as one piece; its per-point algebra is the header's.
void KeptPoints::force(double theta, const Eigen::VectorXd& q, const TimeStep& ts, std::span<const double> old,
                       std::span<double> trial, Eigen::VectorXd& g, Eigen::MatrixXd* jac) const {
  const int n1 = r_ + 1, np = size();
  const int k = path_segment_index(basis_.theta, theta);
  const Hermite h((theta - basis_.theta[k]) / (basis_.theta[k + 1] - basis_.theta[k]), basis_.theta[k + 1] - basis_.theta[k]);
  const Mat3* F0 = F_.data() + static_cast<std::size_t>(k) * np;
  const Mat3* F1 = F0 + np;
  const Mat3* M0 = dF_.data() + static_cast<std::size_t>(k) * np;
  const Mat3* M1 = M0 + np;
  const Mat3* T0 = T_.data() + static_cast<std::size_t>(k) * np;
  const Mat3* T1 = T0 + np;
  const Mat3* S0 = dT_.data() + static_cast<std::size_t>(k) * np;
  const Mat3* S1 = S0 + np;
  // Chunks of up to kChunk points of one group: one batched evaluate each, partial sums per chunk,
  // added in chunk order (the result does not depend on the thread count).
  constexpr int kChunk = 32;
  struct Chunk {
    int group, begin, end;
  };
  std::vector<Chunk> chunks;
  for (int gi = 0; gi < static_cast<int>(groups_.size()); ++gi)
    for (int b = groups_[gi].begin; b < groups_[gi].end; b += kChunk)
      chunks.push_back({gi, b, std::min(b + kChunk, groups_[gi].end)});
  const bool tangent = jac != nullptr;
  const std::size_t jsz = tangent ? static_cast<std::size_t>(n1) * n1 : 0;
  std::vector<double> part(chunks.size() * (n1 + jsz), 0.0);
  std::atomic<int> bad{INT_MAX};
  // One BLAS thread per call: the products run inside TBB's tasks, and OpenBLAS's own threads would
  // serialise concurrent calls (the factorisations set their count again before every call).
  const bool blas = tangent && openblas_set_num_threads != nullptr;
  if (blas) openblas_set_num_threads(1);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, chunks.size(), 1), [&](const tbb::blocked_range<std::size_t>& range) {
    std::array<Mat3, kChunk> F, Ft, Tw, Twt;
    std::array<PointResponse, kChunk> resp;
    // The chunk's tangent as one product: rows 9j..9j+8 of Dt_all hold point j's test gradients
    // [T, B], of AD_all its W A [dF/dtheta, B]; J += Dt_all^T AD_all (one blocked GEMM per chunk,
    // where a product per point spent most of its time packing 9-row operands).
    using RowMajorB = Eigen::Matrix<double, 9, Eigen::Dynamic, Eigen::RowMajor>;
    Eigen::MatrixXd Dt_all(tangent ? 9 * kChunk : 0, n1), AD_all(tangent ? 9 * kChunk : 0, n1);
    Eigen::Matrix<double, 9, Eigen::Dynamic> D(9, n1);
    for (std::size_t c = range.begin(); c < range.end(); ++c) {
      const Chunk& ch = chunks[c];
      const Group& gr = groups_[ch.group];
      const int m = ch.end - ch.begin;
      bool ok = true;
      for (int j = 0; j < m; ++j) {
        const int i = ch.begin + j;
        F[j] = h(F0[i], F1[i], M0[i], M1[i], &Ft[j]);
        Tw[j] = tangent ? h(T0[i], T1[i], S0[i], S1[i], &Twt[j]) : h.value(T0[i], T1[i], S0[i], S1[i]);
        const Eigen::Map<const RowMajorB> B(B_.data() + static_cast<std::size_t>(i) * 9 * r_, 9, r_);
        F[j].reshaped() += B.lazyProduct(q);  // coefficient-wise: a 9 x r product is too small for a GEMV kernel
        const double J = F[j].determinant();
        if (!(J > 0.0) || !std::isfinite(J)) ok = false;
      }
      if (!ok) {
        for (int j = 0; j < m; ++j) {
          const double J = F[j].determinant();
          if (!(J > 0.0) || !std::isfinite(J)) {
            int cur = bad.load(), e = element_[ch.begin + j];
            while (e < cur && !bad.compare_exchange_weak(cur, e)) {
            }
          }
        }
        continue;
      }
      const std::size_t so = gr.state_offset + static_cast<std::size_t>(ch.begin - gr.begin) * gr.state_size;
      const std::size_t sl = static_cast<std::size_t>(m) * gr.state_size;
      std::span<const double> s_old = gr.state_size > 0 && !old.empty() ? old.subspan(so, sl) : std::span<const double>();
      std::span<double> s_new = gr.state_size > 0 && !trial.empty() ? trial.subspan(so, sl) : std::span<double>();
      gr.material->evaluate(std::span<const Mat3>(F.data(), m), ts, s_old, s_new, std::span<PointResponse>(resp.data(), m), tangent);
      double* gp = part.data() + c * (n1 + jsz);
      Eigen::Map<Eigen::MatrixXd> Jp(gp + n1, tangent ? n1 : 0, tangent ? n1 : 0);
      Eigen::Map<Eigen::VectorXd> gq(gp + 1, r_);
      bool finite = true;
      for (int j = 0; j < m; ++j) {
        const int i = ch.begin + j;
        const Mat3 P = resp[j].P();
        if (!P.allFinite()) {
          int cur = bad.load(), e = element_[i];
          while (e < cur && !bad.compare_exchange_weak(cur, e)) {
          }
          finite = false;
          break;
        }
        const double W = weight_[i];
        const Eigen::Map<const RowMajorB> B(B_.data() + static_cast<std::size_t>(i) * 9 * r_, 9, r_);
        gp[0] += W * P.cwiseProduct(Tw[j]).sum();
        const Eigen::Matrix<double, 9, 1> WP = W * P.reshaped();
        gq.noalias() += B.transpose().lazyProduct(WP);
        if (!tangent) continue;
        D.col(0) = Ft[j].reshaped();
        D.rightCols(r_) = B;
        Dt_all.block(9 * j, 0, 9, 1) = Tw[j].reshaped();
        Dt_all.block(9 * j, 1, 9, r_) = B;
        AD_all.middleRows(9 * j, 9).noalias() = (W * resp[j].A()) * D;
        Jp(0, 0) += W * P.cwiseProduct(Twt[j]).sum();
      }
      if (tangent && finite) {
        if (blas) {  // Jp += Dt^T AD, the same product (column-major, leading dimension 9 kChunk)
          const int rows = 9 * m, ld = 9 * kChunk, n = n1;
          const double one = 1.0;
          dgemm_("T", "N", &n, &n, &rows, &one, Dt_all.data(), &ld, AD_all.data(), &ld, &one, Jp.data(), &n);
        } else {
          Jp.noalias() += Dt_all.topRows(9 * m).transpose() * AD_all.topRows(9 * m);
        }
      }
    }
  });
  if (bad.load() != INT_MAX) {
    std::ostringstream s;
    s << "reduced model: element " << bad.load() + 1
      << " inverted or gave a non-finite stress at t = " << ts.time_s
      << " s (the reduced state left the range its basis describes, or the actuator is past its limit point)";
    throw PhysicsError(s.str(), bad.load(), ts.time_s);
  }
  g = Eigen::VectorXd::Zero(n1);
  if (tangent) *jac = Eigen::MatrixXd::Zero(n1, n1);
  for (std::size_t c = 0; c < chunks.size(); ++c) {
    const double* gp = part.data() + c * (n1 + jsz);
    g += Eigen::Map<const Eigen::VectorXd>(gp, n1);
    if (tangent) *jac += Eigen::Map<const Eigen::MatrixXd>(gp + n1, n1, n1);
  }
}

}  // namespace rom_detail

}  // namespace pneufem
