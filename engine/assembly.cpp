#include "engine/assembly.h"

#include <algorithm>
#include <array>
#include <atomic>
#include <climits>
#include <cmath>
#include <map>
#include <sstream>
#include <string>
#include <utility>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <Eigen/Geometry>

#include "core/errors.h"
#include "engine/nonlocal.h"

namespace pneufem {

namespace {

// Greedy colouring of elements so that elements of one colour share no node.
std::vector<std::vector<int>> colour_elements(const Mesh& mesh) {
  const int ne = mesh.num_elements(), npe = mesh.npe();
  std::vector<std::vector<int>> node_colours(mesh.num_nodes());
  std::vector<std::vector<int>> colours;
  std::vector<char> used;
  for (int e = 0; e < ne; ++e) {
    const int* n = mesh.element(e);
    used.assign(colours.size() + 1, 0);
    for (int a = 0; a < npe; ++a)
      for (int c : node_colours[n[a]]) used[c] = 1;
    int c = 0;
    while (used[c]) ++c;
    if (c == static_cast<int>(colours.size())) colours.emplace_back();
    colours[c].push_back(e);
    for (int a = 0; a < npe; ++a) node_colours[n[a]].push_back(c);
  }
  return colours;
}

void atomic_min(std::atomic<int>& target, int v) {
  int cur = target.load();
  while (v < cur && !target.compare_exchange_weak(cur, v)) {
  }
}

Eigen::Matrix3d skew(const Eigen::Vector3d& v) {
  Eigen::Matrix3d S;
  S << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return S;
}

}  // namespace

Assembler::Assembler(const Model& model) : model_(model), geom_(compute_geometry(model.mesh)) {
  build_element_loop();
  const int ne = model.mesh.num_elements();
  state_offset_.assign(ne + 1, 0);
  for (int e = 0; e < ne; ++e)
    state_offset_[e + 1] = state_offset_[e] + static_cast<std::size_t>(geom_.nqp) * model.material_of(e).state_size();
  build_nonlocal();
  build_solid_mass();
  build_pattern();
  build_pressure_faces();
}

void Assembler::build_element_loop() {
  const Model& model = model_;
  const Mesh& mesh = model.mesh;
  const int ne = mesh.num_elements(), npe = mesh.npe();
  std::vector<std::vector<int>> colours = colour_elements(mesh);
  colour_ptr_.assign(1, 0);
  kelem_.reserve(ne);
  for (auto& c : colours) {
    // Within a colour the order is free (its elements share no node, so every sum sees the same
    // terms in the same order): group the elements by part, hence by material, so that the
    // force kernel's batches of one material are full (fabric and silicone interleave otherwise).
    std::stable_sort(c.begin(), c.end(), [&](int a, int b) { return model.element_part[a] < model.element_part[b]; });
    kelem_.insert(kelem_.end(), c.begin(), c.end());
    colour_ptr_.push_back(static_cast<int>(kelem_.size()));
  }
  const std::size_t gq = static_cast<std::size_t>(geom_.nqp) * npe * 3;
  knodes_.resize(static_cast<std::size_t>(ne) * npe);
  kgrad_.resize(static_cast<std::size_t>(ne) * gq);
  kw_.resize(static_cast<std::size_t>(ne) * geom_.nqp);
  kmat_.resize(ne);
  for (int i = 0; i < ne; ++i) {
    const int e = kelem_[i];
    std::copy(mesh.element(e), mesh.element(e) + npe, knodes_.begin() + static_cast<std::ptrdiff_t>(i) * npe);
    std::copy(geom_.grad(e, 0), geom_.grad(e, 0) + gq, kgrad_.begin() + static_cast<std::ptrdiff_t>(i * gq));
    for (int q = 0; q < geom_.nqp; ++q) kw_[static_cast<std::size_t>(i) * geom_.nqp + q] = geom_.w(e, q);
    kmat_[i] = &model.material_of(e);
  }
}

void Assembler::build_solid_mass() {
  const Mesh& mesh = model_.mesh;
  const int ne = mesh.num_elements(), npe = mesh.npe();
  mass_ = Eigen::VectorXd::Zero(mesh.num_nodes());
  const auto frac = lumped_mass_fractions(mesh.type);
  for (int e = 0; e < ne; ++e) {
    const double m = model_.parts[model_.element_part[e]].density_kg_m3 * geom_.volume[e];
    const int* n = mesh.element(e);
    for (int a = 0; a < npe; ++a) mass_[n[a]] += frac[a] * m;
  }
}

void Assembler::build_pattern() {
  const Model& model = model_;
  const Mesh& mesh = model.mesh;
  const int ne = mesh.num_elements(), nn = mesh.num_nodes(), npe = mesh.npe();
  // Node adjacency (including self), sorted.
  std::vector<std::vector<int>> adj(nn);
  for (int e = 0; e < ne; ++e) {
    const int* n = mesh.element(e);
    for (int a = 0; a < npe; ++a)
      for (int b = 0; b < npe; ++b) adj[n[a]].push_back(n[b]);
  }
  // Membrane triangles couple their nodes too (already neighbours when they are element faces).
  const int npf_m = nodes_per_face(mesh.type);
  for (const MembraneSet& ms : model.membranes)
    for (std::size_t t = 0; t + npf_m <= ms.nodes.size(); t += npf_m)
      for (int a = 0; a < npf_m; ++a)
        for (int b = 0; b < npf_m; ++b) adj[ms.nodes[t + a]].push_back(ms.nodes[t + b]);
  adj_ptr_.assign(nn + 1, 0);
  for (int i = 0; i < nn; ++i) {
    auto& v = adj[i];
    std::sort(v.begin(), v.end());
    v.erase(std::unique(v.begin(), v.end()), v.end());
    adj_ptr_[i + 1] = adj_ptr_[i] + static_cast<int>(v.size());
  }
  adj_.reserve(adj_ptr_.back());
  for (auto& v : adj) adj_.insert(adj_.end(), v.begin(), v.end());
  // Pair slots: position of node a in adj(b), per loop position.
  pair_slot_.resize(static_cast<std::size_t>(ne) * npe * npe);
  for (int i = 0; i < ne; ++i) {
    const int* n = knodes_.data() + static_cast<std::size_t>(i) * npe;
    for (int a = 0; a < npe; ++a)
      for (int b = 0; b < npe; ++b) {
        const int* first = adj_.data() + adj_ptr_[n[b]];
        const int* last = adj_.data() + adj_ptr_[n[b] + 1];
        pair_slot_[(static_cast<std::size_t>(i) * npe + a) * npe + b] =
            static_cast<std::uint16_t>(std::lower_bound(first, last, n[a]) - first);
      }
  }
  // ---- Membranes (engine/membrane.h): reference geometry, lumped mass, pair slots ----------
  for (const MembraneSet& ms : model.membranes) {
    mgeom_.push_back(compute_membrane_geometry(mesh, ms));
    add_membrane_lumped_mass(ms, mgeom_.back(), mass_);
    auto& slots = mslot_.emplace_back(ms.nodes.size() * npf_m);
    for (std::size_t t = 0; t < ms.nodes.size(); t += npf_m)
      for (int a = 0; a < npf_m; ++a)
        for (int b = 0; b < npf_m; ++b) {
          const int* first = adj_.data() + adj_ptr_[ms.nodes[t + b]];
          const int* last = adj_.data() + adj_ptr_[ms.nodes[t + b] + 1];
          slots[(t + a) * npf_m + b] = static_cast<std::uint16_t>(std::lower_bound(first, last, ms.nodes[t + a]) - first);
        }
  }
  // ---- end membranes ---------------------------------------------------------------------------
  // CSC column pointers: column 3*b + k holds the 3 * |adj(b)| rows of b's neighbours.
  col_ptr_.assign(3 * nn + 1, 0);
  for (int b = 0; b < nn; ++b)
    for (int k = 0; k < 3; ++k) col_ptr_[3 * b + k + 1] = col_ptr_[3 * b + k] + 3 * (adj_ptr_[b + 1] - adj_ptr_[b]);
}

void Assembler::build_pressure_faces() {
  const Mesh& mesh = model_.mesh;
  // Pressure faces in outward order: the Abaqus face order has an inward right-hand normal,
  // so swap the 2nd and 3rd corner (and the mid-edge nodes accordingly).
  const int npf = nodes_per_face(mesh.type);
  pface_nodes_.reserve(model_.pressure_faces.size() * npf);
  for (const FaceRef& f : model_.pressure_faces) {
    const int* ln = face_local_nodes(mesh.type, f.local_face);
    const int* n = mesh.element(f.element);
    if (npf == 3) {
      for (int k : {0, 2, 1}) pface_nodes_.push_back(n[ln[k]]);
    } else {
      for (int k : {0, 2, 1, 5, 4, 3}) pface_nodes_.push_back(n[ln[k]]);
    }
  }
}

std::vector<double> Assembler::initial_state() const {
  std::vector<double> s(state_size(), 0.0);
  const int ne = model_.mesh.num_elements();
  for (int e = 0; e < ne; ++e) {
    const Material& mat = model_.material_of(e);
    const int ss = mat.state_size();
    if (ss == 0) continue;
    for (int q = 0; q < geom_.nqp; ++q)
      mat.init_state(std::span<double>(s).subspan(state_offset_[e] + static_cast<std::size_t>(q) * ss, ss));
  }
  return s;
}

SparseMatrix Assembler::tangent_pattern() const {
  const int nn = model_.mesh.num_nodes();
  SparseMatrix K(3 * nn, 3 * nn);
  K.resizeNonZeros(col_ptr_.back());
  int* outer = K.outerIndexPtr();
  int* inner = K.innerIndexPtr();
  std::copy(col_ptr_.begin(), col_ptr_.end(), outer);
  for (int b = 0; b < nn; ++b)
    for (int k = 0; k < 3; ++k) {
      int p = col_ptr_[3 * b + k];
      for (int s = adj_ptr_[b]; s < adj_ptr_[b + 1]; ++s)
        for (int i = 0; i < 3; ++i) inner[p++] = 3 * adj_[s] + i;
    }
  std::fill(K.valuePtr(), K.valuePtr() + K.nonZeros(), 0.0);
  return K;
}

/// The inputs and outputs of one internal() call, shared by its element kernels.
struct Assembler::Pass {
  const Eigen::VectorXd& u;
  const TimeStep& ts;
  std::span<const double> state_old;
  std::span<double> state_new;
  Eigen::VectorXd* f_int;      ///< null: not assembled
  SparseMatrix* K;             ///< null: force only
  double* elem_energy;         ///< per element; null: no energy
  std::atomic<int>& bad;       ///< lowest element that inverted or gave a non-finite stress (INT_MAX: none)
  bool has_state;              ///< some law has history
};

void Assembler::internal(const Eigen::VectorXd& u, const TimeStep& ts, std::span<const double> state_old,
                         std::span<double> state_new, Eigen::VectorXd* f_int, SparseMatrix* K, double* energy) const {
  if (model_.mesh.type == ElementType::Tet4)
    internal_impl<4, 1>(u, ts, state_old, state_new, f_int, K, energy);
  else
    internal_impl<10, 4>(u, ts, state_old, state_new, f_int, K, energy);
}

// F = I + grad u at the element's points (not x grad N): at small strain the displacement
// gradient is computed to full relative precision, so stresses of a stiff layer (E = 6.5 GPa)
// carry no round-off floor.
template <int NPE, int NQP>
inline void Assembler::deformation_gradients(const Eigen::VectorXd& u, int pos, std::array<Mat3, NQP>& F) const {
  const int* n = knodes_.data() + static_cast<std::size_t>(pos) * NPE;
  const double* grad = kgrad_.data() + static_cast<std::size_t>(pos) * NQP * NPE * 3;  // [q][a][3]
  Eigen::Matrix<double, 3, NPE> ue;
  for (int a = 0; a < NPE; ++a) ue.col(a) = u.template segment<3>(3 * n[a]);
  for (int q = 0; q < NQP; ++q) {
    const Eigen::Map<const Eigen::Matrix<double, 3, NPE>> g(grad + q * NPE * 3);  // column a = dN_a/dX
    F[q] = Mat3::Identity() + ue * g.transpose();
  }
}

namespace {

inline bool inverted(double J) { return !(J > 0.0) || !std::isfinite(J); }

}  // namespace

// The element's slice of the material history (empty spans for a law without history).
inline void Assembler::element_states(const Pass& p, int pos, std::span<const double>& s_old,
                                      std::span<double>& s_new) const {
  if (!p.has_state) return;
  const int e = kelem_[pos];
  const std::size_t o0 = state_offset_[e], o1 = state_offset_[e + 1];
  s_old = p.state_old.subspan(o0, o1 - o0);
  if (!p.state_new.empty()) s_new = p.state_new.subspan(o0, o1 - o0);
}

// Force only (explicit steps, residuals): consecutive elements of one material share a batch of
// StressBatch::kLanes points, hence one virtual call, and the law computes them with
// structure-of-arrays arithmetic (materials/material.h); a law with history gets one element per
// batch, with its state. F and fe stay element by element, with the tangent path's Eigen
// expressions (same bits); det F, P = P_iso + P_vol and the finiteness checks run on the batch.
// The Tet4 force became 2x faster (BENCHMARKS §4); arranging F and fe by lanes too was slower.
template <int NPE, int NQP>
void Assembler::force_range(const Pass& p, int begin, int end) const {
  constexpr int kPerBatch = StressBatch::kLanes / NQP;
  static_assert(StressBatch::kLanes % NQP == 0, "a batch holds whole elements");
  StressBatch b;
  std::array<int, kPerBatch> bpos;  // loop positions of the batch's elements
  std::array<Mat3, NQP> F;
  for (int pos = begin; pos < end;) {
    const Material& mat = *kmat_[pos];
    const int cap = p.has_state && mat.state_size() > 0 ? 1 : kPerBatch;
    int m = 0;
    for (; pos < end && m < cap && kmat_[pos] == &mat; ++pos) {
      deformation_gradients<NPE, NQP>(p.u, pos, F);
      for (int q = 0; q < NQP; ++q) b.set_F(m * NQP + q, F[q]);
      bpos[m++] = pos;
    }
    b.n = m * NQP;
    b.pad();
    force_batch<NPE, NQP>(p, mat, cap == 1, b, bpos.data(), m);
  }
}

// One batch of force_range: `m` elements at loop positions `bpos`, their F set in `b`.
template <int NPE, int NQP>
void Assembler::force_batch(const Pass& p, const Material& mat, bool with_state, StressBatch& b, const int* bpos,
                            int m) const {
  constexpr int L = StressBatch::kLanes;
  constexpr int kPerBatch = L / NQP;
  // det F of every point (Eigen's 3x3 formula); an inverted element is reported after the
  // loop, and its points are replaced by F = I so that the law sees valid input.
  const auto& Fb = b.F;
  double J[L];
  for (int l = 0; l < L; ++l)
    J[l] = (Fb[0][l] * (Fb[4][l] * Fb[8][l] - Fb[7][l] * Fb[5][l]) -
            Fb[3][l] * (Fb[1][l] * Fb[8][l] - Fb[7][l] * Fb[2][l])) +
           Fb[6][l] * (Fb[1][l] * Fb[5][l] - Fb[4][l] * Fb[2][l]);
  std::array<bool, kPerBatch> ok;
  for (int j = 0; j < m; ++j) {
    ok[j] = true;
    for (int q = 0; q < NQP; ++q) ok[j] = ok[j] && !inverted(J[j * NQP + q]);
    if (ok[j]) continue;
    atomic_min(p.bad, kelem_[bpos[j]]);
    for (int q = 0; q < NQP; ++q) b.set_F(j * NQP + q, Mat3::Identity());
  }
  if (std::none_of(ok.begin(), ok.begin() + m, [](bool v) { return v; })) return;  // e.g. no trial state
  std::span<const double> s_old;
  std::span<double> s_new;
  if (with_state) element_states(p, bpos[0], s_old, s_new);
  mat.stress(b, p.ts, s_old, s_new);
  double P[9][L], psi[L], nonfinite[L];
  for (int l = 0; l < L; ++l) {
    psi[l] = b.psi_iso[l] + b.psi_vol[l];
    nonfinite[l] = 0.0;
  }
  for (int k = 0; k < 9; ++k)
    for (int l = 0; l < L; ++l) {
      P[k][l] = b.P_iso[k][l] + b.P_vol[k][l];
      nonfinite[l] = nonfinite[l] + (P[k][l] - P[k][l]);  // 0 for a finite entry, NaN otherwise
    }
  for (int j = 0; j < m; ++j) {
    if (!ok[j]) continue;
    const int pj = bpos[j], e = kelem_[pj];
    const double* grad = kgrad_.data() + static_cast<std::size_t>(pj) * NQP * NPE * 3;
    const double* wq = kw_.data() + static_cast<std::size_t>(pj) * NQP;
    Eigen::Matrix<double, 3, NPE> fe = Eigen::Matrix<double, 3, NPE>::Zero();
    double psi_e = 0.0;
    for (int q = 0; q < NQP; ++q) {
      const int l = j * NQP + q;
      if (!(nonfinite[l] == 0.0)) {
        ok[j] = false;
        break;
      }
      const Eigen::Map<const Eigen::Matrix<double, 3, NPE>> g(grad + q * NPE * 3);
      const Eigen::Map<const Mat3, 0, Eigen::InnerStride<L>> Pl(&P[0][l]);
      const double w = wq[q];
      fe.noalias() += w * Pl * g;
      psi_e += w * psi[l];
    }
    if (!ok[j]) {
      atomic_min(p.bad, e);
      continue;
    }
    if (p.elem_energy) p.elem_energy[e] = psi_e;
    if (p.f_int) {
      const int* n = knodes_.data() + static_cast<std::size_t>(pj) * NPE;
      for (int a = 0; a < NPE; ++a) p.f_int->template segment<3>(3 * n[a]) += fe.col(a);
    }
  }
}

namespace {

// Element stiffness K_ab(i,k) = sum_q w sum_JL g_a[J] A(iJ,kL) g_b[L], accumulated over the
// points in a local matrix (upper blocks only, A has major symmetry).
template <int NPE, int NQP>
void element_stiffness(const double* grad, const double* wq, const std::array<PointResponse, NQP>& resp,
                       Eigen::Matrix<double, 3 * NPE, 3 * NPE>& Ke) {
  Ke.setZero();
  for (int q = 0; q < NQP; ++q) {
    const Eigen::Map<const Eigen::Matrix<double, 3, NPE>> g(grad + q * NPE * 3);
    // The symmetric part of the material tangent: K = sum G^T A G is then the symmetric part of
    // the consistent tangent, which the symmetric solver (Cholesky, upper blocks here) needs.
    // Hyperelastic tangents have major symmetry (A = A^T, and 0.5 (a + a) == a exactly, so
    // nothing changes for them); a rate law's consistent tangent need not (fatigue driven by the
    // principal stretch: dP/dF gains P (x) dlambda/dF), and using its upper half only would be
    // neither the tangent nor its symmetric part.
    const Mat9 Aq = resp[q].A();
    const Mat9 A = (0.5 * wq[q]) * (Aq + Aq.transpose());
    for (int b = 0; b < NPE; ++b) {
      // T(iJ, k) = sum_L A(iJ, kL) g_b[L]
      Eigen::Matrix<double, 9, 3> T;
      for (int k = 0; k < 3; ++k)
        T.col(k) = A.col(flat(k, 0)) * g(0, b) + A.col(flat(k, 1)) * g(1, b) + A.col(flat(k, 2)) * g(2, b);
      for (int a = 0; a <= b; ++a)
        for (int k = 0; k < 3; ++k)
          for (int i = 0; i < 3; ++i)
            Ke(3 * a + i, 3 * b + k) +=
                g(0, a) * T(flat(i, 0), k) + g(1, a) * T(flat(i, 1), k) + g(2, a) * T(flat(i, 2), k);
    }
  }
}

}  // namespace

// Force and tangent of the element at loop position `pos` (colour order, see assembly.h).
template <int NPE, int NQP>
void Assembler::tangent_element(const Pass& p, int pos) const {
  const int* n = knodes_.data() + static_cast<std::size_t>(pos) * NPE;
  const double* grad = kgrad_.data() + static_cast<std::size_t>(pos) * NQP * NPE * 3;  // [q][a][3]
  const double* wq = kw_.data() + static_cast<std::size_t>(pos) * NQP;
  std::array<Mat3, NQP> F;
  deformation_gradients<NPE, NQP>(p.u, pos, F);
  for (int q = 0; q < NQP; ++q)
    if (inverted(F[q].determinant())) {
      atomic_min(p.bad, kelem_[pos]);
      return;
    }
  std::array<PointResponse, NQP> resp;
  std::span<const double> s_old;
  std::span<double> s_new;
  element_states(p, pos, s_old, s_new);
  kmat_[pos]->evaluate(F, p.ts, s_old, s_new, resp, true);
  const int e = kelem_[pos];
  Eigen::Matrix<double, 3, NPE> fe = Eigen::Matrix<double, 3, NPE>::Zero();
  double psi = 0.0;
  for (int q = 0; q < NQP; ++q) {
    const Eigen::Map<const Eigen::Matrix<double, 3, NPE>> g(grad + q * NPE * 3);
    const double w = wq[q];
    const Mat3 P = resp[q].P();
    if (!P.allFinite()) {
      atomic_min(p.bad, e);
      return;
    }
    fe.noalias() += w * P * g;
    psi += w * resp[q].psi();
  }
  if (p.elem_energy) p.elem_energy[e] = psi;
  if (p.f_int)
    for (int a = 0; a < NPE; ++a) p.f_int->template segment<3>(3 * n[a]) += fe.col(a);
  // The element stiffness, scattered once.
  Eigen::Matrix<double, 3 * NPE, 3 * NPE> Ke;
  element_stiffness<NPE, NQP>(grad, wq, resp, Ke);
  double* val = p.K->valuePtr();
  for (int b = 0; b < NPE; ++b)
    for (int a = 0; a < NPE; ++a) {
      const int slot = pair_slot_[(static_cast<std::size_t>(pos) * NPE + a) * NPE + b];
      for (int k = 0; k < 3; ++k) {
        double* col = val + col_ptr_[3 * n[b] + k] + 3 * slot;
        for (int i = 0; i < 3; ++i) col[i] += a <= b ? Ke(3 * a + i, 3 * b + k) : Ke(3 * b + k, 3 * a + i);
      }
    }
}

template <int NPE, int NQP>
void Assembler::internal_impl(const Eigen::VectorXd& u, const TimeStep& ts, std::span<const double> state_old,
                              std::span<double> state_new, Eigen::VectorXd* f_int, SparseMatrix* K,
                              double* energy) const {
  const Mesh& mesh = model_.mesh;
  const int ne = mesh.num_elements();
  if (f_int) f_int->setZero(num_dofs());
  if (K) {
    if (K->nonZeros() != col_ptr_.back()) *K = tangent_pattern();
    std::fill(K->valuePtr(), K->valuePtr() + K->nonZeros(), 0.0);
  }
  std::vector<double> elem_energy;
  if (energy) elem_energy.assign(ne, 0.0);
  std::atomic<int> bad{INT_MAX};
  const bool tangent = K != nullptr;
  const Pass pass{u, ts, state_old, state_new, f_int, K, energy ? elem_energy.data() : nullptr, bad, state_size() > 0};

  // Tasks of 10 us or more: one costs ~0.5 us to schedule, and a linear tet's force only ~50 ns
  // (64-element tasks made the two-thread Tet4 force ~5 % slower than 256-element ones).
  const int grain = !tangent && NQP == 1 ? 256 : 64;
  for (std::size_t c = 0; c + 1 < colour_ptr_.size(); ++c) {
    tbb::parallel_for(tbb::blocked_range<int>(colour_ptr_[c], colour_ptr_[c + 1], grain), [&](const tbb::blocked_range<int>& r) {
      if (!tangent) {
        force_range<NPE, NQP>(pass, r.begin(), r.end());
        return;
      }
      for (int i = r.begin(); i < r.end(); ++i) tangent_element<NPE, NQP>(pass, i);
    });
  }
  if (bad.load() != INT_MAX) {
    const int e = bad.load();
    std::ostringstream s;
    s << mesh.element_label(e) << " inverted or produced a non-finite stress (det F <= 0) at t = " << ts.time_s
      << " s. Hint: the load step is too large or the actuator is past its ballooning limit; "
         "reduce the step (explicit: smaller dt_safety; static: smaller max_increment), refine the "
         "mesh near this element, or check its material constants.";
    throw PhysicsError(s.str(), e, ts.time_s);
  }
  // ---- Membranes (engine/membrane.h): serial, after the coloured loop ----------------------
  double membrane_energy = 0.0;
  if (!model_.membranes.empty())
    add_membranes<NPE == 4 ? 3 : 6>(u, ts, f_int, K, energy ? &membrane_energy : nullptr);
  // ---- end membranes ---------------------------------------------------------------------------
  if (energy) {
    double sum = 0.0;
    for (double v : elem_energy) sum += v;  // serial: deterministic
    *energy = sum + membrane_energy;
  }
}

template <int NPF>
void Assembler::add_membranes(const Eigen::VectorXd& u, const TimeStep& ts, Eigen::VectorXd* f_int, SparseMatrix* K,
                              double* energy) const {
  Eigen::Matrix<double, 3, NPF> ue, fe;
  Eigen::Matrix<double, 3 * NPF, 3 * NPF> Ke;
  for (std::size_t s = 0; s < model_.membranes.size(); ++s) {
    const MembraneSet& ms = model_.membranes[s];
    const MembraneGeometry& g = mgeom_[s];
    for (int t = 0; t < g.num_triangles(); ++t) {
      const int* n = ms.nodes.data() + static_cast<std::size_t>(t) * NPF;
      for (int a = 0; a < NPF; ++a) ue.col(a) = u.template segment<3>(3 * n[a]);
      double W = 0.0;
      if (!membrane_triangle<NPF>(ms, g, t, ue, W, fe, K ? &Ke : nullptr)) {
        std::ostringstream msg;
        msg << "membrane '" << ms.name << "' triangle " << t + 1 << " (first node " << model_.mesh.node_name(n[0])
            << ") collapsed or produced a non-finite stress at t = " << ts.time_s
            << " s. Hint: the load step is too large; reduce it (static: smaller max_increment) or check the "
               "membrane's thickness and constants.";
        throw PhysicsError(msg.str(), -1, ts.time_s);
      }
      if (energy) *energy += W;
      if (f_int)
        for (int a = 0; a < NPF; ++a) f_int->template segment<3>(3 * n[a]) += fe.col(a);
      if (!K) continue;
      double* val = K->valuePtr();
      const std::uint16_t* slot = mslot_[s].data() + static_cast<std::size_t>(t) * NPF * NPF;
      for (int b = 0; b < NPF; ++b)
        for (int a = 0; a < NPF; ++a)
          for (int k = 0; k < 3; ++k) {
            double* col = val + col_ptr_[3 * n[b] + k] + 3 * slot[a * NPF + b];
            for (int i = 0; i < 3; ++i) col[i] += Ke(3 * a + i, 3 * b + k);
          }
    }
  }
}

std::vector<double> Assembler::history_scalars(std::span<const double> state) const {
  const int ne = model_.mesh.num_elements();
  std::vector<double> out(static_cast<std::size_t>(ne) * geom_.nqp * 2, 0.0);
  for (int e = 0; e < ne; ++e) {
    const Material& mat = model_.material_of(e);
    const std::size_t ss = static_cast<std::size_t>(mat.state_size());
    if (ss == 0) continue;
    for (int q = 0; q < geom_.nqp; ++q) {
      const PointFields f = mat.fields(state.subspan(state_offset_[e] + q * ss, ss));
      const std::size_t i = 2 * (static_cast<std::size_t>(e) * geom_.nqp + q);
      out[i] = f.fatigue_damage;
      out[i + 1] = f.viscous_strain;
    }
  }
  return out;
}

std::vector<double> Assembler::linear_drives(std::span<const double> state) const {
  const int ne = model_.mesh.num_elements();
  std::vector<double> out(static_cast<std::size_t>(ne) * geom_.nqp * 6, 0.0);
  for (int e = 0; e < ne; ++e) {
    const Material& mat = model_.material_of(e);
    const std::size_t ss = static_cast<std::size_t>(mat.state_size());
    if (ss == 0 || mat.linear_drive().terms == 0) continue;
    for (int q = 0; q < geom_.nqp; ++q) {
      const std::size_t i = 6 * (static_cast<std::size_t>(e) * geom_.nqp + q);
      mat.linear_drive_value(state.subspan(state_offset_[e] + q * ss, ss), std::span<double>(out.data() + i, 6));
    }
  }
  return out;
}

Assembler::RegionFailures Assembler::failed_points(std::span<const double> state) const {
  const Mesh& mesh = model_.mesh;
  // A mesh without region tags counts as one region (index 0).
  const bool tagged = !mesh.region_names.empty() && mesh.region.size() == static_cast<std::size_t>(mesh.num_elements());
  RegionFailures r;
  r.failed.assign(tagged ? mesh.region_names.size() : 1, 0);
  r.points.assign(r.failed.size(), 0);
  for (int e = 0; e < mesh.num_elements(); ++e) {
    const Material& mat = model_.material_of(e);
    const std::size_t ss = static_cast<std::size_t>(mat.state_size());
    const std::size_t reg = tagged ? mesh.region[e] : 0;
    r.points[reg] += geom_.nqp;
    if (ss == 0) continue;
    for (int q = 0; q < geom_.nqp; ++q)
      if (mat.fields(state.subspan(state_offset_[e] + q * ss, ss)).failed) ++r.failed[reg];
  }
  return r;
}

void Assembler::build_nonlocal() {
  const Mesh& mesh = model_.mesh;
  const int ne = mesh.num_elements(), nqp = geom_.nqp, npe = mesh.npe();
  nl_element_.assign(ne, 0);
  // One group per (kind, radius): points of the same driver and length are averaged together,
  // across parts (the silicone's regions with their own stiffness scales are one material).
  std::map<std::pair<std::string, double>, int> group_of;
  std::vector<double> radius;
  std::vector<int> element_group(ne, -1);
  for (std::size_t p = 0; p < model_.parts.size(); ++p) {
    const Material::NonlocalSpec spec = model_.parts[p].material->nonlocal();
    if (!(spec.radius_m > 0.0)) continue;
    const auto [it, added] = group_of.emplace(std::make_pair(spec.kind, spec.radius_m), static_cast<int>(radius.size()));
    if (added) radius.push_back(spec.radius_m);
    for (int e = 0; e < ne; ++e)
      if (model_.element_part[e] == static_cast<int>(p)) element_group[e] = it->second;
  }
  if (radius.empty()) return;
  std::vector<NonlocalAverage::Point> points(static_cast<std::size_t>(ne) * nqp);
  const auto rule = tet_rule(mesh.type);
  std::array<double, 10> N{};
  std::array<double, 30> dN{};
  for (int e = 0; e < ne; ++e) {
    if (element_group[e] < 0) continue;
    nl_element_[e] = 1;
    for (int q = 0; q < nqp; ++q) {
      tet_shape(mesh.type, rule[q].xi, rule[q].eta, rule[q].zeta, N.data(), dN.data());
      NonlocalAverage::Point& pt = points[static_cast<std::size_t>(e) * nqp + q];
      for (int a = 0; a < npe; ++a) pt.X += N[a] * mesh.X[mesh.element(e)[a]];
      pt.volume_m3 = geom_.w(e, q);
      pt.group = element_group[e];
    }
  }
  nonlocal_ = std::make_shared<const NonlocalAverage>(points, radius);
}

void Assembler::update_nonlocal(const Eigen::VectorXd& u, std::span<double> state) const {
  if (!nonlocal_) return;
  const Mesh& mesh = model_.mesh;
  const int ne = mesh.num_elements(), nqp = geom_.nqp, npe = mesh.npe();
  std::vector<double> X(static_cast<std::size_t>(ne) * nqp, 0.0), Xbar(X.size(), 0.0);
  auto point_state = [&](int e, int q) {
    const std::size_t ss = static_cast<std::size_t>(model_.material_of(e).state_size());
    return state.subspan(state_offset_[e] + q * ss, ss);
  };
  tbb::parallel_for(0, ne, [&](int e) {
    if (!nl_element_[e]) return;
    const int* n = mesh.element(e);
    for (int q = 0; q < nqp; ++q) {
      const double* g = geom_.grad(e, q);
      Mat3 F = Mat3::Identity();
      for (int a = 0; a < npe; ++a) F += u.segment<3>(3 * n[a]) * Eigen::Map<const Eigen::RowVector3d>(g + 3 * a);
      X[static_cast<std::size_t>(e) * nqp + q] = model_.material_of(e).nonlocal_driver(F, point_state(e, q));
    }
  });
  nonlocal_->average(X, Xbar);
  tbb::parallel_for(0, ne, [&](int e) {
    if (!nl_element_[e]) return;
    for (int q = 0; q < nqp; ++q) {
      const std::size_t i = static_cast<std::size_t>(e) * nqp + q;
      model_.material_of(e).set_nonlocal_driver(point_state(e, q), X[i], Xbar[i]);
    }
  });
}

void Assembler::point_responses(const Eigen::VectorXd& u, int e, std::span<const double> state, std::span<Mat3> F,
                                std::span<PointResponse> out) const {
  const Mesh& mesh = model_.mesh;
  const int npe = mesh.npe();
  const int* n = mesh.element(e);
  for (int q = 0; q < geom_.nqp; ++q) {
    const double* g = geom_.grad(e, q);
    Mat3 Fq = Mat3::Identity();
    for (int a = 0; a < npe; ++a) Fq += u.segment<3>(3 * n[a]) * Eigen::Map<const Eigen::RowVector3d>(g + 3 * a);
    F[q] = Fq;
  }
  const Material& mat = model_.material_of(e);
  std::vector<double> scratch(state.size());
  mat.evaluate(F.first(geom_.nqp), TimeStep{}, state, scratch, out.first(geom_.nqp), false);
}

void Assembler::add_pressure(const Eigen::VectorXd& u, double p, Eigen::VectorXd& f_ext, SparseMatrix* K) const {
  if (p == 0.0 || pface_nodes_.empty()) return;
  const Mesh& mesh = model_.mesh;
  const int npf = nodes_per_face(mesh.type);
  const auto rule = tri_rule();
  const std::size_t nf = model_.pressure_faces.size();
  std::array<double, 6> N{};
  std::array<double, 12> dN{};
  std::array<Eigen::Vector3d, 6> x;
  Eigen::Matrix<double, 18, 18> Kf;
  for (std::size_t f = 0; f < nf; ++f) {
    const int* fn = pface_nodes_.data() + f * npf;
    for (int a = 0; a < npf; ++a) x[a] = mesh.X[fn[a]] + u.segment<3>(3 * fn[a]);
    if (K) Kf.setZero();
    for (const QuadPoint& qp : rule) {
      tri_shape(mesh.type, qp.xi, qp.eta, N.data(), dN.data());
      Eigen::Vector3d xs = Eigen::Vector3d::Zero(), xt = Eigen::Vector3d::Zero();
      for (int a = 0; a < npf; ++a) {
        xs += dN[2 * a] * x[a];
        xt += dN[2 * a + 1] * x[a];
      }
      const Eigen::Vector3d c = xs.cross(xt);  // outward area vector density
      for (int a = 0; a < npf; ++a) f_ext.segment<3>(3 * fn[a]) -= p * qp.w * N[a] * c;
      if (K) {
        const Eigen::Matrix3d Ss = skew(xs), St = skew(xt);
        // d f_a / d x_b = -p w N_a (dN_b/deta [xs]x - dN_b/dxi [xt]x); K_t -= d f_ext/dx
        for (int a = 0; a < npf; ++a)
          for (int b = 0; b < npf; ++b)
            Kf.block<3, 3>(3 * a, 3 * b) += p * qp.w * N[a] * (dN[2 * b + 1] * Ss - dN[2 * b] * St);
      }
    }
    if (!K) continue;
    // Symmetrise: for a closed cavity the assembled load stiffness is symmetric, so this is exact
    // there; for open surfaces it keeps a symmetric (approximate-Newton) tangent.
    const Eigen::Matrix<double, 18, 18> Ks = 0.5 * (Kf + Kf.transpose());
    double* val = K->valuePtr();
    for (int b = 0; b < npf; ++b)
      for (int a = 0; a < npf; ++a) {
        const int* first = adj_.data() + adj_ptr_[fn[b]];
        const int* last = adj_.data() + adj_ptr_[fn[b] + 1];
        const int slot = static_cast<int>(std::lower_bound(first, last, fn[a]) - first);
        for (int k = 0; k < 3; ++k) {
          double* col = val + col_ptr_[3 * fn[b] + k] + 3 * slot;
          for (int i = 0; i < 3; ++i) col[i] += Ks(3 * a + i, 3 * b + k);
        }
      }
  }
}

double Assembler::cavity_volume(const Eigen::VectorXd& u) const {
  const Mesh& mesh = model_.mesh;
  const int npf = nodes_per_face(mesh.type);
  std::array<double, 6> N{};
  std::array<double, 12> dN{};
  double V = 0.0;
  for (std::size_t f = 0; f < model_.pressure_faces.size(); ++f) {
    const int* fn = pface_nodes_.data() + f * npf;
    for (const QuadPoint& qp : tri_rule()) {
      tri_shape(mesh.type, qp.xi, qp.eta, N.data(), dN.data());
      Eigen::Vector3d xq = Eigen::Vector3d::Zero(), xs = Eigen::Vector3d::Zero(), xt = Eigen::Vector3d::Zero();
      for (int a = 0; a < npf; ++a) {
        const Eigen::Vector3d xa = mesh.X[fn[a]] + u.segment<3>(3 * fn[a]);
        xq += N[a] * xa;
        xs += dN[2 * a] * xa;
        xt += dN[2 * a + 1] * xa;
      }
      V -= qp.w * xq.dot(xs.cross(xt)) / 3.0;  // cavity normal = -(solid outward normal)
    }
  }
  return V;
}

void Assembler::add_gravity(Eigen::VectorXd& f_ext, double scale) const {
  const Eigen::Vector3d g = scale * model_.gravity_m_s2;
  if (g.isZero()) return;
  const Mesh& mesh = model_.mesh;
  const auto rule = tet_rule(mesh.type);
  const int npe = mesh.npe();
  std::vector<double> N(npe), dN(3 * npe);
  for (int e = 0; e < mesh.num_elements(); ++e) {
    const double rho = model_.parts[model_.element_part[e]].density_kg_m3;
    const int* n = mesh.element(e);
    for (int q = 0; q < geom_.nqp; ++q) {
      tet_shape(mesh.type, rule[q].xi, rule[q].eta, rule[q].zeta, N.data(), dN.data());
      for (int a = 0; a < npe; ++a) f_ext.segment<3>(3 * n[a]) += rho * geom_.w(e, q) * N[a] * g;
    }
  }
  for (std::size_t s = 0; s < model_.membranes.size(); ++s)  // membranes (engine/membrane.h)
    add_membrane_gravity(model_.membranes[s], mgeom_[s], mesh.type, g, f_ext);
}

void Assembler::apply_constraints(SparseMatrix& K, double diag) const {
  const auto& fixed = model_.fixed;
  for (int c = 0; c < K.outerSize(); ++c)
    for (SparseMatrix::InnerIterator it(K, c); it; ++it)
      if (fixed[it.row()] || fixed[c]) it.valueRef() = (it.row() == c) ? diag : 0.0;
}

void Assembler::zero_fixed(Eigen::VectorXd& v) const {
  for (int i = 0; i < v.size(); ++i)
    if (model_.fixed[i]) v[i] = 0.0;
}

Eigen::VectorXd Assembler::row_abs_sums(const SparseMatrix& K) const {
  Eigen::VectorXd r = Eigen::VectorXd::Zero(K.rows());
  for (int c = 0; c < K.outerSize(); ++c)
    for (SparseMatrix::InnerIterator it(K, c); it; ++it) r[it.row()] += std::abs(it.value());
  return r;
}

}  // namespace pneufem
