#include "scenes/stl/thin_walls.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Geometry>

#include "core/number_text.h"

namespace pneufem {

namespace {

constexpr double kFloor = 1.0 / 8.0;  // smallest cell, a fraction of h (see thin_walls.h)

double axis_h(const StuffingOptions& o, int d) { return d == 2 && o.h_z > 0.0 ? o.h_z : o.h; }

/// Points on triangle f at spacing <= `step` along its two shortest edges (the centres of a
/// lattice on the corner with the largest angle, so there are at most ~2.3 area / step^2 of them).
std::vector<Eigen::Vector3d> triangle_samples(const TriSurface& s, int f, double step) {
  const auto& t = s.F[f];
  int corner = 0;
  double longest = -1.0;
  for (int k = 0; k < 3; ++k) {  // the corner opposite the longest edge
    const double len = (s.V[t[(k + 1) % 3]] - s.V[t[(k + 2) % 3]]).norm();
    if (len > longest) longest = len, corner = k;
  }
  const Eigen::Vector3d a = s.V[t[corner]], e1 = s.V[t[(corner + 1) % 3]] - a, e2 = s.V[t[(corner + 2) % 3]] - a;
  const int m1 = std::max(1, static_cast<int>(std::ceil(e1.norm() / step)));
  const int m2 = std::max(1, static_cast<int>(std::ceil(e2.norm() / step)));
  std::vector<Eigen::Vector3d> out;
  for (int i = 0; i < m1; ++i)
    for (int j = 0; j < m2; ++j) {
      const double u = (i + 0.5) / m1, w = (j + 0.5) / m2;
      if (u + w < 1.0) out.push_back(a + u * e1 + w * e2);
    }
  if (out.empty()) out.push_back(a + (e1 + e2) / 3.0);  // a triangle smaller than the step
  return out;
}

/// Whether x lies on one of the sorted planes (within tol).
bool on_plane(const std::vector<double>& planes, double x, double tol) {
  const auto it = std::lower_bound(planes.begin(), planes.end(), x - tol);
  return it != planes.end() && *it <= x + tol;
}

/// Per-axis bins of width h_d / 32 holding the smallest required cell size; merged into runs.
struct AxisBins {
  double x0 = 0.0, w = 1.0, h = 1.0;
  std::vector<double> size;

  void require(double lo, double hi, double s) {
    const int n = static_cast<int>(size.size());
    const int i0 = std::clamp(static_cast<int>(std::floor((lo - x0) / w)), 0, n - 1);
    const int i1 = std::clamp(static_cast<int>(std::floor((hi - x0) / w)), 0, n - 1);
    for (int i = i0; i <= i1; ++i) size[i] = std::min(size[i], s);
  }

  std::vector<AxisSize> runs() const {
    std::vector<AxisSize> out;
    for (std::size_t i = 0; i < size.size(); ++i) {
      if (!(size[i] < h)) continue;
      if (!out.empty() && out.back().spacing == size[i] && out.back().hi == x0 + w * static_cast<double>(i))
        out.back().hi = x0 + w * static_cast<double>(i + 1);
      else
        out.push_back({x0 + w * static_cast<double>(i), x0 + w * static_cast<double>(i + 1), size[i]});
    }
    return out;
  }
};

}  // namespace

std::optional<double> ray_thickness(const SurfaceDistance& dist, const Eigen::Vector3d& p, const Eigen::Vector3d& dir,
                                    double inside_sign, double t_max, double h) {
  const double min_step = 1e-3 * h;  // grazing a parallel face: at most t_max / min_step steps
  double t = min_step, t_in = 0.0;
  for (int it = 0; it < 4000 && t <= t_max; ++it) {
    SurfacePoint sp;
    if (!dist.nearest(p + t * dir, sp)) return std::nullopt;  // beyond the band: thicker than it
    const double phi = -inside_sign * sp.distance;             // < 0 on the ray's side
    if (phi >= 0.0) {
      double lo = t_in, hi = t;  // inside at lo, outside (or on the surface) at hi
      for (int k = 0; k < 40; ++k) {
        const double mid = 0.5 * (lo + hi);
        SurfacePoint q;
        const bool inside = dist.nearest(p + mid * dir, q) && inside_sign * q.distance > 0.0;
        (inside ? lo : hi) = mid;
      }
      return hi;
    }
    t_in = t;
    t += std::max(-phi, min_step);
  }
  return std::nullopt;
}

ThinWalls measure_thin_walls(const TriSurface& s, const SurfaceDistance& dist, const StuffingOptions& opt, int cells) {
  ThinWalls out;
  if (cells <= 0) return out;
  const auto planes = stuffing_planes(s, opt);
  const double h_max = std::max(opt.h, axis_h(opt, 2)), h_min = std::min(opt.h, axis_h(opt, 2));
  std::array<AxisBins, 3> bins;
  for (int d = 0; d < 3; ++d) {
    bins[d].h = axis_h(opt, d);
    bins[d].w = bins[d].h / 32.0;
    bins[d].x0 = planes[d].front();
    const double span = planes[d].back() - planes[d].front();
    bins[d].size.assign(static_cast<std::size_t>(std::ceil(span / bins[d].w)) + 1, bins[d].h);
  }
  const double t_max = cells * h_max;  // thicker walls need no refinement along any axis
  double floor_hit = 0.0;
  Eigen::Vector3d floor_at = Eigen::Vector3d::Zero();
  for (int f = 0; f < static_cast<int>(s.F.size()); ++f) {
    const auto& tri = s.F[f];
    if (opt.half && s.V[tri[0]].x() < 0.0 && s.V[tri[1]].x() < 0.0 && s.V[tri[2]].x() < 0.0) continue;
    const Eigen::Vector3d n = s.normal(f);
    for (const Eigen::Vector3d& p : triangle_samples(s, f, 0.5 * h_min)) {
      for (const double side : {-1.0, 1.0}) {  // -1: through the solid (a wall), +1: through a void (a gap)
        ++out.samples;
        const std::optional<double> t = ray_thickness(dist, p, side * n, side, t_max, h_min);
        if (!t) continue;
        const Eigen::Vector3d q = p + *t * side * n;
        bool needed = false;
        for (int d = 0; d < 3; ++d) {
          const double hd = bins[d].h, nd = std::abs(n[d]);
          // A wall of exactly cells * h (to round-off of the CAD coordinates) needs nothing.
          if (!(nd > 0.0) || *t / (cells * nd) >= hd * (1.0 - 1e-9)) continue;
          // A half model meshes x >= 0: a wall or gap across the symmetry plane ends there.
          const double lo = d == 0 && opt.half ? std::max(0.0, std::min(p[d], q[d])) : std::min(p[d], q[d]);
          const double hi = std::max(p[d], q[d]);
          if (hi <= lo) continue;
          if (on_plane(planes[d], lo, 1e-6 * hd) && on_plane(planes[d], hi, 1e-6 * hd)) continue;  // meshed exactly
          double size = *t / (cells * nd);
          if (size < kFloor * hd) {
            if (floor_hit == 0.0 || *t < floor_hit) floor_hit = *t, floor_at = p;
            size = kFloor * hd;
          }
          bins[d].require(lo, hi, size);
          needed = true;
        }
        if (!needed) continue;
        ++out.thin;
        if (out.thinnest == 0.0 || *t < out.thinnest) out.thinnest = *t, out.thinnest_at = p, out.thinnest_is_gap = side > 0.0;
      }
    }
  }
  for (int d = 0; d < 3; ++d) out.sizes[d] = bins[d].runs();
  if (floor_hit > 0.0)
    out.notes.push_back("a wall or gap " + short_num(floor_hit * 1e3) + " mm thick at " + mm_point(floor_at) +
                        " would need cells below mesh.h_mm / 8 for " + std::to_string(cells) +
                        " across it (mesh.wall_cells); it got cells of h / 8: thicken it in CAD or use a smaller "
                        "mesh.h_mm");
  return out;
}

}  // namespace pneufem
