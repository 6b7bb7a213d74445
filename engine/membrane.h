#pragma once
// Membrane elements: a thin sheet (the fabric strain-limiting layer) with in-plane stiffness and
// no bending stiffness, carried by triangles on nodes of the solid mesh: Tri3 on Tet4 meshes,
// Tri6 on Tet10 meshes, nodes in face_local_nodes order (corners, then mid-edge nodes of the
// edges (0,1), (1,2), (2,0)). Placed on element faces, a membrane adds no new node pairs to the
// tangent pattern; the Assembler extends the pattern for triangles that are not faces.
//
// Total Lagrangian membrane (the material-description internal force and tangent of Bonet &
// Wood, "Nonlinear Continuum Mechanics for Finite Element Analysis", 2nd ed. 2008, ch. 9, written
// on the surface as in Bonet, Wood, Mahaney & Heywood, CMAME 190 (2000) 579-595). At each
// quadrature point of the reference triangle:
//   T = [T1 T2]      orthonormal basis of the reference tangent plane (3 x 2), T1 along X_xi,
//   g_a = dN_a/dS    shape-function gradient in the local coordinates S = T^T X (2-vector),
//   H = sum_a u_a g_a^T,   F = dx/dS = T + H                   (3 x 2 surface deformation gradient)
//   E = (F^T F - I)/2 = sym(T^T H) + H^T H / 2                 (2 x 2 membrane Green strain;
//                      from H, not F, so small strains keep full relative precision)
//   S = lambda_s tr(E) I + 2 mu E,  lambda_s = E nu / (1 - nu^2),  mu = E / (2 (1 + nu))
//                      (plane-stress St Venant-Kirchhoff: lambda_s = 2 lambda mu / (lambda + 2 mu))
//   energy     W   = t int psi dA,            psi = lambda_s/2 tr(E)^2 + mu E:E
//   force      f_a = t int F S g_a dA
//   tangent    K_ab = t int [ (g_a . S g_b) I  +  B_a^T D B_b ] dA
//     B_a (3 x 3) maps du_a to the Voigt strain variation (dE11, dE22, 2 dE12); its rows are
//     g_a1 F1^T, g_a2 F2^T and g_a1 F2^T + g_a2 F1^T (F1, F2 the columns of F);
//     D = E/(1 - nu^2) [1 nu 0; nu 1 0; 0 0 (1 - nu)/2].
// t is the reference thickness (not updated: the fabric's strains are small). dA is the
// reference area. On a flat straight-sided triangle H is of degree 1 (Tri6) or 0 (Tri3), so E
// and S are of degree <= 2 and psi, F S g_a and both tangent terms of degree <= 4: the 6-point
// degree-4 rule of tri_rule() integrates energy, force and tangent exactly.
//
// Limitations, by design: no bending stiffness, and no wrinkling model: in compression the
// membrane keeps the plane-stress compressive stiffness of the law (a free membrane would
// wrinkle and carry none). Embedded in the silicone, the fabric is mostly in tension.
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "engine/mesh.h"

namespace pneufem {

/// Plane-stress St Venant-Kirchhoff law of a membrane (Pa). Small immutable value type.
class PlaneStressSVK {
 public:
  /// Throws InputError naming the bad constant (E > 0, -1 < nu < 0.5, as the 3-D law).
  PlaneStressSVK(double E_Pa, double nu);
  double youngs_modulus() const { return E_; }
  double poisson_ratio() const { return nu_; }
  double lambda_s() const { return lambda_s_; }
  double mu() const { return mu_; }

  /// psi(E) (J/m^3) and S(E) (Pa) of a 2 x 2 Green strain.
  double psi(const Eigen::Matrix2d& E) const { return 0.5 * lambda_s_ * E.trace() * E.trace() + mu_ * (E.cwiseProduct(E)).sum(); }
  Eigen::Matrix2d S(const Eigen::Matrix2d& E) const {
    return lambda_s_ * E.trace() * Eigen::Matrix2d::Identity() + 2.0 * mu_ * E;
  }
  /// Voigt matrix D (S11, S22, S12) = D (E11, E22, 2 E12).
  Eigen::Matrix3d D() const;

 private:
  double E_, nu_, lambda_s_, mu_;
};

/// A membrane layer: triangles (nodes_per_face(mesh.type) node ids each), thickness, law, density.
struct MembraneSet {
  std::string name;
  std::vector<int> nodes;  ///< per triangle, in face_local_nodes order
  double thickness_m = 0.0;
  PlaneStressSVK law{1.0, 0.0};
  double density_kg_m3 = 1000.0;
};

/// Triangle node lists of element faces (the face_local_nodes order), for a MembraneSet.
std::vector<int> membrane_nodes_of_faces(const Mesh& mesh, std::span<const FaceRef> faces);

/// Reference data of every quadrature point of a membrane set, computed once.
struct MembraneGeometry {
  int npf = 0;                   ///< nodes per triangle (3 or 6)
  int nqp = 0;                   ///< points per triangle
  std::vector<double> dNdS;      ///< [tri][q][a][2], g_a of the header comment
  std::vector<double> tangent;   ///< [tri][q][6], T = [T1 T2] column-major
  std::vector<double> weight;    ///< [tri][q], w_q |X_xi x X_eta| (m^2)
  std::vector<double> area;      ///< [tri] reference area (m^2)

  int num_triangles() const { return static_cast<int>(area.size()); }
  const double* grad(int t, int q) const { return dNdS.data() + (static_cast<std::size_t>(t) * nqp + q) * npf * 2; }
  const double* basis(int t, int q) const { return tangent.data() + (static_cast<std::size_t>(t) * nqp + q) * 6; }
  double w(int t, int q) const { return weight[static_cast<std::size_t>(t) * nqp + q]; }
};

/// Throws InputError naming the set and triangle when a triangle is degenerate.
MembraneGeometry compute_membrane_geometry(const Mesh& mesh, const MembraneSet& set);

/// One triangle: energy W (J), internal force f (3 x NPF, N) and, when K is given, the tangent
/// (3 NPF x 3 NPF, N/m, dof order 3 a + i) for the nodal displacements ue (3 x NPF, m).
/// Returns false (outputs unspecified) when the deformed triangle is degenerate
/// (det(F^T F) <= 0 at a point) or a stress is not finite.
template <int NPF>
bool membrane_triangle(const MembraneSet& set, const MembraneGeometry& g, int tri, const Eigen::Matrix<double, 3, NPF>& ue,
                       double& W, Eigen::Matrix<double, 3, NPF>& f, Eigen::Matrix<double, 3 * NPF, 3 * NPF>* K);
extern template bool membrane_triangle<3>(const MembraneSet&, const MembraneGeometry&, int, const Eigen::Matrix<double, 3, 3>&,
                                          double&, Eigen::Matrix<double, 3, 3>&, Eigen::Matrix<double, 9, 9>*);
extern template bool membrane_triangle<6>(const MembraneSet&, const MembraneGeometry&, int, const Eigen::Matrix<double, 3, 6>&,
                                          double&, Eigen::Matrix<double, 3, 6>&, Eigen::Matrix<double, 18, 18>*);

/// Adds the lumped mass rho t A of every triangle to `mass` (kg per node): Tri3 1/3 per node,
/// Tri6 by HRZ scaling of the consistent-mass diagonal (corners 1/19, mid-edge nodes 16/57).
void add_membrane_lumped_mass(const MembraneSet& set, const MembraneGeometry& g, Eigen::VectorXd& mass);
/// Adds the consistent gravity load rho t int N_a g dA to f_ext (3 per node).
void add_membrane_gravity(const MembraneSet& set, const MembraneGeometry& g, ElementType type,
                          const Eigen::Vector3d& g_m_s2, Eigen::VectorXd& f_ext);

}  // namespace pneufem
