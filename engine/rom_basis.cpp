// Offline part of the reduced-order model (engine/rom.h): path, correction modes, reference
// operators and the ECSW sampling, all from the elastic reference model and its traced path.
#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <map>
#include <memory>
#include <random>
#include <sstream>

#include <tbb/parallel_for.h>
#include <Eigen/Eigenvalues>

#include "engine/angle.h"
#include "engine/assembly.h"
#include "engine/linear_solver.h"
#include "engine/nnls.h"
#include "engine/path_spline.h"
#include "engine/rom.h"
#include "engine/rom_points.h"
#include "engine/static_solver.h"
#include "engine/tet_element.h"
#include "core/errors.h"

namespace pneufem {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

/// Parts at least `ratio` times stiffer (initial shear modulus) than the softest part: the fabric.
std::vector<char> stiff_parts(const Model& model, double ratio) {
  double soft = std::numeric_limits<double>::infinity();
  for (const Part& p : model.parts) soft = std::min(soft, p.material->initial_shear_modulus());
  std::vector<char> stiff(model.parts.size(), 0);
  for (std::size_t i = 0; i < model.parts.size(); ++i)
    stiff[i] = model.parts[i].material->initial_shear_modulus() >= ratio * soft ? 1 : 0;
  return stiff;
}

Eigen::Vector3d centroid(const Mesh& mesh, int e) {
  const int* n = mesh.element(e);
  return 0.25 * (mesh.X[n[0]] + mesh.X[n[1]] + mesh.X[n[2]] + mesh.X[n[3]]);
}

/// k-means clusters (Lloyd) of the element centroids of `elements`, `k` of them, seeded by farthest
/// points from the element nearest the centroid (deterministic; ties to the lowest index).
std::vector<std::vector<int>> kmeans(const Mesh& mesh, const std::vector<int>& elements, int k) {
  const std::size_t n = elements.size();
  k = std::max(1, std::min<int>(k, static_cast<int>(n)));
  std::vector<Eigen::Vector3d> x(n);
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < n; ++i) mean += (x[i] = centroid(mesh, elements[i]));
  mean /= static_cast<double>(n);
  std::vector<Eigen::Vector3d> c;
  std::size_t first = 0;
  for (std::size_t i = 1; i < n; ++i)
    if ((x[i] - mean).squaredNorm() < (x[first] - mean).squaredNorm()) first = i;
  c.push_back(x[first]);
  std::vector<double> dmin(n, std::numeric_limits<double>::infinity());
  while (static_cast<int>(c.size()) < k) {
    std::size_t far = 0;
    for (std::size_t i = 0; i < n; ++i) {
      dmin[i] = std::min(dmin[i], (x[i] - c.back()).squaredNorm());
      if (dmin[i] > dmin[far]) far = i;
    }
    c.push_back(x[far]);
  }
  std::vector<int> assign(n, 0);
  for (int it = 0; it < 25; ++it) {
    bool moved = false;
    for (std::size_t i = 0; i < n; ++i) {
      int best = 0;
      for (int j = 1; j < k; ++j)
        if ((x[i] - c[j]).squaredNorm() < (x[i] - c[best]).squaredNorm()) best = j;
      if (best != assign[i]) moved = true;
      assign[i] = best;
    }
    std::vector<Eigen::Vector3d> sum(k, Eigen::Vector3d::Zero());
    std::vector<int> cnt(k, 0);
    for (std::size_t i = 0; i < n; ++i) sum[assign[i]] += x[i], ++cnt[assign[i]];
    for (int j = 0; j < k; ++j)
      if (cnt[j] > 0) c[j] = sum[j] / cnt[j];
    if (!moved && it > 0) break;
  }
  std::vector<std::vector<int>> out(k);
  for (std::size_t i = 0; i < n; ++i) out[assign[i]].push_back(elements[i]);
  out.erase(std::remove_if(out.begin(), out.end(), [](const auto& v) { return v.empty(); }), out.end());
  return out;
}

/// Clusters of the soft elements: k-means within each region, about `total` in all, in proportion
/// to the regions' element counts (a softening confined to one region is then a sum of clusters).
std::vector<std::vector<int>> soft_clusters(const Model& model, const std::vector<char>& stiff, int total) {
  const Mesh& mesh = model.mesh;
  std::map<int, std::vector<int>> by_region;
  int soft = 0;
  for (int e = 0; e < mesh.num_elements(); ++e) {
    if (stiff[model.element_part[e]]) continue;
    by_region[mesh.region.empty() ? 0 : mesh.region[e]].push_back(e);
    ++soft;
  }
  std::vector<std::vector<int>> out;
  for (auto& [region, elems] : by_region) {
    const int k = std::max(1, static_cast<int>(std::lround(static_cast<double>(total) * elems.size() / std::max(1, soft))));
    for (auto& c : kmeans(mesh, elems, k)) out.push_back(std::move(c));
  }
  return out;
}

/// The deformation gradients of element e's quadrature points at u and its (elastic) material's
/// response there.
void element_points(const Model& model, const ElementGeometry& geom, int e, const Eigen::VectorXd& u, std::array<Mat3, 4>& F,
                    std::array<PointResponse, 4>& resp) {
  const int npe = geom.npe, nqp = geom.nqp;
  const int* n = model.mesh.element(e);
  for (int q = 0; q < nqp; ++q) {
    const double* g = geom.grad(e, q);
    F[q] = Mat3::Identity();
    for (int a = 0; a < npe; ++a) F[q] += u.segment<3>(3 * n[a]) * Eigen::Map<const Eigen::RowVector3d>(g + 3 * a);
  }
  model.material_of(e).evaluate(std::span<const Mat3>(F.data(), nqp), TimeStep{}, {}, {},
                                std::span<PointResponse>(resp.data(), nqp), false);
}

/// Internal force of element e (3 npe) at u with its (elastic) material, the whole stress and its
/// isochoric part.
void element_force(const Model& model, const ElementGeometry& geom, int e, const Eigen::VectorXd& u, Eigen::VectorXd& f,
                   Eigen::VectorXd& f_iso) {
  const int npe = geom.npe, nqp = geom.nqp;
  std::array<Mat3, 4> F;
  std::array<PointResponse, 4> resp;
  element_points(model, geom, e, u, F, resp);
  f = Eigen::VectorXd::Zero(3 * npe);
  f_iso = Eigen::VectorXd::Zero(3 * npe);
  for (int q = 0; q < nqp; ++q) {
    const double* g = geom.grad(e, q);
    const double w = geom.w(e, q);
    const Mat3 P = resp[q].P(), Pi = resp[q].P_iso;
    for (int a = 0; a < npe; ++a) {
      const Eigen::Map<const Eigen::Vector3d> ga(g + 3 * a);
      f.segment<3>(3 * a) += w * P * ga;
      f_iso.segment<3>(3 * a) += w * Pi * ga;
    }
  }
}

/// The frozen isochoric stress's force of element e at the reference configuration:
/// int B_0^T S_iso(u) dV, S_iso = F^-1 P_iso the isochoric second Piola-Kirchhoff stress at u.
void element_frozen_force(const Model& model, const ElementGeometry& geom, int e, const Eigen::VectorXd& u, Eigen::VectorXd& f) {
  const int npe = geom.npe, nqp = geom.nqp;
  std::array<Mat3, 4> F;
  std::array<PointResponse, 4> resp;
  element_points(model, geom, e, u, F, resp);
  f = Eigen::VectorXd::Zero(3 * npe);
  for (int q = 0; q < nqp; ++q) {
    const Mat3 S = F[q].inverse() * resp[q].P_iso;
    const double* g = geom.grad(e, q);
    const double w = geom.w(e, q);
    for (int a = 0; a < npe; ++a) f.segment<3>(3 * a) += w * S * Eigen::Map<const Eigen::Vector3d>(g + 3 * a);
  }
}

/// K_T = K_int - p H_V at u (the follower load's stiffness included), unconstrained.
SparseMatrix tangent(const Assembler& A, const Eigen::VectorXd& u, double p) {
  SparseMatrix K = A.tangent_pattern();
  std::vector<double> none;
  A.internal(u, TimeStep{}, none, none, nullptr, &K, nullptr);
  Eigen::VectorXd dummy = Eigen::VectorXd::Zero(A.num_dofs());
  A.add_pressure(u, p, dummy, &K);
  return K;
}

/// H_V = d(dV/du)/du at u (symmetrised), and g = dV/du.
SparseMatrix volume_hessian(const Assembler& A, const Eigen::VectorXd& u, Eigen::VectorXd& g) {
  SparseMatrix K = A.tangent_pattern();
  g = Eigen::VectorXd::Zero(A.num_dofs());
  A.add_pressure(u, 1.0, g, &K);  // subtracts H_V from the zero matrix
  return -K;
}

double mass_dot(const Eigen::VectorXd& m, const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  double s = 0.0;
  for (Eigen::Index i = 0; i < m.size(); ++i) s += m[i] * a.segment<3>(3 * i).dot(b.segment<3>(3 * i));
  return s;
}

}  // namespace

/// d(bending angle)/du at u (deg/m), by central differences over the tip nodes' dofs (the only
/// ones the angle reads). Step: 1e-7 of the model's size, far above round-off of the SVD fit and far
/// below the displacement over which the angle is nonlinear.
Eigen::VectorXd rom_detail::angle_gradient(const Model& model, const Eigen::VectorXd& u) {
  Eigen::VectorXd g = Eigen::VectorXd::Zero(u.size());
  Eigen::Vector3d lo = model.mesh.X[0], hi = lo;
  for (const auto& x : model.mesh.X) lo = lo.cwiseMin(x), hi = hi.cwiseMax(x);
  const double step = 1e-7 * (hi - lo).norm();
  Eigen::VectorXd v = u;
  const double a0 = bending_angle(model, u).angle_deg;
  for (int n : model.angle.tip_nodes)
    for (int d = 0; d < 3; ++d) {
      const Eigen::Index i = 3 * n + d;
      v[i] = u[i] + step;
      const double ap = unwrap_deg(bending_angle(model, v).angle_deg, a0);
      v[i] = u[i] - step;
      const double am = unwrap_deg(bending_angle(model, v).angle_deg, a0);
      v[i] = u[i];
      g[i] = (ap - am) / (2.0 * step);
    }
  return g;
}

namespace {

/// Appends to `modes` (mass-orthonormal, unit RMS) up to `count` POD modes of `shapes` after their
/// parts along `modes` are removed. With `normalise`, each shape is scaled to unit mass norm first,
/// so that every shape counts alike; without, the shapes count by size. `left` is set to the relative
/// energy of the projected shapes outside the kept modes.
void pod_append(const std::vector<Eigen::VectorXd>& shapes, const Eigen::VectorXd& mass, int count, double tolerance,
                std::vector<Eigen::VectorXd>& modes, double& left, bool normalise = true) {
  const double m_tot = mass.sum();
  const std::size_t n = shapes.size();
  if (n == 0 || count <= 0) return;
  std::vector<Eigen::VectorXd> x(n);
  tbb::parallel_for(std::size_t(0), n, [&](std::size_t i) {
    x[i] = normalise ? Eigen::VectorXd(shapes[i] / (std::sqrt(mass_dot(mass, shapes[i], shapes[i]) / m_tot) + 1e-300)) : shapes[i];
    for (const Eigen::VectorXd& m : modes) x[i] -= (mass_dot(mass, m, x[i]) / m_tot) * m;
  });
  Eigen::MatrixXd C(static_cast<Eigen::Index>(n), static_cast<Eigen::Index>(n));
  tbb::parallel_for(std::size_t(0), n, [&](std::size_t i) {
    for (std::size_t j = 0; j <= i; ++j)
      C(static_cast<Eigen::Index>(i), static_cast<Eigen::Index>(j)) = C(static_cast<Eigen::Index>(j), static_cast<Eigen::Index>(i)) =
          mass_dot(mass, x[i], x[j]) / m_tot;
  });
  Eigen::SelfAdjointEigenSolver<Eigen::MatrixXd> eig(C);
  const Eigen::VectorXd lam = eig.eigenvalues().reverse();
  const Eigen::MatrixXd vec = eig.eigenvectors().rowwise().reverse();
  const double total = std::max(lam.sum(), 1e-300);
  // Shapes the earlier modes hold already leave only round-off of their energy: nothing to add.
  double before = 0.0;
  for (std::size_t i = 0; i < n; ++i)
    before += normalise ? 1.0 : mass_dot(mass, shapes[i], shapes[i]) / m_tot;
  if (lam.sum() <= 1e-20 * before) return;
  int r = 0;
  left = total;
  while (r < count && r < static_cast<int>(n) && lam[r] > 1e-14 * lam[0] && left > tolerance * total) left -= lam[r++];
  left = std::max(0.0, left / total);
  for (int j = 0; j < r; ++j) {
    Eigen::VectorXd m = Eigen::VectorXd::Zero(mass.size() * 3);
    for (std::size_t i = 0; i < n; ++i) m += vec(static_cast<Eigen::Index>(i), j) * x[i];
    for (const Eigen::VectorXd& prev : modes) m -= (mass_dot(mass, prev, m) / m_tot) * prev;  // round-off
    const double norm = std::sqrt(mass_dot(mass, m, m) / m_tot);
    if (!(norm > 0.0)) break;
    modes.push_back(m / norm);
  }
}

/// Removes from `modes` (mass-orthonormal, unit RMS) their parts along the path's tangents (the
/// columns of dU): the tangents' POD to 1e-6 of their energy is projected out and the modes are
/// orthonormalised again; a mode with less than 1e-3 of its norm left is dropped (it was a tangent).
void project_out_path_tangents(const Eigen::MatrixXd& dU, const Eigen::VectorXd& mass, std::vector<Eigen::VectorXd>& modes) {
  const double m_tot = mass.sum();
  std::vector<Eigen::VectorXd> tangents, tangent_modes;
  for (Eigen::Index k = 0; k < dU.cols(); ++k) tangents.push_back(dU.col(k));
  double left = 0.0;
  pod_append(tangents, mass, static_cast<int>(tangents.size()), 1e-6, tangent_modes, left);
  std::vector<Eigen::VectorXd> kept;
  for (Eigen::VectorXd m : modes) {
    for (const Eigen::VectorXd& t : tangent_modes) m -= (mass_dot(mass, t, m) / m_tot) * t;
    for (const Eigen::VectorXd& k : kept) m -= (mass_dot(mass, k, m) / m_tot) * k;
    const double norm = std::sqrt(mass_dot(mass, m, m) / m_tot);
    if (norm > 1e-3) kept.push_back(m / norm);
  }
  modes = std::move(kept);
}

/// The isochoric part of a material scaled by s (the volumetric part kept): what a damage law's
/// (1 - d) does to the stress.
class IsochoricScaled final : public Material {
 public:
  IsochoricScaled(MaterialPtr base, double s) : base_(std::move(base)), s_(s) {}
  std::string name() const override { return "isochoric_scaled(" + base_->name() + ")"; }
  void evaluate(std::span<const Mat3> F, const TimeStep& step, std::span<const double> so, std::span<double> sn,
                std::span<PointResponse> out, bool tangent) const override {
    base_->evaluate(F, step, so, sn, out, tangent);
    for (PointResponse& r : out) {
      r.psi_iso *= s_;
      r.P_iso *= s_;
      if (tangent) r.A_iso *= s_;
    }
  }
  void stress(StressBatch& b, const TimeStep& step, std::span<const double> so, std::span<double> sn) const override {
    base_->stress(b, step, so, sn);
    for (int l = 0; l < b.n; ++l) {
      b.psi_iso[l] *= s_;
      for (int k = 0; k < 9; ++k) b.P_iso[k][l] *= s_;
    }
  }
  double initial_shear_modulus() const override { return s_ * base_->initial_shear_modulus(); }
  double initial_bulk_modulus() const override { return base_->initial_bulk_modulus(); }

 private:
  MaterialPtr base_;
  double s_;
};

}  // namespace

std::vector<Eigen::VectorXd> softened_states(const Model& reference, const ElasticPathTrace& trace, const std::vector<int>& samples,
                                             int levels, double max_softening, bool verbose, double stiff_modulus_ratio) {
  std::vector<Eigen::VectorXd> out;
  if (levels <= 0) return out;
  const auto t0 = Clock::now();
  const std::vector<char> stiff = stiff_parts(reference, stiff_modulus_ratio);
  Model soft = reference;  // one copy of the mesh; each level only reassigns parts
  const Assembler A0(reference);
  const ElementGeometry& geom = A0.geometry();
  const int ne = reference.mesh.num_elements();
  constexpr int kBins = 16;  // softening levels are binned: one part per bin and original part
  for (int k : samples) {
    const Eigen::VectorXd& uk = trace.u[static_cast<std::size_t>(k)];
    const double pk = trace.p_Pa[static_cast<std::size_t>(k)];
    // Isochoric energy density per soft element (mean over its points).
    std::vector<double> W(static_cast<std::size_t>(ne), 0.0);
    double wmax = 0.0;
    for (int e = 0; e < ne; ++e) {
      if (stiff[reference.element_part[e]]) continue;
      std::array<Mat3, 4> F;
      std::array<PointResponse, 4> resp;
      const int* n = reference.mesh.element(e);
      for (int q = 0; q < geom.nqp; ++q) {
        const double* g = geom.grad(e, q);
        F[q] = Mat3::Identity();
        for (int a = 0; a < geom.npe; ++a) F[q] += uk.segment<3>(3 * n[a]) * Eigen::Map<const Eigen::RowVector3d>(g + 3 * a);
      }
      reference.material_of(e).evaluate(std::span<const Mat3>(F.data(), geom.nqp), TimeStep{}, {}, {},
                                        std::span<PointResponse>(resp.data(), geom.nqp), false);
      for (int q = 0; q < geom.nqp; ++q) W[static_cast<std::size_t>(e)] += resp[q].psi_iso / geom.nqp;
      wmax = std::max(wmax, W[static_cast<std::size_t>(e)]);
    }
    if (!(wmax > 0.0)) continue;
    for (double m : {0.0, 1.0, 4.0}) {
      Eigen::VectorXd u = uk;
      for (int l = 1; l <= levels; ++l) {
        const double s = max_softening * l / levels;
        soft.parts = reference.parts;
        soft.element_part = reference.element_part;
        std::map<std::pair<int, int>, int> part_of;  // (original part, bin) -> new part
        for (int e = 0; e < ne; ++e) {
          const int op = reference.element_part[e];
          if (stiff[op]) continue;
          const double d = s * std::pow(W[static_cast<std::size_t>(e)] / wmax, m);
          const int bin = std::min(kBins, static_cast<int>(std::lround(d / max_softening * kBins)));
          if (bin == 0) continue;
          auto [it, fresh] = part_of.try_emplace({op, bin}, static_cast<int>(soft.parts.size()));
          if (fresh) {
            Part p = reference.parts[static_cast<std::size_t>(op)];
            p.material = std::make_shared<IsochoricScaled>(p.material, 1.0 - max_softening * bin / kBins);
            soft.parts.push_back(p);
          }
          soft.element_part[e] = it->second;
        }
        const Assembler A(soft);
        StaticSolver solver(A);
        const NewtonReport rep = solver.solve(pk, TimeStep{}, {}, {}, u);
        if (!rep.converged || !u.allFinite()) break;  // past the softened structure's limit point
        out.push_back(u);
      }
    }
  }
  if (verbose)
    std::fprintf(stderr, "reduced basis: %zu softened equilibria at %zu samples, %.1f s\n", out.size(), samples.size(), seconds_since(t0));
  return out;
}


namespace {

/// The follower load's second order in q (ReducedBasis::pq, pw). The load per unit pressure,
/// g(u) = dV/du, is a polynomial of degree two in the nodal positions (each face's area vector
/// x_xi x x_eta is bilinear in them, for any fixed quadrature), so
///     g(u + d) = g(u) + H_V(u) d + 1/2 g2[d, d]
/// exactly, with g2 constant, and by polarisation g2[a, b] = g(a + b) - g(a) - g(b) + g(0).
/// The linearised reference carries g(u_el) + H_V(u_el) Phi q; this adds the rest, projected:
/// pq(i, j + r l) = Phi_i^T g2[Phi_j, Phi_l], pw(j + r l, k) = w_k^T g2[Phi_j, Phi_l].
/// Why: a damaged interior wall balloons into the gap (a large local q), and on the story's
/// 15-chamber actuator with the FEM's own states in the basis the reduced model was 0.45 deg off
/// by trial 3 without this term and 0.17 deg with it (bench/results/rom_h6_pressure_order).
/// Cost: r (r + 3) / 2 + 1 assemblies of the pressure load, once.
void pressure_second_order(const Assembler& A, ReducedBasis& B) {
  const int r = B.num_modes();
  const Eigen::Index nd = B.dofs(), ns = B.num_samples();
  auto load = [&](const Eigen::VectorXd& u) {
    Eigen::VectorXd f = Eigen::VectorXd::Zero(nd);
    A.add_pressure(u, 1.0, f, nullptr);
    A.zero_fixed(f);
    return f;
  };
  const Eigen::VectorXd g0 = load(Eigen::VectorXd::Zero(nd));
  std::vector<Eigen::VectorXd> g1(static_cast<std::size_t>(r));
  for (int j = 0; j < r; ++j) g1[static_cast<std::size_t>(j)] = load(B.Phi.col(j));
  B.pq = Eigen::MatrixXd::Zero(r, static_cast<Eigen::Index>(r) * r);
  B.pw = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(r) * r, ns);
  for (int j = 0; j < r; ++j)
    for (int l = j; l < r; ++l) {
      const Eigen::VectorXd v = load(B.Phi.col(j) + B.Phi.col(l)) - g1[static_cast<std::size_t>(j)] - g1[static_cast<std::size_t>(l)] + g0;
      const Eigen::VectorXd pv = B.Phi.transpose() * v;
      const Eigen::RowVectorXd wv = v.transpose() * B.W;
      B.pq.col(j + static_cast<Eigen::Index>(r) * l) = pv;
      B.pq.col(l + static_cast<Eigen::Index>(r) * j) = pv;
      B.pw.row(j + static_cast<Eigen::Index>(r) * l) = wv;
      B.pw.row(l + static_cast<Eigen::Index>(r) * j) = wv;
    }
}

void check_basis_options(const RomBasisOptions& opt) {
  if (opt.clusters < 1 || opt.mode_samples < 1 || opt.max_modes < 1 || !(opt.pod_tolerance > 0.0 && opt.pod_tolerance < 1.0) ||
      !(opt.ecsw_tolerance > 0.0 && opt.ecsw_tolerance < 1.0) || opt.training_fields < 0 || opt.ecsw_blocks < 0 ||
      !(opt.training_softening > 0.0 && opt.training_softening <= 1.0))
    throw InputError("reduced model: basis options out of range (clusters, mode_samples, max_modes >= 1; ecsw_blocks >= 0; "
                     "pod_tolerance and ecsw_tolerance in (0, 1); training_softening in (0, 1])");
}

/// The path's samples in B: pressures, displacements, their angles (unwrapped, strictly increasing)
/// and the spline's slopes in theta.
void set_path_samples(const Model& reference, const ElasticPathTrace& trace, ReducedBasis& B) {
  const int ndof = reference.num_dofs();
  const std::size_t ns = trace.u.size();
  if (ns < 3 || trace.p_Pa.size() != ns) throw InputError("reduced model: the elastic path trace needs at least three samples");
  B.p = trace.p_Pa;
  B.U.resize(ndof, static_cast<Eigen::Index>(ns));
  for (std::size_t k = 0; k < ns; ++k) {
    if (trace.u[k].size() != ndof)
      throw InputError("reduced model: the elastic path trace has " + std::to_string(trace.u[k].size()) + " dof, the model " +
                       std::to_string(ndof));
    B.U.col(static_cast<Eigen::Index>(k)) = trace.u[k];
    const double th = k == 0 ? 0.0 : unwrap_deg(bending_angle(reference, trace.u[k]).angle_deg, B.theta.back());
    if (k > 0 && !(th > B.theta.back()))
      throw InputError("reduced model: the elastic path trace is not increasing in angle at sample " + std::to_string(k));
    B.theta.push_back(th);
  }
  B.dU.resize(ndof, static_cast<Eigen::Index>(ns));
  const std::vector<Eigen::VectorXd> m = spline_slopes<Eigen::VectorXd>(
      B.theta, [&](std::size_t k) { return Eigen::VectorXd(B.U.col(static_cast<Eigen::Index>(k))); });
  for (std::size_t k = 0; k < ns; ++k) B.dU.col(static_cast<Eigen::Index>(k)) = m[k];
}

/// The path samples at which the softening responses are computed: spread evenly along the path in
/// pressure and in angle alike (the mean of the two normalised coordinates). The response shapes
/// change with the load level (a wall's bulge at 5 kPa is not its bulge at 40 kPa, turned), and near
/// a limit point the angle runs ahead of the pressure. Samples chosen by angle alone left the low
/// levels without shapes of their own: a softening of the walls then moved the angle at 5 kPa 14 %
/// too far on a 3-chamber actuator.
std::vector<int> pick_mode_samples(const ReducedBasis& B, int count) {
  const std::size_t ns = B.theta.size();
  std::vector<double> s(ns);
  for (std::size_t k = 0; k < ns; ++k) s[k] = 0.5 * (B.p[k] / B.p.back() + B.theta[k] / B.theta.back());
  std::vector<int> mode_k;
  for (int j = 1; j <= count; ++j) {
    const double target = (j - 0.25) / count;
    std::size_t best = 1;
    for (std::size_t k = 1; k < ns; ++k)
      if (std::abs(s[k] - target) < std::abs(s[best] - target)) best = k;
    if (std::find(mode_k.begin(), mode_k.end(), static_cast<int>(best)) == mode_k.end()) mode_k.push_back(static_cast<int>(best));
  }
  return mode_k;
}

/// Shapes the modes are compressed from: the softening responses and the snapshots' departures
/// from the path, each with the path sample it belongs to (-1: a snapshot's departure).
struct CandidateShapes {
  std::vector<Eigen::VectorXd> shape;
  std::vector<int> sample;
};

/// For each group of elements: the response du = K^-1 f to the sum of its elements' forces `fel`
/// (solver: K factorised, constraints applied), without its part along t (theta's), appended to
/// `out` with `sample`.
void add_group_responses(const Assembler& A, const Model& reference, const LinearSolver& solver,
                         const std::vector<std::vector<int>>& groups, const std::vector<Eigen::VectorXd>& fel, const Eigen::VectorXd& t,
                         int sample, CandidateShapes& out) {
  const Eigen::VectorXd& mass = A.lumped_mass();
  const double tt = mass_dot(mass, t, t);
  const int npe = A.geometry().npe;
  for (const std::vector<int>& group : groups) {
    Eigen::VectorXd f = Eigen::VectorXd::Zero(reference.num_dofs());
    for (int e : group) {
      const int* n = reference.mesh.element(e);
      for (int a = 0; a < npe; ++a) f.segment<3>(3 * n[a]) += fel[static_cast<std::size_t>(e)].segment<3>(3 * a);
    }
    A.zero_fixed(f);
    Eigen::VectorXd du = solver.solve(f);
    A.zero_fixed(du);
    du -= (mass_dot(mass, t, du) / tt) * t;  // the part along the path is theta's
    out.shape.push_back(std::move(du));
    out.sample.push_back(sample);
  }
}

/// The linear responses of the path at each mode sample k to softening one cluster of soft
/// elements, du_c = K_T(theta_k)^-1 f_iso,c(theta_k) (see the header), without their part along the
/// path tangent (theta's). A sample whose tangent cannot be factorised is skipped.
void add_softening_responses(const Assembler& A, const Model& reference, const ReducedBasis& B,
                             const std::vector<std::vector<int>>& clusters, const std::vector<int>& mode_k, bool verbose,
                             CandidateShapes& out) {
  const ElementGeometry& geom = A.geometry();
  for (int k : mode_k) {
    const Eigen::VectorXd uk = B.U.col(k);
    SparseMatrix K = tangent(A, uk, B.p[k]);
    A.apply_constraints(K, 1.0);
    LinearSolver solver;
    if (!solver.factorize(K)) {
      if (verbose) std::fprintf(stderr, "reduced basis: tangent at %.3g kPa not positive definite, sample skipped\n", B.p[k] * 1e-3);
      continue;
    }
    // Per soft element: its isochoric force at the sample.
    std::vector<Eigen::VectorXd> fel(static_cast<std::size_t>(reference.mesh.num_elements()));
    tbb::parallel_for(std::size_t(0), clusters.size(), [&](std::size_t c) {
      Eigen::VectorXd fe;
      for (int e : clusters[c]) element_force(reference, geom, e, uk, fe, fel[static_cast<std::size_t>(e)]);
    });
    add_group_responses(A, reference, solver, clusters, fel, B.dU.col(k), k, out);
  }
}

/// The linear responses of the unloaded actuator to the isochoric stress that the whole soft body
/// (at every path sample) and each cluster of soft elements (at the mode samples) carries on the
/// path, frozen and applied at the reference configuration: du_c = K_T(0)^-1 int B_0^T
/// S_iso,c(theta_k) dV (S_iso = F^-1 P_iso, the second Piola-Kirchhoff stress). Why: a history law that relaxes under load (a Prony series) leaves, after a release in
/// zero time, a frozen stress of the loaded state's pattern (Simo 1987: the overstress jumps by
/// gamma (S_0(F) - S_0(F_n)), so the total holds h_n - gamma S_0(F_n)); the released state is the
/// response of the unloaded body to it, a small self-equilibrated shape no loaded response or
/// softened equilibrium contains. Without it the reduced release found roots far from the FEM's.
void add_release_responses(const Assembler& A, const Model& reference, const ReducedBasis& B,
                           const std::vector<std::vector<int>>& clusters, const std::vector<int>& mode_k, bool verbose,
                           CandidateShapes& out) {
  SparseMatrix K = tangent(A, Eigen::VectorXd::Zero(reference.num_dofs()), 0.0);
  A.apply_constraints(K, 1.0);
  LinearSolver solver;
  if (!solver.factorize(K)) {
    if (verbose) std::fprintf(stderr, "reduced basis: the unloaded tangent is not positive definite, no release responses\n");
    return;
  }
  // The whole soft body's response at every path sample (the frozen stress of a Prony term is the
  // path's stress history weighted by a kernel of time alone: a combination of the whole body's
  // stress fields at all angles), then each cluster's at the mode samples (a damage law weighs that
  // history locally); each sample's element forces computed once for both.
  const std::vector<std::vector<int>> whole(1, [&] {
    std::vector<int> all;
    for (const auto& c : clusters) all.insert(all.end(), c.begin(), c.end());
    return all;
  }());
  const Eigen::VectorXd t = B.dU.col(0);
  CandidateShapes by_cluster;
  for (int k = 1; k < B.num_samples(); ++k) {
    const Eigen::VectorXd uk = B.U.col(k);
    std::vector<Eigen::VectorXd> fel(static_cast<std::size_t>(reference.mesh.num_elements()));
    tbb::parallel_for(std::size_t(0), clusters.size(), [&](std::size_t c) {
      for (int e : clusters[c]) element_frozen_force(reference, A.geometry(), e, uk, fel[static_cast<std::size_t>(e)]);
    });
    add_group_responses(A, reference, solver, whole, fel, t, 0, out);
    if (std::find(mode_k.begin(), mode_k.end(), k) != mode_k.end()) add_group_responses(A, reference, solver, clusters, fel, t, 0, by_cluster);
  }
  out.shape.insert(out.shape.end(), std::make_move_iterator(by_cluster.shape.begin()), std::make_move_iterator(by_cluster.shape.end()));
  out.sample.insert(out.sample.end(), by_cluster.sample.begin(), by_cluster.sample.end());
}

/// Each state's departure from the path point of equal angle (bisection on the path's angle),
/// without its part along the path tangent there.
void add_departures(const Model& reference, const ReducedBasis& B, const Eigen::VectorXd& mass,
                    const std::vector<Eigen::VectorXd>& states, CandidateShapes& out) {
  const int ndof = reference.num_dofs();
  for (const Eigen::VectorXd& u : states) {
    if (u.size() != ndof) throw InputError("reduced model: a snapshot has " + std::to_string(u.size()) + " dof, the model " + std::to_string(ndof));
    const double target = bending_angle(reference, u).angle_deg;
    double lo = B.theta.front(), hi = B.theta.back();
    auto path_at = [&](double th, Eigen::VectorXd* slope) {
      const int k = path_segment_index(B.theta, th);
      const Hermite h((th - B.theta[k]) / (B.theta[k + 1] - B.theta[k]), B.theta[k + 1] - B.theta[k]);
      const Eigen::VectorXd y0 = B.U.col(k), y1 = B.U.col(k + 1), m0 = B.dU.col(k), m1 = B.dU.col(k + 1);
      if (slope) *slope = h.slope(y0, y1, m0, m1);
      return Eigen::VectorXd(h.value(y0, y1, m0, m1));
    };
    for (int it = 0; it < 60; ++it) {
      const double mid = 0.5 * (lo + hi);
      const double a = unwrap_deg(bending_angle(reference, path_at(mid, nullptr)).angle_deg, mid);
      (a < target ? lo : hi) = mid;
    }
    Eigen::VectorXd t;
    Eigen::VectorXd du = u - path_at(0.5 * (lo + hi), &t);
    du -= (mass_dot(mass, t, du) / mass_dot(mass, t, t)) * t;
    if (mass_dot(mass, du, du) <= 0.0) continue;
    out.shape.push_back(std::move(du));
    out.sample.push_back(-1);
  }
}

/// The modes: snapshots first, then the softening responses in what the snapshots leave out. A
/// damaged FEM state holds the local feedback of damage on stretch (a damaged point stretches more,
/// which damages it faster) that no cluster-level softening shape resolves; pooled with the ~300
/// responses at equal weight, its ~20 shapes lost the POD and the fatigue drift of a 3-chamber
/// actuator stayed 8 % short after three trials; taken first, 1 % (docs/theory.md). Sets B.Phi and
/// B.info.pod_energy_left.
void set_modes(const CandidateShapes& shapes, const Eigen::VectorXd& mass, const RomBasisOptions& opt, ReducedBasis& B) {
  std::vector<Eigen::VectorXd> snapshot_shapes, response_shapes, release_shapes;
  for (std::size_t i = 0; i < shapes.shape.size(); ++i)
    (shapes.sample[i] < 0 ? snapshot_shapes : shapes.sample[i] == 0 ? release_shapes : response_shapes).push_back(shapes.shape[i]);
  std::vector<Eigen::VectorXd> modes;
  double left = 0.0;
  if (!snapshot_shapes.empty())
    pod_append(snapshot_shapes, mass, opt.max_modes, opt.pod_tolerance, modes, left, /*normalise=*/false);
  pod_append(response_shapes, mass, opt.max_modes, opt.pod_tolerance, modes, left);
  if (!release_shapes.empty()) {
    double left_release = 0.0;
    pod_append(release_shapes, mass, opt.max_modes, opt.pod_tolerance, modes, left_release);
  }
  if (opt.tangent_free_modes) project_out_path_tangents(B.dU, mass, modes);
  const int r = static_cast<int>(modes.size());
  B.info.pod_energy_left = left;
  B.Phi = Eigen::MatrixXd::Zero(B.dofs(), r);
  for (int j = 0; j < r; ++j) B.Phi.col(j) = modes[static_cast<std::size_t>(j)];
}

/// The reference operators per path sample, from the assembled FEM tangent (the header's E and the
/// theta row's test vector w), the gauge, and the follower load's second order. Returns the share of
/// the path tangent's mass norm squared that the modes hold, lowest and highest over the samples.
std::pair<double, double> set_reference_operators(const Assembler& A, const Model& reference, const RomBasisOptions& opt,
                                                  ReducedBasis& B) {
  const Eigen::Index ndof = B.dofs();
  const std::size_t ns = B.theta.size();
  const int r = B.num_modes();
  const Eigen::VectorXd& mass = A.lumped_mass();
  const double m_tot = mass.sum();
  Eigen::VectorXd unit_load;  // consistent gravity load per unit acceleration (same along x, y, z)
  {
    Model g1 = reference;
    g1.gravity_m_s2 = Eigen::Vector3d::Ones();
    const Assembler Ag(g1);
    Eigen::VectorXd f = Eigen::VectorXd::Zero(ndof);
    Ag.add_gravity(f);
    unit_load = f;
  }
  std::array<Eigen::VectorXd, 3> f_axis;
  for (int d = 0; d < 3; ++d) {
    f_axis[d] = Eigen::VectorXd::Zero(ndof);
    for (int a = 0; a < reference.mesh.num_nodes(); ++a) f_axis[d][3 * a + d] = unit_load[3 * a + d];
  }
  B.V.resize(ns);
  B.dV.resize(ns);
  B.b.resize(r, static_cast<Eigen::Index>(ns));
  B.db.resize(r, static_cast<Eigen::Index>(ns));
  B.c.resize(r, static_cast<Eigen::Index>(ns));
  B.W.resize(ndof, static_cast<Eigen::Index>(ns));
  B.wg.resize(ns);
  B.wa.assign(ns, 0.0);
  B.h.resize(r, static_cast<Eigen::Index>(ns));
  B.gt.resize(3, static_cast<Eigen::Index>(ns));
  B.gauge.resize(r, static_cast<Eigen::Index>(ns));
  B.K.resize(ns);
  B.H.resize(ns);
  B.gq.resize(r, 3);
  for (int d = 0; d < 3; ++d) B.gq.col(d) = B.Phi.transpose() * f_axis[d];
  Eigen::MatrixXd MPhi = B.Phi;
  for (Eigen::Index i = 0; i < ndof; ++i) MPhi.row(i) *= mass[i / 3];
  double tangent_share_lo = 1.0, tangent_share_hi = 0.0;
  for (std::size_t k = 0; k < ns; ++k) {
    const Eigen::Index kk = static_cast<Eigen::Index>(k);
    const Eigen::VectorXd uk = B.U.col(kk), tk = B.dU.col(kk);
    const SparseMatrix KT = tangent(A, uk, B.p[k]);
    Eigen::VectorXd g;
    const SparseMatrix HV = volume_hessian(A, uk, g);
    B.V[k] = A.cavity_volume(uk);
    B.dV[k] = tk.dot(g);
    // The theta row's test vector: the influence vector of the bending angle, w = K_T^-1 grad(angle),
    // normalised so that w^T g = 1 (see the header). Where the tangent cannot be factorised (at the
    // unloaded sample with nothing to bend, or at a limit point) the path tangent u_el' / V'.
    Eigen::VectorXd w = tk / B.dV[k];
    Eigen::VectorXd ga = rom_detail::angle_gradient(reference, uk);
    A.zero_fixed(ga);
    {
      SparseMatrix Kc = KT;
      A.apply_constraints(Kc, 1.0);
      LinearSolver ls;
      if (!opt.galerkin_theta_row && ls.factorize(Kc)) {
        Eigen::VectorXd a = ls.solve(ga);
        A.zero_fixed(a);
        const double ag = a.dot(g);
        if (ag > 0.0 && a.allFinite()) w = a / ag, B.wa[k] = ag;
      }
    }
    B.W.col(kk) = w;
    B.wg[k] = w.dot(g);
    B.b.col(kk) = B.Phi.transpose() * g;
    const Eigen::MatrixXd KPhi = KT * B.Phi, HPhi = HV * B.Phi;
    B.db.col(kk) = HPhi.transpose() * tk;
    B.c.col(kk) = KPhi.transpose() * w;
    B.h.col(kk) = HPhi.transpose() * w;
    B.K[k] = B.Phi.transpose() * KPhi;
    B.H[k] = B.Phi.transpose() * HPhi;
    B.K[k] = 0.5 * (B.K[k] + B.K[k].transpose());
    B.H[k] = 0.5 * (B.H[k] + B.H[k].transpose());
    for (int d = 0; d < 3; ++d) B.gt(d, kk) = w.dot(f_axis[d]);
    B.gauge.col(kk) = MPhi.transpose() * tk;
    // The share of the path tangent's mass norm that the modes hold (Phi^T M Phi = m_tot I): near 1,
    // theta and q would describe the same motion and only the gauge keeps them apart.
    const double tangent_share = B.gauge.col(kk).squaredNorm() / (m_tot * mass_dot(mass, tk, tk));
    tangent_share_lo = std::min(tangent_share_lo, tangent_share);
    tangent_share_hi = std::max(tangent_share_hi, tangent_share);
  }
  if (opt.tangent_free_modes) B.gauge.setZero();  // what is left is the tangents' POD remainder: no gauge
  pressure_second_order(A, B);
  return {tangent_share_lo, tangent_share_hi};
}

/// A state the ECSW weights are trained on.
struct TrainingState {
  Eigen::VectorXd u, t;  // displacement, the theta row's test vector
  double t_scale;        // its RMS size: the theta row in force per metre, as the modes' rows
};

/// The path sample nearest in angle to th (deg).
int nearest_sample(const ReducedBasis& B, double th) {
  int k = path_segment_index(B.theta, th);
  if (std::abs(B.theta[static_cast<std::size_t>(k) + 1] - th) < std::abs(B.theta[static_cast<std::size_t>(k)] - th)) ++k;
  return k;
}

/// The ECSW training states: path samples (the top one and every stride-th below it), path samples
/// plus the response to a random cluster-wise softening field, and the snapshots themselves.
std::vector<TrainingState> ecsw_training_states(const ReducedBasis& B, const Eigen::VectorXd& mass, const Model& reference,
                                                const CandidateShapes& shapes, const std::vector<int>& mode_k,
                                                const std::vector<Eigen::VectorXd>& snapshots, const RomBasisOptions& opt) {
  const std::size_t ns = B.theta.size();
  const double m_tot = mass.sum();
  std::vector<TrainingState> train;
  const std::size_t stride = std::max<std::size_t>(1, (ns + 15) / 16);
  for (std::size_t k = ns - 1;; k -= stride) {  // the top sample and every stride-th below it
    train.push_back({B.U.col(static_cast<Eigen::Index>(k)), B.W.col(static_cast<Eigen::Index>(k)), 0.0});
    if (k <= stride) break;
  }
  std::mt19937_64 rng(20261126);
  std::uniform_real_distribution<double> unif(0.0, opt.training_softening);
  // A field's linear response is capped at training_amplitude of the path's largest RMS
  // displacement: near the limit point the linear response to a 30 % softening would invert
  // elements, a state no run visits.
  const Eigen::VectorXd u_top = B.U.col(static_cast<Eigen::Index>(ns - 1));
  const double cap = opt.training_amplitude * std::sqrt(mass_dot(mass, u_top, u_top) / m_tot);
  Eigen::MatrixXd MPhi = B.Phi;
  for (Eigen::Index i = 0; i < B.dofs(); ++i) MPhi.row(i) *= mass[i / 3];
  for (int k : mode_k) {
    std::vector<std::size_t> idx;
    for (std::size_t i = 0; i < shapes.shape.size(); ++i)
      if (shapes.sample[i] == k) idx.push_back(i);
    if (idx.empty()) continue;
    for (int f = 0; f < opt.training_fields; ++f) {
      Eigen::VectorXd du = Eigen::VectorXd::Zero(B.dofs());
      for (std::size_t i : idx) du += unif(rng) * shapes.shape[i];
      Eigen::VectorXd q = MPhi.transpose() * du / m_tot;
      if (q.norm() > cap) q *= cap / q.norm();
      train.push_back({B.U.col(k) + B.Phi * q, B.W.col(k), 0.0});
    }
  }
  // The snapshots themselves: the states a run with history visits, with the theta row's test
  // vector of the path sample nearest in angle. As among the path samples above, the unloaded
  // sample 0 gives no training state.
  for (const Eigen::VectorXd& u : snapshots) {
    const double th = bending_angle(reference, u).angle_deg;
    const int k = nearest_sample(B, th);
    if (k > 0) train.push_back({u, B.W.col(k), 0.0});
  }
  for (TrainingState& s : train) s.t_scale = std::sqrt(mass_dot(mass, s.t, s.t) / m_tot) + 1e-300;
  return train;
}

/// A state the stiff parts' remainder is trained on: path sample k and correction q.
struct RemainderState {
  int k;
  Eigen::VectorXd q;
  double t_scale;  // RMS size of w_k, as TrainingState::t_scale
};

/// The remainder's training states: every training state off the path, as its nearest path sample
/// (by angle) plus its mass-weighted projection onto the modes.
std::vector<RemainderState> remainder_training_states(const ReducedBasis& B, const Eigen::VectorXd& mass, const Model& reference,
                                                      const std::vector<TrainingState>& train) {
  const double m_tot = mass.sum();
  Eigen::MatrixXd MPhi = B.Phi;
  for (Eigen::Index i = 0; i < B.dofs(); ++i) MPhi.row(i) *= mass[i / 3];
  std::vector<RemainderState> out;
  for (const TrainingState& s : train) {
    const double th = bending_angle(reference, s.u).angle_deg;
    const int k = nearest_sample(B, th);
    const Eigen::VectorXd q = MPhi.transpose() * (s.u - B.U.col(k)) / m_tot;
    if (k == 0 || q.norm() == 0.0) continue;
    const Eigen::VectorXd wk = B.W.col(k);
    out.push_back({k, q, std::sqrt(mass_dot(mass, wk, wk) / m_tot) + 1e-300});
  }
  return out;
}

/// The NNLS fit of ECSW: G holds, per training state s and generalised coordinate c (row
/// s * ncomp + c), each element's contribution (one column per element of `el`); the target is the
/// whole cluster's (the row sums). A training state that inverts an element says nothing about
/// it: its rows are dropped. Every coordinate counts alike, relative to its own size over the
/// training states: the theta row, which sets the angle, is then fitted as well as any mode's, not
/// drowned by the sixteen of them. Returns the picked (element, weight) pairs and the relative
/// residual.
std::vector<std::pair<int, double>> ecsw_fit(Eigen::MatrixXd& G, int ncomp, const std::vector<int>& el, double tolerance,
                                             double& residual) {
  const Eigen::Index rows = G.rows();
  const std::size_t nt = static_cast<std::size_t>(rows / ncomp);
  for (Eigen::Index row = 0; row < rows; ++row)
    if (!G.row(row).allFinite()) G.row(row).setZero();
  Eigen::VectorXd target = G.rowwise().sum();
  for (int comp = 0; comp < ncomp; ++comp) {
    double ss = 0.0;
    for (std::size_t s = 0; s < nt; ++s) ss += std::pow(target[static_cast<Eigen::Index>(s * ncomp + comp)], 2);
    const double scale = std::sqrt(ss / static_cast<double>(std::max<std::size_t>(nt, 1)));
    if (!(scale > 0.0)) continue;
    for (std::size_t s = 0; s < nt; ++s) {
      const Eigen::Index row = static_cast<Eigen::Index>(s * ncomp + comp);
      G.row(row) /= scale;
      target[row] /= scale;
    }
  }
  // A block of many elements in the normal-equations form: its cost grows with the picked
  // elements, not with the rows times their cube (nnls_normal). Small blocks keep the QR form.
  constexpr Eigen::Index kNormalFormColumns = 256;
  NnlsResult res;
  if (G.cols() > kNormalFormColumns) {
    Eigen::MatrixXd GtG = Eigen::MatrixXd::Zero(G.cols(), G.cols());
    GtG.selfadjointView<Eigen::Lower>().rankUpdate(G.transpose());
    GtG.triangularView<Eigen::StrictlyUpper>() = GtG.transpose();
    res = nnls_normal(GtG, G.transpose() * target, target.squaredNorm(), tolerance);
  } else {
    res = nnls(G, target, tolerance);
  }
  residual = res.residual / std::max(target.norm(), 1e-300);
  std::vector<std::pair<int, double>> picked;
  for (std::size_t j = 0; j < el.size(); ++j)
    if (res.x[static_cast<Eigen::Index>(j)] > 0.0) picked.push_back({el[j], res.x[static_cast<Eigen::Index>(j)]});
  return picked;
}

/// ECSW in one cluster: non-negative element weights that reproduce the cluster's reduced force
/// (theta row and every mode, of the whole and of the isochoric force) on the training states
/// within the tolerance (ecsw_fit).
std::vector<std::pair<int, double>> ecsw_cluster_weights(const Model& reference, const ElementGeometry& geom, const ReducedBasis& B,
                                                         const std::vector<int>& el, const std::vector<TrainingState>& train,
                                                         double tolerance, double& residual) {
  const int r = B.num_modes(), n1 = r + 1;
  const std::size_t nt = train.size();
  const Eigen::Index rows = static_cast<Eigen::Index>(nt * 2 * n1);
  Eigen::MatrixXd G(rows, static_cast<Eigen::Index>(el.size()));
  Eigen::VectorXd fe, fi;
  for (std::size_t j = 0; j < el.size(); ++j) {
    const int e = el[j];
    const int* n = reference.mesh.element(e);
    for (std::size_t s = 0; s < nt; ++s) {
      element_force(reference, geom, e, train[s].u, fe, fi);
      for (int blk = 0; blk < 2; ++blk) {
        const Eigen::VectorXd& f = blk == 0 ? fe : fi;
        const Eigen::Index row = static_cast<Eigen::Index>((s * 2 + blk) * n1);
        double gth = 0.0;
        Eigen::VectorXd gq = Eigen::VectorXd::Zero(r);
        for (int a = 0; a < geom.npe; ++a) {
          gth += train[s].t.segment<3>(3 * n[a]).dot(f.segment<3>(3 * a));
          for (int m = 0; m < r; ++m) gq[m] += B.Phi.col(m).segment<3>(3 * n[a]).dot(f.segment<3>(3 * a));
        }
        G(row, static_cast<Eigen::Index>(j)) = gth / train[s].t_scale;
        G.block(row + 1, static_cast<Eigen::Index>(j), r, 1) = gq;
      }
    }
  }
  return ecsw_fit(G, 2 * n1, el, tolerance, residual);
}

/// Clusters of the stiff elements (the fabric): k-means within each region, about `total` / 4 in
/// all (at least one per region).
std::vector<std::vector<int>> stiff_clusters(const Model& model, const std::vector<char>& stiff, int total) {
  const Mesh& mesh = model.mesh;
  std::map<int, std::vector<int>> by_region;
  for (int e = 0; e < mesh.num_elements(); ++e)
    if (stiff[model.element_part[e]]) by_region[mesh.region.empty() ? 0 : mesh.region[e]].push_back(e);
  std::vector<std::vector<int>> out;
  const int k = std::max(1, total / 4 / std::max<int>(1, static_cast<int>(by_region.size())));
  for (auto& [region, elems] : by_region)
    for (auto& c : kmeans(mesh, elems, std::min<int>(k, static_cast<int>(elems.size())))) out.push_back(std::move(c));
  return out;
}

/// ECSW of the stiff elements on what the bracket integrates for them: the remainder of their
/// force beyond its linearisation about the path sample k,
///     f_e(U_k + Phi q) - f_e(U_k) - K_e(U_k) Phi q,
/// tested with [w_k, Phi] (K_e Phi q by a central difference: the remainder is second order in q,
/// the difference's error third order, 1e-4 of it at the step below). The reference's quadrature
/// (G_hat_ref, K_hat_ref) uses the same weights, so the bracket of a stiff part is exactly the
/// weighted sum of these remainders. Fitted as the soft parts' (ecsw_fit).
std::vector<std::pair<int, double>> ecsw_remainder_weights(const Model& reference, const ElementGeometry& geom, const ReducedBasis& B,
                                                           const std::vector<int>& el, const std::vector<RemainderState>& train,
                                                           double tolerance, double& residual) {
  const int r = B.num_modes(), n1 = r + 1;
  const std::size_t nt = train.size();
  Eigen::MatrixXd G(static_cast<Eigen::Index>(nt * n1), static_cast<Eigen::Index>(el.size()));
  Eigen::VectorXd f, fp, fm, fi;
  constexpr double eps = 1e-2;  // relative to q: the remainder is O(|q|^2), the difference's error O(eps^2 |q|^3)
  for (std::size_t s = 0; s < nt; ++s) {  // states outside: the three displacements once per state
    const Eigen::VectorXd d = B.Phi * train[s].q;
    const Eigen::VectorXd u = B.U.col(train[s].k) + d, up = B.U.col(train[s].k) + eps * d, um = B.U.col(train[s].k) - eps * d;
    const Eigen::Index row = static_cast<Eigen::Index>(s * n1);
    for (std::size_t j = 0; j < el.size(); ++j) {
      const int e = el[j];
      const int* n = reference.mesh.element(e);
      element_force(reference, geom, e, u, f, fi);
      element_force(reference, geom, e, up, fp, fi);
      element_force(reference, geom, e, um, fm, fi);
      const Eigen::VectorXd rem = f - (fp + fm) * 0.5 - (fp - fm) / (2.0 * eps);  // f(u+d) - f(u) - K d, f(u) ~ (fp+fm)/2
      double gth = 0.0;
      Eigen::VectorXd gq = Eigen::VectorXd::Zero(r);
      for (int a = 0; a < geom.npe; ++a) {
        gth += B.W.col(train[s].k).segment<3>(3 * n[a]).dot(rem.segment<3>(3 * a));
        for (int m = 0; m < r; ++m) gq[m] += B.Phi.col(m).segment<3>(3 * n[a]).dot(rem.segment<3>(3 * a));
      }
      G(row, static_cast<Eigen::Index>(j)) = gth / train[s].t_scale;
      G.block(row + 1, static_cast<Eigen::Index>(j), r, 1) = gq;
    }
  }
  return ecsw_fit(G, n1, el, tolerance, residual);
}

/// The sampled elements and their weights (B.elements, B.weights, sorted by element): ECSW per
/// cluster, or every soft element at weight 1 without hyper-reduction; and the stiff parts' elements
/// as RomBasisOptions::stiff_parts asks (every one at weight 1, or ECSW on their remainder).
void set_sampled_elements(const Model& reference, const ElementGeometry& geom, const std::vector<std::vector<int>>& softening_clusters,
                          const std::vector<TrainingState>& train, const std::vector<RemainderState>& remainder_train,
                          const RomBasisOptions& opt, ReducedBasis& B) {
  const std::vector<std::vector<int>> clusters =
      opt.ecsw_blocks > 0 ? soft_clusters(reference, B.stiff_part, opt.ecsw_blocks) : softening_clusters;
  std::vector<std::vector<std::pair<int, double>>> picked(clusters.size());
  std::vector<double> cluster_residual(clusters.size(), 0.0);
  if (!opt.hyper_reduce) {
    for (std::size_t c = 0; c < clusters.size(); ++c)
      for (int e : clusters[c]) picked[c].push_back({e, 1.0});
  } else {
    tbb::parallel_for(std::size_t(0), clusters.size(), [&](std::size_t c) {
      picked[c] = ecsw_cluster_weights(reference, geom, B, clusters[c], train, opt.ecsw_tolerance, cluster_residual[c]);
    });
  }
  std::vector<std::pair<int, double>> all;
  for (std::size_t c = 0; c < clusters.size(); ++c) {
    all.insert(all.end(), picked[c].begin(), picked[c].end());
    B.info.ecsw_worst_residual = std::max(B.info.ecsw_worst_residual, cluster_residual[c]);
  }
  if (opt.stiff_parts == RomBasisOptions::StiffParts::exact)
    for (int e = 0; e < reference.mesh.num_elements(); ++e)
      if (B.stiff_part[reference.element_part[e]]) all.push_back({e, 1.0});
  if (opt.stiff_parts == RomBasisOptions::StiffParts::sampled) {
    const std::vector<std::vector<int>> stiff = stiff_clusters(reference, B.stiff_part, opt.ecsw_blocks > 0 ? 4 * opt.ecsw_blocks : opt.clusters);
    std::vector<std::vector<std::pair<int, double>>> pick(stiff.size());
    std::vector<double> res(stiff.size(), 0.0);
    tbb::parallel_for(std::size_t(0), stiff.size(), [&](std::size_t c) {
      pick[c] = ecsw_remainder_weights(reference, geom, B, stiff[c], remainder_train, opt.ecsw_tolerance, res[c]);
    });
    for (std::size_t c = 0; c < stiff.size(); ++c) {
      all.insert(all.end(), pick[c].begin(), pick[c].end());
      B.info.ecsw_worst_residual = std::max(B.info.ecsw_worst_residual, res[c]);
    }
  }
  std::sort(all.begin(), all.end());
  for (auto [e, w] : all) {
    B.elements.push_back(e);
    B.weights.push_back(w);
  }
}

/// The reference's hyper-reduced force at q = 0 on the fine grid (B.Gref), and its Jacobian per
/// sample (B.Kref).
void set_reference_force(const Model& reference, ReducedBasis& B) {
  const std::size_t ns = B.theta.size();
  const rom_detail::KeptPoints pts(reference, B);
  const Eigen::VectorXd q0 = Eigen::VectorXd::Zero(B.num_modes());
  const int nsub = ReducedBasis::kRefSub;
  B.Gref.resize(B.num_modes() + 1, static_cast<Eigen::Index>((ns - 1) * (nsub + 1)));
  Eigen::VectorXd g;
  for (std::size_t k = 0; k + 1 < ns; ++k)
    for (int j = 0; j <= nsub; ++j) {
      const double th = B.theta[k] + (B.theta[k + 1] - B.theta[k]) * j / nsub;
      // At j = nsub, theta_{k+1} itself would select segment k + 1: evaluate on segment k's end.
      const double th_eval = j == nsub ? std::nextafter(B.theta[k + 1], B.theta[k]) : th;
      pts.force(th_eval, q0, TimeStep{}, {}, {}, g, nullptr);
      B.Gref.col(static_cast<Eigen::Index>(k * (nsub + 1) + j)) = g;
    }
  B.Kref.resize(ns);
  for (std::size_t k = 0; k < ns; ++k) {
    Eigen::MatrixXd J;
    pts.force(B.theta[k], q0, TimeStep{}, {}, {}, g, &J);
    B.Kref[k] = J;
  }
}

}  // namespace

ReducedBasis build_reduced_basis(const Model& reference, const ElasticPathTrace& trace, const RomBasisOptions& opt,
                                 const std::vector<Eigen::VectorXd>& snapshots) {
  const auto t_start = Clock::now();
  check_basis_options(opt);
  const Assembler A(reference);
  if (A.state_size() != 0 || !reference.gravity_m_s2.isZero())
    throw InputError("reduced model: the reference model must be elastic and without gravity");
  ReducedBasis B;
  set_path_samples(reference, trace, B);
  B.stiff_part = stiff_parts(reference, opt.stiff_modulus_ratio);
  B.mesh_fingerprint = mesh_fingerprint(reference.mesh);
  const Eigen::VectorXd& mass = A.lumped_mass();

  // 1. Correction modes: softening responses at the mode samples, the snapshots' and softened
  // equilibria's departures from the path, and their POD.
  const std::vector<std::vector<int>> clusters = soft_clusters(reference, B.stiff_part, opt.clusters);
  B.info.clusters = static_cast<int>(clusters.size());
  for (const auto& c : clusters) B.info.soft_elements += static_cast<int>(c.size());
  const std::vector<int> mode_k = pick_mode_samples(B, opt.mode_samples);
  std::vector<Eigen::VectorXd> all_snapshots = snapshots;
  if (opt.softened_levels > 0) {
    const std::vector<Eigen::VectorXd> softened = softened_states(reference, trace, mode_k, opt.softened_levels, opt.softened_max,
                                                                  opt.verbose, opt.stiff_modulus_ratio);
    all_snapshots.insert(all_snapshots.end(), softened.begin(), softened.end());
  }
  CandidateShapes shapes;
  add_softening_responses(A, reference, B, clusters, mode_k, opt.verbose, shapes);
  if (opt.release_responses) add_release_responses(A, reference, B, clusters, mode_k, opt.verbose, shapes);
  add_departures(reference, B, mass, all_snapshots, shapes);
  if (shapes.shape.empty())
    throw PhysicsError("reduced model: no tangent along the elastic path could be factorised (the path may start at a limit "
                       "point); check the model with pneufem simulate");
  B.info.responses = static_cast<int>(shapes.shape.size());
  set_modes(shapes, mass, opt, B);
  if (opt.verbose) {
    const auto n_snap = static_cast<std::size_t>(std::count(shapes.sample.begin(), shapes.sample.end(), -1));
    std::fprintf(stderr, "reduced basis: %d clusters, %zu responses at %zu samples, %zu snapshots, %d modes (energy left %.2e), %.1f s\n",
                 B.info.clusters, shapes.shape.size() - n_snap, mode_k.size(), n_snap, B.num_modes(), B.info.pod_energy_left,
                 seconds_since(t_start));
  }

  // 2. Reference operators per path sample (from the assembled FEM tangent).
  const auto [share_lo, share_hi] = set_reference_operators(A, reference, opt, B);
  if (opt.verbose) {
    std::fprintf(stderr, "reduced basis: the modes hold %.3g-%.3g of the path tangent's mass norm squared\n", share_lo, share_hi);
    std::fprintf(stderr, "reduced basis: operators at %zu samples, %.1f s\n", B.theta.size(), seconds_since(t_start));
  }

  // 3. ECSW: per cluster, non-negative element weights reproducing the cluster's reduced force on
  // training states (path samples, and path samples plus the response to a random softening field).
  const std::vector<TrainingState> train = ecsw_training_states(B, mass, reference, shapes, mode_k, all_snapshots, opt);
  shapes = CandidateShapes{};
  const std::vector<RemainderState> remainder_train = opt.stiff_parts == RomBasisOptions::StiffParts::sampled
                                                          ? remainder_training_states(B, mass, reference, train)
                                                          : std::vector<RemainderState>{};
  set_sampled_elements(reference, A.geometry(), clusters, train, remainder_train, opt, B);
  if (opt.verbose)
    std::fprintf(stderr, "reduced basis: ECSW kept %zu elements (soft and stiff) of %d soft (%zu training states, worst block residual %.2e), %.1f s\n",
                 B.elements.size(), B.info.soft_elements, train.size(), B.info.ecsw_worst_residual, seconds_since(t_start));

  // 4. The reference's hyper-reduced force at q = 0 on the fine grid, and its Jacobian per sample.
  set_reference_force(reference, B);
  B.info.build_s = seconds_since(t_start);
  if (opt.verbose) std::fprintf(stderr, "reduced basis: done in %.1f s\n", B.info.build_s);
  return B;
}

}  // namespace pneufem
