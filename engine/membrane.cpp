#include "engine/membrane.h"

#include <array>
#include <cmath>

#include <Eigen/Geometry>
#include <Eigen/LU>

#include "core/errors.h"
#include "core/number_text.h"
#include "engine/tet_element.h"

namespace pneufem {

PlaneStressSVK::PlaneStressSVK(double E_Pa, double nu) : E_(E_Pa), nu_(nu) {
  if (!(std::isfinite(E_Pa) && E_Pa > 0.0))
    throw InputError("membrane: Young's modulus E must be a finite number > 0, got " + short_num(E_Pa) + " Pa");
  if (!(nu > -1.0 && nu < 0.5))
    throw InputError("membrane: Poisson ratio must lie in (-1, 0.5), got " + short_num(nu));
  lambda_s_ = E_Pa * nu / (1.0 - nu * nu);
  mu_ = E_Pa / (2.0 * (1.0 + nu));
}

Eigen::Matrix3d PlaneStressSVK::D() const {
  Eigen::Matrix3d D;
  D << lambda_s_ + 2.0 * mu_, lambda_s_, 0.0, lambda_s_, lambda_s_ + 2.0 * mu_, 0.0, 0.0, 0.0, mu_;
  return D;
}

std::vector<int> membrane_nodes_of_faces(const Mesh& mesh, std::span<const FaceRef> faces) {
  const int npf = nodes_per_face(mesh.type);
  std::vector<int> nodes;
  nodes.reserve(faces.size() * npf);
  for (const FaceRef& f : faces) {
    const int* ln = face_local_nodes(mesh.type, f.local_face);
    const int* n = mesh.element(f.element);
    for (int a = 0; a < npf; ++a) nodes.push_back(n[ln[a]]);
  }
  return nodes;
}

MembraneGeometry compute_membrane_geometry(const Mesh& mesh, const MembraneSet& set) {
  MembraneGeometry g;
  g.npf = nodes_per_face(mesh.type);
  const auto rule = tri_rule();
  g.nqp = static_cast<int>(rule.size());
  if (set.nodes.size() % g.npf != 0)
    throw InputError("membrane '" + set.name + "': " + std::to_string(set.nodes.size()) +
                     " node ids is not a whole number of triangles of " + std::to_string(g.npf) + " nodes");
  const int nt = static_cast<int>(set.nodes.size()) / g.npf;
  g.dNdS.resize(static_cast<std::size_t>(nt) * g.nqp * g.npf * 2);
  g.tangent.resize(static_cast<std::size_t>(nt) * g.nqp * 6);
  g.weight.resize(static_cast<std::size_t>(nt) * g.nqp);
  g.area.assign(nt, 0.0);
  std::array<double, 6> N{};
  std::array<double, 12> dN{};
  for (int t = 0; t < nt; ++t) {
    const int* n = set.nodes.data() + static_cast<std::size_t>(t) * g.npf;
    for (int a = 0; a < g.npf; ++a)
      if (n[a] < 0 || n[a] >= mesh.num_nodes())
        throw InputError("membrane '" + set.name + "': triangle " + std::to_string(t + 1) +
                         " refers to a node index outside the mesh");
    for (int q = 0; q < g.nqp; ++q) {
      tri_shape(mesh.type, rule[q].xi, rule[q].eta, N.data(), dN.data());
      Eigen::Vector3d G1 = Eigen::Vector3d::Zero(), G2 = Eigen::Vector3d::Zero();  // X_xi, X_eta
      for (int a = 0; a < g.npf; ++a) {
        G1 += dN[2 * a] * mesh.X[n[a]];
        G2 += dN[2 * a + 1] * mesh.X[n[a]];
      }
      const Eigen::Vector3d c = G1.cross(G2);
      const double jac = c.norm();
      if (!(jac > 1e-12 * G1.norm() * G2.norm()))
        throw InputError("membrane '" + set.name + "': triangle " + std::to_string(t + 1) + " (first node " +
                         mesh.node_name(n[0]) +
                         ") is degenerate (zero area at an integration point); check its node order");
      Eigen::Matrix<double, 3, 2> T;
      T.col(0) = G1.normalized();
      T.col(1) = (c / jac).cross(T.col(0));
      // dS/dxi = T^T [G1 G2]; g_a = (dxi/dS)^T dN_a/dxi.
      Eigen::Matrix<double, 3, 2> G;
      G << G1, G2;
      const Eigen::Matrix2d dxi_dS = (T.transpose() * G).inverse();
      double* grad = g.dNdS.data() + (static_cast<std::size_t>(t) * g.nqp + q) * g.npf * 2;
      for (int a = 0; a < g.npf; ++a) {
        const Eigen::Vector2d ga = dxi_dS.transpose() * Eigen::Vector2d(dN[2 * a], dN[2 * a + 1]);
        grad[2 * a] = ga[0];
        grad[2 * a + 1] = ga[1];
      }
      Eigen::Map<Eigen::Matrix<double, 3, 2>>(g.tangent.data() + (static_cast<std::size_t>(t) * g.nqp + q) * 6) = T;
      g.weight[static_cast<std::size_t>(t) * g.nqp + q] = rule[q].w * jac;
      g.area[t] += rule[q].w * jac;
    }
  }
  return g;
}

template <int NPF>
bool membrane_triangle(const MembraneSet& set, const MembraneGeometry& g, int tri, const Eigen::Matrix<double, 3, NPF>& ue,
                       double& W, Eigen::Matrix<double, 3, NPF>& f, Eigen::Matrix<double, 3 * NPF, 3 * NPF>* K) {
  const PlaneStressSVK& law = set.law;
  const Eigen::Matrix3d D = law.D();
  W = 0.0;
  f.setZero();
  if (K) K->setZero();
  for (int q = 0; q < g.nqp; ++q) {
    const Eigen::Map<const Eigen::Matrix<double, 2, NPF>> gq(g.grad(tri, q));  // column a = g_a
    const Eigen::Map<const Eigen::Matrix<double, 3, 2>> T(g.basis(tri, q));
    const double wt = g.w(tri, q) * set.thickness_m;
    const Eigen::Matrix<double, 3, 2> H = ue * gq.transpose();
    const Eigen::Matrix<double, 3, 2> F = T + H;
    const Eigen::Matrix2d TH = T.transpose() * H;
    const Eigen::Matrix2d E = 0.5 * (TH + TH.transpose() + H.transpose() * H);
    if (!((F.transpose() * F).determinant() > 0.0)) return false;
    const Eigen::Matrix2d S = law.S(E);
    if (!S.allFinite()) return false;
    W += wt * law.psi(E);
    f.noalias() += wt * (F * S) * gq;
    if (!K) continue;
    Eigen::Matrix<double, 3, 3 * NPF> B;
    for (int a = 0; a < NPF; ++a) {
      B.template block<1, 3>(0, 3 * a) = gq(0, a) * F.col(0).transpose();
      B.template block<1, 3>(1, 3 * a) = gq(1, a) * F.col(1).transpose();
      B.template block<1, 3>(2, 3 * a) = gq(0, a) * F.col(1).transpose() + gq(1, a) * F.col(0).transpose();
    }
    K->noalias() += wt * B.transpose() * D * B;
    const Eigen::Matrix<double, NPF, NPF> Gs = gq.transpose() * S * gq;  // g_a . S g_b
    for (int b = 0; b < NPF; ++b)
      for (int a = 0; a < NPF; ++a)
        K->template block<3, 3>(3 * a, 3 * b).diagonal().array() += wt * Gs(a, b);
  }
  return true;
}

template bool membrane_triangle<3>(const MembraneSet&, const MembraneGeometry&, int, const Eigen::Matrix<double, 3, 3>&,
                                   double&, Eigen::Matrix<double, 3, 3>&, Eigen::Matrix<double, 9, 9>*);
template bool membrane_triangle<6>(const MembraneSet&, const MembraneGeometry&, int, const Eigen::Matrix<double, 3, 6>&,
                                   double&, Eigen::Matrix<double, 3, 6>&, Eigen::Matrix<double, 18, 18>*);

void add_membrane_lumped_mass(const MembraneSet& set, const MembraneGeometry& g, Eigen::VectorXd& mass) {
  static constexpr double kTri3[3] = {1.0 / 3, 1.0 / 3, 1.0 / 3};
  static constexpr double kTri6[6] = {1.0 / 19, 1.0 / 19, 1.0 / 19, 16.0 / 57, 16.0 / 57, 16.0 / 57};
  const double* frac = g.npf == 3 ? kTri3 : kTri6;
  for (int t = 0; t < g.num_triangles(); ++t) {
    const double m = set.density_kg_m3 * set.thickness_m * g.area[t];
    const int* n = set.nodes.data() + static_cast<std::size_t>(t) * g.npf;
    for (int a = 0; a < g.npf; ++a) mass[n[a]] += frac[a] * m;
  }
}

void add_membrane_gravity(const MembraneSet& set, const MembraneGeometry& g, ElementType type,
                          const Eigen::Vector3d& g_m_s2, Eigen::VectorXd& f_ext) {
  const auto rule = tri_rule();
  std::array<double, 6> N{};
  std::array<double, 12> dN{};
  for (int t = 0; t < g.num_triangles(); ++t) {
    const int* n = set.nodes.data() + static_cast<std::size_t>(t) * g.npf;
    for (int q = 0; q < g.nqp; ++q) {
      tri_shape(type, rule[q].xi, rule[q].eta, N.data(), dN.data());
      for (int a = 0; a < g.npf; ++a)
        f_ext.segment<3>(3 * n[a]) += set.density_kg_m3 * set.thickness_m * g.w(t, q) * N[a] * g_m_s2;
    }
  }
}

}  // namespace pneufem
