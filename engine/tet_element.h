#pragma once
// Tetrahedral (Tet4, Tet10) and triangular face (Tri3, Tri6) shape functions and quadrature.
//
// Reference tetrahedron: corners (0,0,0), (1,0,0), (0,1,0), (0,0,1) with barycentric
// L0 = 1 - xi - eta - zeta, L1 = xi, L2 = eta, L3 = zeta; Abaqus node order (mesh.h).
// Tet10 uses the 4-point degree-2 Gauss rule (as CalculiX C3D10), which integrates the
// stiffness of a straight-sided element exactly. Faces use the 6-point degree-4 Dunavant
// rule, exact for the follower-pressure integrand N_a (x_xi x x_eta) on a Tri6 face.
#include <array>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "engine/mesh.h"

namespace pneufem {

struct QuadPoint {
  double xi, eta, zeta, w;
};

/// Volume quadrature rule for the element type (weights sum to 1/6).
std::span<const QuadPoint> tet_rule(ElementType t);
/// Face rule on the reference triangle (xi, eta; weights sum to 1/2).
std::span<const QuadPoint> tri_rule();

/// Shape functions N (n) and derivatives dN/dxi (n x 3) at a reference point.
void tet_shape(ElementType t, double xi, double eta, double zeta, double* N, double* dN);
/// Triangle shape functions (Tri3 or Tri6, matching face_local_nodes order) and dN/d(xi,eta).
void tri_shape(ElementType t, double xi, double eta, double* N, double* dN);

/// Lumped (diagonal) mass fraction of each node of an element: Tet4 1/4 each;
/// Tet10 by HRZ scaling of the consistent-mass diagonal: corners 1/36, mid-edge nodes 4/27.
/// (Row-sum lumping gives negative corner masses for Tet10, which explicit dynamics cannot use.)
std::span<const double> lumped_mass_fractions(ElementType t);

/// Reference-configuration data of every quadrature point, computed once:
/// dN/dX (npe x 3, row-major per point) and the integration weight w * det(dX/dxi) (m^3).
struct ElementGeometry {
  int npe = 0;
  int nqp = 0;
  std::vector<double> dNdX;      ///< [e][q][a][3]
  std::vector<double> weight;    ///< [e][q]
  std::vector<double> volume;    ///< [e] reference volume (m^3)

  const double* grad(int e, int q) const {
    return dNdX.data() + (static_cast<std::size_t>(e) * nqp + q) * npe * 3;
  }
  double w(int e, int q) const { return weight[static_cast<std::size_t>(e) * nqp + q]; }
};

/// Throws InputError naming the element (external id) when a Jacobian is not positive.
ElementGeometry compute_geometry(const Mesh& mesh);

/// How far a quadratic tetrahedron's mid-nodes bend it away from the straight-sided tetrahedron on
/// its corners, which a mesh read from a deck must bound (scenes/inp/reader.cpp).
struct Tet10Distortion {
  /// Smallest Jacobian determinant over the 10 nodes and the 4 integration points, relative to
  /// the straight-sided tetrahedron's: 1 with every mid-node at its edge midpoint, 0 or less where
  /// the element folds over itself (a mid-node a quarter of its edge off the midpoint, along it).
  double min_scaled_jacobian = 1.0;
  int at_node = -1;            ///< local node (0-based) of that minimum; -1 at an integration point
  int farthest_mid_node = 4;   ///< local mid-node (4..9) farthest from its edge's midpoint
  double mid_node_offset = 0;  ///< that distance divided by the edge's length
};

/// The distortion of Tet10 element e, whose corner tetrahedron must have a positive volume.
Tet10Distortion tet10_distortion(const Mesh& mesh, int e);

}  // namespace pneufem
