#include "engine/angle.h"

#include <cmath>
#include <numbers>

#include <Eigen/SVD>

#include "core/errors.h"

namespace pneufem {

AngleResult bending_angle(const Model& model, const Eigen::VectorXd& u) {
  const AngleSpec& spec = model.angle;
  std::vector<Eigen::Vector3d> P, Q;  // reference and deformed tip points
  P.reserve(2 * spec.tip_nodes.size());
  Q.reserve(2 * spec.tip_nodes.size());
  for (int n : spec.tip_nodes) {
    const Eigen::Vector3d X = model.mesh.X[n];
    const Eigen::Vector3d x = X + u.segment<3>(3 * n);
    P.push_back(X);
    Q.push_back(x);
    // Half model: add the mirror image so the fit sees the whole face (nodes on the symmetry
    // plane are their own image and are not duplicated, so the fit weights match a full model).
    if (spec.mirror_axis >= 0 && std::abs(X[spec.mirror_axis]) > 1e-9 * (1.0 + X.norm())) {
      Eigen::Vector3d Xm = X, xm = x;
      Xm[spec.mirror_axis] = -Xm[spec.mirror_axis];
      xm[spec.mirror_axis] = -xm[spec.mirror_axis];
      P.push_back(Xm);
      Q.push_back(xm);
    }
  }
  if (P.size() < 3) throw InputError("bending angle: the tip face needs at least 3 nodes (scene key 'tip_set')");
  const double m = static_cast<double>(P.size());
  Eigen::Vector3d cP = Eigen::Vector3d::Zero(), cQ = Eigen::Vector3d::Zero();
  for (std::size_t i = 0; i < P.size(); ++i) {
    cP += P[i];
    cQ += Q[i];
  }
  cP /= m;
  cQ /= m;
  Eigen::MatrixXd Dq(P.size(), 3), Dp(P.size(), 3);
  for (std::size_t i = 0; i < P.size(); ++i) {
    Dq.row(i) = (Q[i] - cQ).transpose();
    Dp.row(i) = (P[i] - cP).transpose();
  }
  // Reference face normal (least squares) oriented like the fixed face's inward normal, i.e.
  // pointing out of the tip in the undeformed state.
  const Eigen::Vector3d n0 = -spec.fixed_normal_out.normalized();
  Eigen::JacobiSVD<Eigen::MatrixXd> svdP(Dp, Eigen::ComputeThinV);
  Eigen::Vector3d N_ref = svdP.matrixV().col(2);
  if (svdP.singularValues()[1] < 1e-12 * std::max(1.0, svdP.singularValues()[0]))
    throw InputError("bending angle: the tip nodes are collinear; 'tip_set' must span the end face");
  if (N_ref.dot(n0) < 0) N_ref = -N_ref;
  // Kabsch rotation reference -> deformed: fixes the sign of the fitted normal.
  const Eigen::Matrix3d H = Dp.transpose() * Dq;
  Eigen::JacobiSVD<Eigen::Matrix3d> svdH(H, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  D(2, 2) = (svdH.matrixV() * svdH.matrixU().transpose()).determinant() < 0 ? -1.0 : 1.0;
  const Eigen::Matrix3d Rk = svdH.matrixV() * D * svdH.matrixU().transpose();
  const Eigen::Vector3d n_rigid = Rk * N_ref;

  Eigen::JacobiSVD<Eigen::MatrixXd> svdQ(Dq, Eigen::ComputeThinV);
  Eigen::Vector3d n = svdQ.matrixV().col(2);
  if (n.dot(n_rigid) < 0) n = -n;

  AngleResult r;
  r.tip_normal = n;
  const double s3 = svdQ.singularValues()[2];
  r.plane_rms_m = s3 / std::sqrt(m);
  // Bending plane basis: n0 (along the actuator) and d (bend direction made orthogonal to n0).
  Eigen::Vector3d d = spec.bend_direction - spec.bend_direction.dot(n0) * n0;
  d.normalize();
  const double c = n.dot(n0), s = n.dot(d);
  r.angle_deg = std::atan2(s, c) * 180.0 / std::numbers::pi;
  const Eigen::Vector3d side = n0.cross(d);
  r.out_of_plane_deg = std::asin(std::clamp(n.dot(side), -1.0, 1.0)) * 180.0 / std::numbers::pi;
  return r;
}

double unwrap_deg(double wrapped, double previous) {
  return wrapped + 360.0 * std::round((previous - wrapped) / 360.0);
}

}  // namespace pneufem
