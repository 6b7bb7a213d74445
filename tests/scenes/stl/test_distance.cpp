// scenes/stl/distance.h: the exact signed distance to a closed surface through OpenVDB - negative in
// the solid, positive outside and in a void, exact near plane faces, and no answer far from the surface.
#include "scenes/stl/distance.h"

#include <Eigen/Core>
#include <gtest/gtest.h>

#include "scenes/stl/surface.h"
#include "tests/scenes/stl/test_shapes.h"

namespace pneufem {
namespace {

TEST(SurfaceDistance, ExactSignedDistanceInsideOutsideAndInVoids) {
  TriSurface t = test::tube_surface(0.006, 0.0035, 0.04, 0.003, 24);
  close_and_orient(t);
  const SurfaceDistance d(t, 0.5e-3, 4e-3);
  SurfacePoint sp;
  // In the wall below the bore, 1 mm from the end face y = 0 (the bore is 1.3 mm away, the outside 1.19).
  ASSERT_TRUE(d.nearest(Eigen::Vector3d(0.0, 0.001, -0.0048), sp));
  EXPECT_NEAR(sp.distance, -0.001, 1e-15);  // the end face y = 0 is closest (exact: a plane)
  // Outside beyond the end face, 2 mm.
  ASSERT_TRUE(d.nearest(Eigen::Vector3d(0.0, -0.002, 0.0), sp));
  EXPECT_NEAR(sp.distance, 0.002, 1e-15);
  // In the bore (a void, so positive), 1 mm from its end cap at y = 3 mm.
  ASSERT_TRUE(d.nearest(Eigen::Vector3d(0.0, 0.004, 0.0), sp));
  EXPECT_NEAR(sp.distance, 0.001, 1e-15);
  // Far from the surface: no answer (the caller floods the sign).
  EXPECT_FALSE(d.nearest(Eigen::Vector3d(0.0, 0.02, 0.1), sp));
}

}  // namespace
}  // namespace pneufem
