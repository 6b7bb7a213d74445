#include "engine/tet_element.h"

#include <Eigen/LU>
#include <limits>
#include <sstream>

#include "core/errors.h"

namespace pneufem {

namespace {
constexpr double kA = 0.5854101966249685, kB = 0.1381966011250105;
constexpr QuadPoint kTet4Rule[1] = {{0.25, 0.25, 0.25, 1.0 / 6.0}};
// Points given as (xi, eta, zeta) = (L1, L2, L3); L0 = 1 - sum.
constexpr QuadPoint kTet10Rule[4] = {{kB, kB, kB, 1.0 / 24.0},
                                     {kA, kB, kB, 1.0 / 24.0},
                                     {kB, kA, kB, 1.0 / 24.0},
                                     {kB, kB, kA, 1.0 / 24.0}};
// Dunavant (1985) degree-4, 6 points; weights scaled to the reference area 1/2.
constexpr double kW1 = 0.223381589678011 / 2.0, kW2 = 0.109951743655322 / 2.0;
constexpr double kP1a = 0.108103018168070, kP1b = 0.445948490915965;
constexpr double kP2a = 0.816847572980459, kP2b = 0.091576213509771;
constexpr QuadPoint kTriRule[6] = {{kP1b, kP1b, 0, kW1}, {kP1a, kP1b, 0, kW1}, {kP1b, kP1a, 0, kW1},
                                   {kP2b, kP2b, 0, kW2}, {kP2a, kP2b, 0, kW2}, {kP2b, kP2a, 0, kW2}};
constexpr double kMass4[4] = {0.25, 0.25, 0.25, 0.25};
constexpr double kMass10[10] = {1.0 / 36, 1.0 / 36, 1.0 / 36, 1.0 / 36, 4.0 / 27, 4.0 / 27, 4.0 / 27, 4.0 / 27, 4.0 / 27, 4.0 / 27};
}  // namespace

std::span<const QuadPoint> tet_rule(ElementType t) {
  if (t == ElementType::Tet4) return kTet4Rule;
  return kTet10Rule;
}
std::span<const QuadPoint> tri_rule() { return kTriRule; }
std::span<const double> lumped_mass_fractions(ElementType t) {
  if (t == ElementType::Tet4) return kMass4;
  return kMass10;
}

void tet_shape(ElementType t, double xi, double eta, double zeta, double* N, double* dN) {
  const double L[4] = {1.0 - xi - eta - zeta, xi, eta, zeta};
  // dL_i/d(xi, eta, zeta)
  static constexpr double dL[4][3] = {{-1, -1, -1}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  if (t == ElementType::Tet4) {
    for (int a = 0; a < 4; ++a) {
      N[a] = L[a];
      for (int d = 0; d < 3; ++d) dN[3 * a + d] = dL[a][d];
    }
    return;
  }
  for (int a = 0; a < 4; ++a) {
    N[a] = L[a] * (2.0 * L[a] - 1.0);
    for (int d = 0; d < 3; ++d) dN[3 * a + d] = (4.0 * L[a] - 1.0) * dL[a][d];
  }
  static constexpr int E[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};
  for (int k = 0; k < 6; ++k) {
    const int i = E[k][0], j = E[k][1];
    N[4 + k] = 4.0 * L[i] * L[j];
    for (int d = 0; d < 3; ++d) dN[3 * (4 + k) + d] = 4.0 * (dL[i][d] * L[j] + L[i] * dL[j][d]);
  }
}

void tri_shape(ElementType t, double xi, double eta, double* N, double* dN) {
  const double L[3] = {1.0 - xi - eta, xi, eta};
  static constexpr double dL[3][2] = {{-1, -1}, {1, 0}, {0, 1}};
  if (t == ElementType::Tet4) {
    for (int a = 0; a < 3; ++a) {
      N[a] = L[a];
      dN[2 * a] = dL[a][0];
      dN[2 * a + 1] = dL[a][1];
    }
    return;
  }
  for (int a = 0; a < 3; ++a) {
    N[a] = L[a] * (2.0 * L[a] - 1.0);
    for (int d = 0; d < 2; ++d) dN[2 * a + d] = (4.0 * L[a] - 1.0) * dL[a][d];
  }
  static constexpr int E[3][2] = {{0, 1}, {1, 2}, {2, 0}};
  for (int k = 0; k < 3; ++k) {
    const int i = E[k][0], j = E[k][1];
    N[3 + k] = 4.0 * L[i] * L[j];
    for (int d = 0; d < 2; ++d) dN[2 * (3 + k) + d] = 4.0 * (dL[i][d] * L[j] + L[i] * dL[j][d]);
  }
}

ElementGeometry compute_geometry(const Mesh& mesh) {
  ElementGeometry g;
  g.npe = mesh.npe();
  const auto rule = tet_rule(mesh.type);
  g.nqp = static_cast<int>(rule.size());
  const int ne = mesh.num_elements();
  g.dNdX.resize(static_cast<std::size_t>(ne) * g.nqp * g.npe * 3);
  g.weight.resize(static_cast<std::size_t>(ne) * g.nqp);
  g.volume.assign(ne, 0.0);
  std::vector<double> N(g.npe), dN(3 * g.npe);
  for (int e = 0; e < ne; ++e) {
    const int* conn = mesh.element(e);
    for (int q = 0; q < g.nqp; ++q) {
      tet_shape(mesh.type, rule[q].xi, rule[q].eta, rule[q].zeta, N.data(), dN.data());
      Eigen::Matrix3d Jm = Eigen::Matrix3d::Zero();  // dX/dxi
      for (int a = 0; a < g.npe; ++a)
        for (int i = 0; i < 3; ++i)
          for (int d = 0; d < 3; ++d) Jm(i, d) += mesh.X[conn[a]][i] * dN[3 * a + d];
      const double detJ = Jm.determinant();
      if (!(detJ > 0.0)) {
        std::ostringstream s;
        s << mesh.element_label(e) << " has a non-positive Jacobian (det = " << detJ << ") at integration point "
          << q + 1 << ": it is inverted or degenerate in the reference mesh. Check its node order "
             "(Abaqus C3D4/C3D10 convention) and mid-edge node positions.";
        throw InputError(s.str());
      }
      const Eigen::Matrix3d Jinv = Jm.inverse();
      double* out = g.dNdX.data() + (static_cast<std::size_t>(e) * g.nqp + q) * g.npe * 3;
      for (int a = 0; a < g.npe; ++a) {
        const Eigen::RowVector3d r = Eigen::Map<const Eigen::RowVector3d>(&dN[3 * a]) * Jinv;
        for (int d = 0; d < 3; ++d) out[3 * a + d] = r[d];
      }
      g.weight[static_cast<std::size_t>(e) * g.nqp + q] = rule[q].w * detJ;
      g.volume[e] += rule[q].w * detJ;
    }
  }
  return g;
}

Tet10Distortion tet10_distortion(const Mesh& mesh, int e) {
  // The 10 nodes as (xi, eta, zeta) = (L1, L2, L3), in the C3D10 order of mesh.h.
  static constexpr double kNodeAt[10][3] = {{0, 0, 0},     {1, 0, 0},     {0, 1, 0},   {0, 0, 1},     {.5, 0, 0},
                                            {.5, .5, 0},   {0, .5, 0},    {0, 0, .5},  {.5, 0, .5},   {0, .5, .5}};
  static constexpr int kEdge[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};
  const int* conn = mesh.element(e);
  const double straight = 6.0 * corner_volume(mesh, e);  // det J of the straight-sided tetrahedron
  double N[10], dN[30];
  auto scaled_det = [&](const double* at) {
    tet_shape(ElementType::Tet10, at[0], at[1], at[2], N, dN);
    Eigen::Matrix3d Jm = Eigen::Matrix3d::Zero();
    for (int a = 0; a < 10; ++a)
      for (int i = 0; i < 3; ++i)
        for (int d = 0; d < 3; ++d) Jm(i, d) += mesh.X[conn[a]][i] * dN[3 * a + d];
    return Jm.determinant() / straight;
  };
  Tet10Distortion out;
  out.min_scaled_jacobian = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 10; ++a) {
    const double s = scaled_det(kNodeAt[a]);
    if (s < out.min_scaled_jacobian) out = {s, a, 4, 0.0};
  }
  for (const QuadPoint& q : kTet10Rule) {
    const double at[3] = {q.xi, q.eta, q.zeta};
    const double s = scaled_det(at);
    if (s < out.min_scaled_jacobian) out = {s, -1, 4, 0.0};
  }
  for (int k = 0; k < 6; ++k) {
    const Eigen::Vector3d& xi = mesh.X[conn[kEdge[k][0]]];
    const Eigen::Vector3d& xj = mesh.X[conn[kEdge[k][1]]];
    const double offset = (mesh.X[conn[4 + k]] - 0.5 * (xi + xj)).norm() / (xj - xi).norm();
    if (offset > out.mid_node_offset) {
      out.mid_node_offset = offset;
      out.farthest_mid_node = 4 + k;
    }
  }
  return out;
}

}  // namespace pneufem
