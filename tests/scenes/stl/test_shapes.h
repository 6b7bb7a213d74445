#pragma once
// Closed test surfaces: the built-in pneu-net's solid from its dimensions (scenes/pneunet.h), a
// box, and a capped tube with a closed bore (a second actuator, curved). Exact geometry: the
// pneu-net's faces are the faces between solid and void cells of the grid through its feature
// planes, so the triangulation is watertight with no T-junctions.
#include <array>
#include <cmath>
#include <functional>
#include <map>
#include <numbers>
#include <tuple>
#include <utility>
#include <vector>

#include "scenes/pneunet.h"
#include "scenes/stl/surface.h"

namespace pneufem::test {

/// The surface between `solid` and not-solid cells of the grid `lines`: two triangles per face,
/// counter-clockwise seen from the non-solid side. Coordinates in metres.
inline TriSurface grid_solid_surface(const std::array<std::vector<double>, 3>& lines,
                                     const std::function<bool(const Eigen::Vector3d&)>& solid) {
  TriSurface s;
  s.path = "test surface";
  const int n[3] = {static_cast<int>(lines[0].size()), static_cast<int>(lines[1].size()), static_cast<int>(lines[2].size())};
  std::map<std::array<int, 3>, int> vid;
  auto vertex = [&](std::array<int, 3> g) {
    auto [it, fresh] = vid.try_emplace(g, static_cast<int>(s.V.size()));
    if (fresh) s.V.emplace_back(lines[0][g[0]], lines[1][g[1]], lines[2][g[2]]);
    return it->second;
  };
  auto in = [&](int i, int j, int k) {
    if (i < 0 || j < 0 || k < 0 || i >= n[0] - 1 || j >= n[1] - 1 || k >= n[2] - 1) return false;
    return solid(Eigen::Vector3d(0.5 * (lines[0][i] + lines[0][i + 1]), 0.5 * (lines[1][j] + lines[1][j + 1]),
                                 0.5 * (lines[2][k] + lines[2][k + 1])));
  };
  for (int i = -1; i < n[0]; ++i)
    for (int j = -1; j < n[1]; ++j)
      for (int k = -1; k < n[2]; ++k)
        for (int d = 0; d < 3; ++d) {
          std::array<int, 3> c{i, j, k}, nb = c;
          nb[d] += 1;
          const bool a = in(c[0], c[1], c[2]), b = in(nb[0], nb[1], nb[2]);
          if (a == b) continue;
          // The face between c and nb: the plane index nb[d], spanning the cell's other two axes.
          const int u = (d + 1) % 3, w = (d + 2) % 3;
          if (c[u] < 0 || c[w] < 0 || c[u] + 1 >= n[u] || c[w] + 1 >= n[w] || nb[d] < 0 || nb[d] >= n[d]) continue;
          std::array<int, 3> p0 = nb, p1 = nb, p2 = nb, p3 = nb;
          p1[u] += 1;
          p2[u] += 1, p2[w] += 1;
          p3[w] += 1;
          int q[4] = {vertex(p0), vertex(p1), vertex(p2), vertex(p3)};
          // (u, w, d) is right-handed: p0 p1 p2 runs counter-clockwise seen from +d, outward if a is solid.
          if (a)
            s.F.push_back({q[0], q[1], q[2]}), s.F.push_back({q[0], q[2], q[3]});
          else
            s.F.push_back({q[0], q[2], q[1]}), s.F.push_back({q[0], q[3], q[2]});
        }
  return s;
}

/// The built-in pneu-net's full solid (both halves), from its dimensions.
inline TriSurface pneunet_surface(const PneuNetParams& p) {
  const double hw = 0.5 * p.width, hc = hw - p.side_wall, hch = 0.5 * p.channel_width;
  const double hb = p.base_thickness, top = hb + p.body_height, L = p.length();
  std::array<std::vector<double>, 3> lines;
  lines[0] = {-hw, -hc, -hch, hch, hc, hw};
  lines[1].push_back(0.0);
  auto y0 = [&](int i) { return p.end_cap + i * (p.chamber_length + p.interior_wall); };
  for (int i = 0; i < p.chambers; ++i) lines[1].push_back(y0(i)), lines[1].push_back(y0(i) + p.chamber_length);
  lines[1].push_back(L);
  lines[2] = {0.0, hb, hb + p.channel_height, top - p.roof, top};
  auto solid = [&](const Eigen::Vector3d& x) {
    for (int i = 0; i < p.chambers; ++i)
      if (std::abs(x.x()) < hc && x.y() > y0(i) && x.y() < y0(i) + p.chamber_length && x.z() > hb && x.z() < top - p.roof)
        return false;
    if (std::abs(x.x()) < hch && x.y() > y0(0) && x.y() < y0(p.chambers - 1) + p.chamber_length && x.z() > hb &&
        x.z() < hb + p.channel_height)
      return false;
    return true;
  };
  TriSurface s = grid_solid_surface(lines, solid);
  s.path = "pneunet.stl";
  return s;
}

/// The built-in pneu-net's chambers and channel alone, as a closed surface of their own (normals
/// out of the chambers), and the actuator's outer block without them: the two files of a scene with
/// mesh.cavity_file.
inline std::pair<TriSurface, TriSurface> pneunet_block_and_chambers(const PneuNetParams& p) {
  const TriSurface whole = pneunet_surface(p);
  Eigen::Vector3d lo = whole.V.front(), hi = lo;
  for (const auto& v : whole.V) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  std::array<std::vector<double>, 3> box{{{lo.x(), hi.x()}, {lo.y(), hi.y()}, {lo.z(), hi.z()}}};
  TriSurface block = grid_solid_surface(box, [](const Eigen::Vector3d&) { return true; });
  block.path = "block.stl";
  // The void cells of the pneu-net's grid, as a solid of their own.
  const double hw = 0.5 * p.width, hc = hw - p.side_wall, hch = 0.5 * p.channel_width;
  const double hb = p.base_thickness, top = hb + p.body_height;
  std::array<std::vector<double>, 3> lines;
  lines[0] = {-hw, -hc, -hch, hch, hc, hw};
  lines[1].push_back(0.0);
  auto y0 = [&](int i) { return p.end_cap + i * (p.chamber_length + p.interior_wall); };
  for (int i = 0; i < p.chambers; ++i) lines[1].push_back(y0(i)), lines[1].push_back(y0(i) + p.chamber_length);
  lines[1].push_back(p.length());
  lines[2] = {0.0, hb, hb + p.channel_height, top - p.roof, top};
  TriSurface chambers = grid_solid_surface(lines, [&](const Eigen::Vector3d& x) {
    for (int i = 0; i < p.chambers; ++i)
      if (std::abs(x.x()) < hc && x.y() > y0(i) && x.y() < y0(i) + p.chamber_length && x.z() > hb && x.z() < top - p.roof)
        return true;
    return std::abs(x.x()) < hch && x.y() > y0(0) && x.y() < y0(p.chambers - 1) + p.chamber_length && x.z() > hb &&
           x.z() < hb + p.channel_height;
  });
  chambers.path = "chambers.stl";
  return {block, chambers};
}

/// A closed cylinder along y (radius r, y in [y0, y1]) with `segments` facets around, normals out.
inline void add_cylinder(TriSurface& s, double r, double y0, double y1, double zc, int segments, bool inward) {
  const int base = static_cast<int>(s.V.size());
  for (int end = 0; end < 2; ++end)
    for (int k = 0; k < segments; ++k) {
      const double t = 2.0 * std::numbers::pi * k / segments;
      s.V.emplace_back(r * std::cos(t), end == 0 ? y0 : y1, zc + r * std::sin(t));
    }
  s.V.emplace_back(0.0, y0, zc);
  s.V.emplace_back(0.0, y1, zc);
  const int c0 = base + 2 * segments, c1 = c0 + 1;
  auto tri = [&](int a, int b, int c) {
    if (inward)
      s.F.push_back({a, c, b});
    else
      s.F.push_back({a, b, c});
  };
  for (int k = 0; k < segments; ++k) {
    const int a = base + k, b = base + (k + 1) % segments, a1 = a + segments, b1 = b + segments;
    // Around y, (x, z) = (cos t, sin t): the outward normal of the side is (cos t, 0, sin t).
    tri(a, a1, b1);
    tri(a, b1, b);
    tri(c0, a, b);     // end y0, normal -y
    tri(c1, b1, a1);   // end y1, normal +y
  }
}

/// A capped tube: outer cylinder radius ro, a closed bore of radius ri from y = cap to L - cap.
inline TriSurface tube_surface(double ro, double ri, double L, double cap, int segments) {
  TriSurface s;
  s.path = "tube.stl";
  add_cylinder(s, ro, 0.0, L, 0.0, segments, false);
  add_cylinder(s, ri, cap, L - cap, 0.0, segments, false);  // wrong side on purpose: the reader turns it
  return s;
}

}  // namespace pneufem::test
