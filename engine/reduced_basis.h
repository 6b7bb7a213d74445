#pragma once
// The offline part of the reduced-order model as plain data (engine/rom.h explains every member):
// the elastic path's samples, the correction modes, the reference operators per sample and the
// hyper-reduction's sampled elements and weights. Built by build_reduced_basis (engine/rom.h,
// engine/rom_basis.cpp), stored with its exact bits by the result cache (app/result_cache.h).
#include <vector>

#include <Eigen/Core>

#include "engine/mesh.h"

namespace pneufem {

/// The offline part of a reduced model: everything computed from the elastic reference model and its
/// path. Plain data; to_doubles / from_doubles store it with its exact bits (app/result_cache.h).
struct ReducedBasis {
  // The path: samples theta_k (deg), p_k (Pa), displacements U (dofs x ns) and their spline slopes dU.
  std::vector<double> theta, p;
  Eigen::MatrixXd U, dU;
  Eigen::MatrixXd Phi;            ///< correction modes (dofs x r)
  // Reference operators per path sample (see the header comment).
  Eigen::MatrixXd W;              ///< dofs x ns: the theta row's test vector w (below), per sample
  std::vector<double> V, dV;      ///< cavity volume (m^3) and V' = u_el'^T g
  std::vector<double> wg;         ///< w^T g (1 where w is the angle's influence vector)
  std::vector<double> wa;         ///< g^T K_T^-1 grad(angle) (deg/m^3): K_T^-1 grad(angle) = wa w; 0 where w is u_el'/V'
  Eigen::MatrixXd b, db, c, h;    ///< r x ns: b = Phi^T g, db = Phi^T H_V u_el' (= b'), c = Phi^T K_T w, h = Phi^T H_V w
  std::vector<Eigen::MatrixXd> K, H;  ///< r x r per sample
  Eigen::MatrixXd gt;             ///< 3 x ns: w^T f_g per unit acceleration along x, y, z
  Eigen::MatrixXd gq;             ///< r x 3: Phi^T f_g per unit acceleration
  Eigen::MatrixXd gauge;          ///< r x ns: Phi^T M u_el' (q is kept orthogonal to it); all zero: no gauge (tangent_free_modes)
  // Hyper-reduction: sampled elements and their ECSW weights; the reference's hyper-reduced force at
  // q = 0 on a fine grid of every segment (kRefSub + 1 points each) and its q-Jacobian per sample.
  std::vector<int> elements;
  std::vector<double> weights;
  static constexpr int kRefSub = 64;
  Eigen::MatrixXd Gref;           ///< (r + 1) x (segments * (kRefSub + 1))
  std::vector<Eigen::MatrixXd> Kref;  ///< (r + 1) x (r + 1) per sample: d G_hat_ref / d(theta, q) at q = 0
  // The follower load's second order in q (constant: the load is quadratic in the positions):
  // pq(i, j + r l) = Phi_i^T g2[Phi_j, Phi_l] and pw(j + r l, k) = w_k^T g2[Phi_j, Phi_l], g2 the
  // second derivative of g = dV/du (see the header comment).
  Eigen::MatrixXd pq;             ///< r x r^2
  Eigen::MatrixXd pw;             ///< r^2 x ns
  std::vector<char> stiff_part;   ///< per part of the reference: 1 = stiff (linear reference only)
  double mesh_fingerprint = 0.0;  ///< mesh_fingerprint() of the reference's mesh
  // What the construction saw (reported in summaries).
  struct Info {
    int clusters = 0, responses = 0, soft_elements = 0;
    double pod_energy_left = 0.0;     ///< relative energy of the responses outside the kept modes
    double ecsw_worst_residual = 0.0; ///< largest relative residual of a cluster's training fit
    double build_s = 0.0;
  } info;

  int num_modes() const { return static_cast<int>(Phi.cols()); }
  int num_samples() const { return static_cast<int>(theta.size()); }
  long dofs() const { return static_cast<long>(U.rows()); }

  std::vector<double> to_doubles() const;
  /// Throws InputError when the data are not a basis (damaged, or of another format version).
  static ReducedBasis from_doubles(const std::vector<double>& d);
};

/// A 52-bit hash of a mesh's node coordinates and connectivity (exact in a double): a basis is
/// only used with the mesh it was built on.
double mesh_fingerprint(const Mesh& mesh);

}  // namespace pneufem
