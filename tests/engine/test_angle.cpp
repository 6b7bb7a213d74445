// engine/angle.h: the bending angle of a deformed actuator - a rigid rotation's angle, continuous
// past 180 degrees, and a half model's mirrored tip face giving the full face's angle.
#include "engine/angle.h"

#include <cmath>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "tests/engine/test_meshes.h"

namespace pneufem {
namespace {

using testing::box;
using testing::ecoflex;
using testing::single_part_model;

TEST(BendingAngle, RigidRotationsIncludingPast180Degrees) {
  Model model = single_part_model(box(0.02, 0.1, 0.02, 1, 4, 1, ElementType::Tet4), ecoflex());
  model.angle.tip_nodes = testing::nodes_on_plane(model.mesh, 1, 0.1);
  model.angle.fixed_normal_out = Eigen::Vector3d(0, -1, 0);
  model.angle.bend_direction = Eigen::Vector3d(0, 0, -1);
  double prev = 0.0;
  for (double deg = 0.0; deg <= 300.0; deg += 15.0) {
    // Rotate the whole body about x by -deg (tip curls towards -z) plus a translation.
    const double a = -deg * M_PI / 180.0;
    const Eigen::Matrix3d R = Eigen::AngleAxisd(a, Eigen::Vector3d::UnitX()).toRotationMatrix();
    Eigen::VectorXd u(3 * model.mesh.num_nodes());
    for (int i = 0; i < model.mesh.num_nodes(); ++i)
      u.segment<3>(3 * i) = R * model.mesh.X[i] + Eigen::Vector3d(0.01, -0.02, 0.03) - model.mesh.X[i];
    const AngleResult r = bending_angle(model, u);
    prev = unwrap_deg(r.angle_deg, prev);
    EXPECT_NEAR(prev, deg, 1e-9);  // exact up to round-off: planar face, rigid motion
    EXPECT_NEAR(r.plane_rms_m, 0.0, 1e-12);
  }
}

TEST(BendingAngle, HalfModelMirrorGivesSameAngleAsFullFace) {
  Mesh full = box(0.02, 0.1, 0.02, 2, 4, 1, ElementType::Tet4);
  for (auto& X : full.X) X.x() -= 0.01;  // centred in x
  Model model = single_part_model(full, ecoflex());
  model.angle.tip_nodes = testing::nodes_on_plane(model.mesh, 1, 0.1);
  Model half = model;
  half.angle.tip_nodes.clear();
  for (int n : model.angle.tip_nodes)
    if (model.mesh.X[n].x() >= -1e-12) half.angle.tip_nodes.push_back(n);
  half.angle.mirror_axis = 0;
  // A deformation symmetric in x: bend about x with a warped tip.
  Eigen::VectorXd u(3 * model.mesh.num_nodes());
  for (int i = 0; i < model.mesh.num_nodes(); ++i) {
    const Eigen::Vector3d& X = model.mesh.X[i];
    u.segment<3>(3 * i) = Eigen::Vector3d(0.0, -0.2 * X.z() * X.y() / 0.1, 0.2 * X.y() + 5.0 * X.x() * X.x());
  }
  EXPECT_NEAR(bending_angle(half, u).angle_deg, bending_angle(model, u).angle_deg, 1e-9);
  EXPECT_GT(std::abs(bending_angle(model, u).angle_deg), 1.0);
}

}  // namespace
}  // namespace pneufem
