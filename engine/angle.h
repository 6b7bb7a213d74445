#pragma once
// Bending angle of an actuator: the rotation of the free end face relative to the fixed end face,
// measured in the bending plane (the plane spanned by the fixed face's inward normal n0 and the
// bend direction d), signed positive when the tip curls towards d, and continuous past 180 deg.
//
// The free-face normal n is the normal of the least-squares plane through its deformed nodes
// (smallest singular vector of the centred coordinates); its sign is chosen to agree with the
// rigid best-fit (Kabsch) rotation of the reference face, so no 180 deg flips occur.
// theta = atan2(n . d, n . n0) with n0 = -fixed_normal_out; at rest theta = 0, and theta equals
// 180 deg minus the angle between the two outward face normals while that is below 180 deg
// (the paper's "angle between the normals" convention). Unwrapping along a history uses the
// previous value: the branch closest to it is taken.
#include <vector>

#include <Eigen/Core>

#include "engine/model.h"

namespace pneufem {

struct AngleResult {
  double angle_deg = 0.0;     ///< signed bending angle, wrapped to (-180, 180]
  double plane_rms_m = 0.0;   ///< RMS distance of the tip nodes to their fitted plane
  double out_of_plane_deg = 0.0;  ///< tilt of n out of the bending plane (twist/sideways bend)
  Eigen::Vector3d tip_normal = Eigen::Vector3d::Zero();
};

/// Angle of the deformed configuration u (3 * nodes). Throws InputError when the tip set has
/// fewer than 3 non-collinear nodes.
AngleResult bending_angle(const Model& model, const Eigen::VectorXd& u);

/// Picks the representative of `wrapped_deg` (mod 360) closest to `previous_deg`.
double unwrap_deg(double wrapped_deg, double previous_deg);

}  // namespace pneufem
