#pragma once
// Exact signed distance to a closed, oriented triangle surface near it, accelerated by OpenVDB.
//
// OpenVDB (tools::meshToVolume, Museth 2013) voxelises a narrow band around the surface and, per
// voxel, the index of its closest triangle. The distance at a point p is then the exact distance
// to the closest of the candidate triangles of the voxels around p (Ericson, Real-Time Collision
// Detection, 2005, sec. 5.1.5), and its sign comes from the angle-weighted pseudonormal of the
// closest feature, face, edge or vertex (Baerentzen & Aanaes, IEEE TVCG 11(3), 2005, Theorem 1:
// for a closed manifold, (p - q) . n_pseudo > 0 iff p is outside). OpenVDB's own sign (a flood fill
// from outside) would fill the chambers, voids enclosed by the solid; the pseudonormal does not.
//
// Convention: negative inside the solid (silicone), positive in air and in the voids.
#include <memory>

#include <Eigen/Core>

#include "scenes/stl/surface.h"

namespace pneufem {

struct SurfacePoint {
  double distance = 0.0;        ///< signed, metres (< 0 inside the solid)
  Eigen::Vector3d point;        ///< closest point on the surface
  int face = -1;                ///< its triangle
};

class SurfaceDistance {
 public:
  /// `voxel` (m): the OpenVDB voxel size; `band` (m): the half width of the band in which
  /// nearest() answers. Throws InputError when the band would hold more than ~5e7 voxels.
  SurfaceDistance(const TriSurface& surface, double voxel, double band);
  ~SurfaceDistance();
  SurfaceDistance(const SurfaceDistance&) = delete;
  SurfaceDistance& operator=(const SurfaceDistance&) = delete;

  /// The closest surface point to p when p lies within the band (false otherwise).
  bool nearest(const Eigen::Vector3d& p, SurfacePoint& out) const;
  /// OpenVDB's voxel count of the band (for the report).
  long voxels() const;
  /// The surface it measures to.
  const TriSurface& surface() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace pneufem
