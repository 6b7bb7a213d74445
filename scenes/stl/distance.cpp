#include "scenes/stl/distance.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <vector>

#include <Eigen/Geometry>
#include <openvdb/openvdb.h>
#include <openvdb/tools/MeshToVolume.h>

#include "core/errors.h"
#include "core/number_text.h"

namespace pneufem {

namespace {

constexpr double kMaxBandVoxels = 5e7;  // ~0.5 GB of float + index voxels with the tree

/// Closest point of triangle (a, b, c) to p and its feature: 0 face, 1..3 vertex a, b, c, 4..6 edge
/// ab, bc, ca (Ericson 2005, ClosestPtPointTriangle, by Voronoi regions).
Eigen::Vector3d closest_on_triangle(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                                    const Eigen::Vector3d& c, int& feature) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return feature = 1, a;
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return feature = 2, b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return feature = 4, a + (d1 / (d1 - d3)) * ab;
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return feature = 3, c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return feature = 6, a + (d2 / (d2 - d6)) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return feature = 5, b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
  const double denom = 1.0 / (va + vb + vc);
  feature = 0;
  return a + ab * (vb * denom) + ac * (vc * denom);
}

}  // namespace

struct SurfaceDistance::Impl {
  const TriSurface& s;
  double voxel;
  std::vector<Eigen::Vector3d> face_n;    ///< unit face normals
  std::vector<Eigen::Vector3d> edge_n;    ///< per face edge k (F[k] -> F[k+1]): n_f + n_neighbour
  std::vector<Eigen::Vector3d> vertex_n;  ///< angle-weighted vertex pseudonormals
  std::vector<std::vector<int>> vertex_faces;
  openvdb::Int32Grid::Ptr index;
  long voxel_count = 0;

  Impl(const TriSurface& surf, double v) : s(surf), voxel(v) {}

  void pseudonormals() {
    const int nf = static_cast<int>(s.F.size());
    face_n.resize(nf);
    vertex_n.assign(s.V.size(), Eigen::Vector3d::Zero());
    vertex_faces.assign(s.V.size(), {});
    for (int f = 0; f < nf; ++f)
      for (int v : s.F[f]) vertex_faces[v].push_back(f);
    std::map<std::pair<int, int>, Eigen::Vector3d> edge_sum;
    for (int f = 0; f < nf; ++f) {
      face_n[f] = s.normal(f);
      for (int k = 0; k < 3; ++k) {
        const int a = s.F[f][k], b = s.F[f][(k + 1) % 3], c = s.F[f][(k + 2) % 3];
        const Eigen::Vector3d u = (s.V[b] - s.V[a]).normalized(), w = (s.V[c] - s.V[a]).normalized();
        vertex_n[a] += std::acos(std::clamp(u.dot(w), -1.0, 1.0)) * face_n[f];
        auto [it, fresh] = edge_sum.try_emplace({std::min(a, b), std::max(a, b)}, Eigen::Vector3d::Zero());
        it->second += face_n[f];
      }
    }
    edge_n.resize(3 * static_cast<std::size_t>(nf));
    for (int f = 0; f < nf; ++f)
      for (int k = 0; k < 3; ++k) {
        const int a = s.F[f][k], b = s.F[f][(k + 1) % 3];
        edge_n[3 * f + k] = edge_sum.at({std::min(a, b), std::max(a, b)});
      }
  }
};

SurfaceDistance::SurfaceDistance(const TriSurface& surface, double voxel, double band)
    : impl_(std::make_unique<Impl>(surface, voxel)) {
  double area = 0.0;
  for (int f = 0; f < static_cast<int>(surface.F.size()); ++f) area += surface.area(f);
  const double band_voxels = std::ceil(band / voxel) + 1.0;
  const double estimate = area / (voxel * voxel) * 2.0 * band_voxels;
  if (estimate > kMaxBandVoxels)
    throw InputError(surface.path + ": the distance band around the surface would hold about " +
                     short_num(std::round(estimate / 1e5) / 10) + " million voxels of " + short_num(voxel * 1e3) +
                     " mm (limit " + short_num(kMaxBandVoxels / 1e6) +
                     " million); use a larger mesh.h_mm (or check mesh.length_unit: a model in metres read as mm is "
                     "1000 times too large)");
  impl_->pseudonormals();

  openvdb::initialize();
  const auto xform = openvdb::math::Transform::createLinearTransform(voxel);
  std::vector<openvdb::Vec3s> points;
  points.reserve(surface.V.size());
  for (const auto& p : surface.V) {
    const openvdb::Vec3d q = xform->worldToIndex(openvdb::Vec3d(p.x(), p.y(), p.z()));
    points.emplace_back(static_cast<float>(q[0]), static_cast<float>(q[1]), static_cast<float>(q[2]));
  }
  std::vector<openvdb::Vec3I> tris;
  tris.reserve(surface.F.size());
  for (const auto& t : surface.F)
    tris.emplace_back(static_cast<unsigned>(t[0]), static_cast<unsigned>(t[1]), static_cast<unsigned>(t[2]));
  const openvdb::tools::QuadAndTriangleDataAdapter<openvdb::Vec3s, openvdb::Vec3I> mesh(points, tris);
  impl_->index = openvdb::Int32Grid::create(-1);
  impl_->index->setTransform(xform);
  const auto dist = openvdb::tools::meshToVolume<openvdb::FloatGrid>(
      mesh, *xform, static_cast<float>(band_voxels), static_cast<float>(band_voxels),
      openvdb::tools::UNSIGNED_DISTANCE_FIELD, impl_->index.get());
  impl_->voxel_count = static_cast<long>(impl_->index->activeVoxelCount());
}

SurfaceDistance::~SurfaceDistance() = default;

long SurfaceDistance::voxels() const { return impl_->voxel_count; }

const TriSurface& SurfaceDistance::surface() const { return impl_->s; }

bool SurfaceDistance::nearest(const Eigen::Vector3d& p, SurfacePoint& out) const {
  const Impl& m = *impl_;
  const auto& tree = m.index->tree();
  const openvdb::Coord c = openvdb::Coord::round(openvdb::Vec3d(p.x(), p.y(), p.z()) / m.voxel);
  int cand[27];
  int n = 0;
  for (int i = -1; i <= 1; ++i)
    for (int j = -1; j <= 1; ++j)
      for (int k = -1; k <= 1; ++k) {
        int f = -1;
        if (tree.probeValue(c.offsetBy(i, j, k), f) && f >= 0 && std::find(cand, cand + n, f) == cand + n) cand[n++] = f;
      }
  if (n == 0) return false;
  double best = std::numeric_limits<double>::infinity();
  int best_f = -1, best_feature = 0;
  Eigen::Vector3d best_q = Eigen::Vector3d::Zero();
  auto consider = [&](int f) {
    const auto& t = m.s.F[f];
    int feature = 0;
    const Eigen::Vector3d q = closest_on_triangle(p, m.s.V[t[0]], m.s.V[t[1]], m.s.V[t[2]], feature);
    const double d2 = (p - q).squaredNorm();
    if (d2 >= best) return false;
    best = d2, best_f = f, best_feature = feature, best_q = q;
    return true;
  };
  for (int i = 0; i < n; ++i) consider(cand[i]);
  // Each voxel stores one closest triangle, that of its centre: when triangles are smaller than
  // voxels, p's own may be missing. Walk to triangles sharing a corner while one is closer (the
  // distance to a closed surface has no local minimum over a connected fan of its triangles).
  for (int step = 0; step < 64; ++step) {
    bool better = false;
    const auto t = m.s.F[best_f];
    for (int v : t)
      for (int f : m.vertex_faces[v]) better = consider(f) || better;
    if (!better) break;
  }
  const auto& t = m.s.F[best_f];
  Eigen::Vector3d pn;
  if (best_feature == 0)
    pn = m.face_n[best_f];
  else if (best_feature <= 3)
    pn = m.vertex_n[t[best_feature - 1]];
  else
    pn = m.edge_n[3 * static_cast<std::size_t>(best_f) + (best_feature - 4)];
  const double d = std::sqrt(best);
  out.distance = (p - best_q).dot(pn) >= 0.0 ? d : -d;
  out.point = best_q;
  out.face = best_f;
  return true;
}

}  // namespace pneufem
