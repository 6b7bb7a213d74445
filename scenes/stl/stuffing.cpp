#include "scenes/stl/stuffing.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <unordered_map>

#include <Eigen/Geometry>

#include "core/errors.h"
#include "core/number_text.h"
#include "scenes/stl/smoothing.h"

namespace pneufem {

namespace {

constexpr double kMaxCells = 5e6;  // as the built-in mesher (scenes/pneunet.cpp)

struct Plane {
  double at;
  double weight;  ///< facet area; forced planes: infinity
  int cells = 0;  ///< cells of the interval above it; 0 = from h
};

double axis_h(const StuffingOptions& o, int d) { return d == 2 && o.h_z > 0.0 ? o.h_z : o.h; }

/// Axis-aligned planes carrying facets of the surface: (axis, coordinate) -> area.
std::array<std::map<double, double>, 3> facet_planes(const TriSurface& s) {
  std::array<std::map<double, double>, 3> out;
  for (int f = 0; f < static_cast<int>(s.F.size()); ++f) {
    const auto& t = s.F[f];
    for (int d = 0; d < 3; ++d)
      if (s.V[t[0]][d] == s.V[t[1]][d] && s.V[t[1]][d] == s.V[t[2]][d]) out[d][s.V[t[0]][d]] += s.area(f);
  }
  return out;
}

}  // namespace

std::vector<double> slab_planes(const StuffingOptions& o) {
  if (!o.has_slab) return {};
  if (o.slab_mid) return {o.slab_z0, o.slab_z0 + 0.5 * (o.slab_z1 - o.slab_z0), o.slab_z1};
  return {o.slab_z0, o.slab_z1};
}

std::array<std::vector<double>, 3> stuffing_planes(const TriSurface& s, const StuffingOptions& o) {
  Eigen::Vector3d lo = s.V.front(), hi = s.V.front();
  for (const auto& p : s.V) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double size = (hi - lo).norm();
  if (o.half) {
    if (!(lo.x() < 0.0 && hi.x() > 0.0) || std::abs(lo.x() + hi.x()) > 1e-6 * size)
      throw InputError(s.path + ": mesh.half = true models x >= 0 of an actuator mirror-symmetric about x = 0, but the "
                       "surface spans x = " + short_num(lo.x() / s.unit_m) + " to " + short_num(hi.x() / s.unit_m) +
                       " (file units); centre the actuator's width on x = 0 in CAD or set mesh.half = false");
    lo.x() = 0.0;
  }
  const auto facets = facet_planes(s);
  std::array<std::vector<double>, 3> ends;
  for (int d = 0; d < 3; ++d) {
    const double h = axis_h(o, d);
    constexpr double kForced = std::numeric_limits<double>::infinity();
    std::vector<Plane> planes;
    if (d == 0 && o.half) planes.push_back({0.0, kForced});
    for (double at : o.end_planes[d]) {
      bool have = !(at >= lo[d] && at <= hi[d]);  // outside a half model's x >= 0: not meshed
      for (const Plane& p : planes) have = have || p.at == at;
      if (!have) planes.push_back({at, kForced});
    }
    if (d == 2 && o.has_slab) {
      if (!(o.slab_z0 > lo.z() && o.slab_z1 < hi.z() && o.slab_z0 < o.slab_z1))
        throw InputError("mesh.fabric_slab_mm = [" + short_num(o.slab_z0 * 1e3) + ", " + short_num(o.slab_z1 * 1e3) +
                         "] must be an increasing z range strictly inside the actuator's z extent [" +
                         short_num(lo.z() * 1e3) + ", " + short_num(hi.z() * 1e3) +
                         "] mm; give the fabric layer's bottom and top, or [] for no fabric layer");
      for (double z : slab_planes(o)) planes.push_back({z, kForced});
    }
    if (o.feature_planes) {
      // Heaviest planes first; one closer than h/10 to a kept plane would make cells ten times thinner
      // than wide and is left to the cut (step 3). (The built-in mesher keeps every feature plane.)
      std::vector<std::pair<double, double>> cand;
      for (const auto& [at, area] : facets[d])
        if (at >= lo[d] && at <= hi[d]) cand.emplace_back(area, at);
      std::sort(cand.begin(), cand.end(), [](const auto& a, const auto& b) { return a.first > b.first || (a.first == b.first && a.second < b.second); });
      for (const auto& [area, at] : cand) {
        bool near = false;
        for (const Plane& p : planes) near = near || std::abs(p.at - at) < 0.1 * h;
        if (!near) planes.push_back({at, area});
      }
    }
    std::sort(planes.begin(), planes.end(), [](const Plane& a, const Plane& b) { return a.at < b.at; });
    // The ends: one cell beyond an extreme face that is a grid plane, else half a cell beyond the
    // surface (a plane only touching it, as below a cylinder, would make a sliver layer of cells).
    std::vector<double> at;
    if (!(d == 0 && o.half)) at.push_back(!planes.empty() && planes.front().at <= lo[d] ? planes.front().at - h : lo[d] - 0.5 * h);
    for (const Plane& p : planes) at.push_back(p.at);
    at.push_back(!planes.empty() && planes.back().at >= hi[d] ? planes.back().at + h : hi[d] + 0.5 * h);
    ends[d] = std::move(at);
  }
  return ends;
}

std::vector<double> subdivide_interval(double a, double b, double h, const std::vector<AxisSize>& sizes, double grading) {
  auto size_at = [&](double x) {
    double s = h;
    for (const AxisSize& z : sizes) s = std::min(s, z.spacing + grading * std::max({0.0, z.lo - x, x - z.hi}));
    return s;
  };
  double s_min = h;
  for (const AxisSize& z : sizes) s_min = std::min(s_min, z.spacing + grading * std::max({0.0, z.lo - b, a - z.hi}));
  std::vector<double> L;
  if (!(s_min < h)) {  // nothing finer in reach: equal cells, as the built-in mesher
    const int n = static_cast<int>(std::max(1.0, std::ceil((b - a) / h * (1.0 - 1e-12))));
    for (int k = 0; k < n; ++k) L.push_back(a + (b - a) * k / n);
    L.push_back(b);
    return L;
  }
  // Cumulative integral of 1/s on a fine uniform sampling (trapezoid rule; 16 samples per
  // smallest cell keep the cells' sizes within a few per cent of s), then inverted linearly.
  const int m = static_cast<int>(std::clamp(std::ceil(16.0 * (b - a) / s_min), 16.0, 4e6));
  std::vector<double> cum(m + 1, 0.0);
  double f0 = 1.0 / size_at(a);
  for (int i = 1; i <= m; ++i) {
    const double f1 = 1.0 / size_at(a + (b - a) * i / m);
    cum[i] = cum[i - 1] + 0.5 * (f0 + f1) * (b - a) / m;
    f0 = f1;
  }
  const int n = static_cast<int>(std::max(1.0, std::ceil(cum[m] * (1.0 - 1e-12))));
  L.push_back(a);
  for (int k = 1, i = 1; k < n; ++k) {
    const double target = cum[m] * k / n;
    while (cum[i] < target) ++i;
    const double t = (target - cum[i - 1]) / (cum[i] - cum[i - 1]);
    L.push_back(a + (b - a) * (i - 1 + t) / m);
  }
  L.push_back(b);
  return L;
}

std::array<std::vector<double>, 3> stuffing_grid(const TriSurface& s, const StuffingOptions& o) {
  const auto ends = stuffing_planes(s, o);
  std::array<std::vector<double>, 3> lines;
  for (int d = 0; d < 3; ++d) {
    const auto& at = ends[d];
    auto& L = lines[d];
    for (std::size_t m = 0; m + 1 < at.size(); ++m) {
      const double a = at[m], b = at[m + 1];
      const auto zs = d == 2 ? slab_planes(o) : std::vector<double>{};
      const bool slab = zs.size() >= 2 && a >= zs.front() && b <= zs.back();  // an interval inside the slab
      if (slab) {
        const int n = o.slab_mid ? (o.slab_cells + 1) / 2 : o.slab_cells;
        for (int k = 0; k < n; ++k) L.push_back(a + (b - a) * k / n);
        continue;
      }
      std::vector<double> sub = subdivide_interval(a, b, axis_h(o, d), o.sizes[d], o.grading);
      L.insert(L.end(), sub.begin(), sub.end() - 1);
    }
    L.push_back(at.back());
  }
  const double cells = static_cast<double>(lines[0].size() - 1) * (lines[1].size() - 1) * (lines[2].size() - 1);
  if (cells > kMaxCells)
    throw InputError(s.path + ": mesh.h_mm = " + short_num(o.h * 1e3) + " gives " + short_num(std::round(cells / 1e5) / 10) +
                     " million background cells (limit " + short_num(kMaxCells / 1e6) +
                     " million); use a larger mesh.h_mm, or check mesh.length_unit (a model in metres read as mm is "
                     "1000 times too large)");
  return lines;
}

namespace {

/// The 5-tetrahedron split of a cell with alternating parity (scenes/pneunet.cpp explains it):
/// corner c = a + 2 b + 4 c' for local offsets (a, b, c') in {0,1}^3.
std::array<std::array<std::array<int, 4>, 5>, 2> cell_splits() {
  std::array<std::array<std::array<int, 4>, 5>, 2> s{};
  for (int q = 0; q < 2; ++q) {
    int t = 1;
    int n = 0;
    for (int c = 0; c < 8; ++c) {
      if ((std::popcount(static_cast<unsigned>(c)) + q) % 2 == 0)
        s[q][0][n++] = c;
      else
        s[q][t++] = {c, c ^ 1, c ^ 2, c ^ 4};
    }
  }
  return s;
}

struct EdgeHash {
  std::size_t operator()(std::uint64_t k) const { return std::hash<std::uint64_t>()(k); }
};
std::uint64_t edge_key(int a, int b) {
  return (static_cast<std::uint64_t>(std::min(a, b)) << 32) | static_cast<std::uint32_t>(std::max(a, b));
}

/// Splits a prism (a0, a1, a2 | b0, b1, b2; lateral edges ai-bi) into 3 tetrahedra, every
/// quadrilateral cut on the diagonal through its lowest-numbered vertex (Dompierre et al. 1999).
void split_prism(std::array<int, 3> a, std::array<int, 3> b, std::vector<std::array<int, 4>>& out) {
  int m = 0;
  for (int i = 1; i < 6; ++i)
    if ((i < 3 ? a[i] : b[i - 3]) < (m < 3 ? a[m] : b[m - 3])) m = i;
  if (m >= 3) {
    std::swap(a, b);
    m -= 3;
  }
  std::rotate(a.begin(), a.begin() + m, a.end());
  std::rotate(b.begin(), b.begin() + m, b.end());
  out.push_back({a[0], b[0], b[1], b[2]});
  // Pyramid apex a0 on the quad (a1, a2, b2, b1).
  if (std::min(a[1], b[2]) < std::min(a[2], b[1])) {
    out.push_back({a[0], a[1], a[2], b[2]});
    out.push_back({a[0], a[1], b[2], b[1]});
  } else {
    out.push_back({a[0], a[1], a[2], b[1]});
    out.push_back({a[0], a[2], b[2], b[1]});
  }
}

/// A pyramid with apex `apex` on the quadrilateral q (cyclic), cut on its lowest vertex's diagonal.
void split_pyramid(int apex, std::array<int, 4> q, std::vector<std::array<int, 4>>& out) {
  const int m = static_cast<int>(std::min_element(q.begin(), q.end()) - q.begin());
  std::rotate(q.begin(), q.begin() + m, q.end());
  out.push_back({apex, q[0], q[1], q[2]});
  out.push_back({apex, q[0], q[2], q[3]});
}

/// Step 4b (see stuff_surface). Returns the vertices moved.
int snap_to_creases(std::vector<Eigen::Vector3d>& X, const std::vector<double>& phi,
                    const std::vector<std::vector<int>>& nb, const std::vector<char>& forced,
                    const SurfaceDistance& dist, double alpha, double zero_tol) {
  const int nv = static_cast<int>(X.size());
  auto on_surface = [&](const Eigen::Vector3d& p) {
    SurfacePoint sp;
    return dist.nearest(p, sp) && std::abs(sp.distance) <= zero_tol;
  };
  constexpr double kMinT = 0.01;  // below: the edge leaves the surface at once (a curved surface's chord)
  int moved = 0;
  for (int v = 0; v < nv; ++v) {
    if (phi[v] != 0.0) continue;
    double best_t = 1.0;
    int best_w = -1;
    for (int w : nb[v]) {
      if (phi[w] == 0.0) continue;
      bool allowed = true;
      for (int d : {0, 2})
        if ((forced[v] >> d) & 1) allowed = allowed && X[w][d] == X[v][d];
      const Eigen::Vector3d e = X[w] - X[v];
      if (!allowed || !on_surface(X[v] + kMinT * e) || on_surface(X[v] + alpha * e)) continue;
      double lo = kMinT, hi = alpha;  // on the surface at lo, off it at hi
      for (int it = 0; it < 40; ++it) {
        const double mid = 0.5 * (lo + hi);
        (on_surface(X[v] + mid * e) ? lo : hi) = mid;
      }
      if (lo < best_t) best_t = lo, best_w = w;
    }
    if (best_w < 0) continue;
    X[v] += best_t * (X[best_w] - X[v]);
    ++moved;
  }
  return moved;
}

/// Step 6: sharp edges. Stencils cut a sharp edge of the surface (two facets meeting at more than
/// 30 degrees: a box's edge, a chamber's) with a chamfer about a cell wide. Each surface node within
/// `reach` of a sharp edge and on a boundary face that leaves the surface (a chamfer: its centroid
/// off the surface by more than 1e-3 reach), nearest first, moves onto it, unless a tetrahedron
/// around it would then have a dihedral angle below 5 degrees (or below its own, if that is
/// smaller): then it stays. Nodes of a mesh that already follows the surface do not move.
int snap_to_sharp_edges(StuffedTets& out, const TriSurface& s, const SurfaceDistance& dist, double reach) {
  std::map<std::pair<int, int>, std::vector<int>> faces_of;
  for (int f = 0; f < static_cast<int>(s.F.size()); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = s.F[f][k], b = s.F[f][(k + 1) % 3];
      faces_of[{std::min(a, b), std::max(a, b)}].push_back(f);
    }
  const double cos_sharp = std::cos(30.0 * 3.141592653589793 / 180.0);
  std::vector<std::array<Eigen::Vector3d, 2>> sharp;
  for (const auto& [e, fs] : faces_of)
    if (fs.size() == 2 && s.normal(fs[0]).dot(s.normal(fs[1])) < cos_sharp) sharp.push_back({s.V[e.first], s.V[e.second]});
  if (sharp.empty()) return 0;
  const int nn = static_cast<int>(out.X.size());
  std::vector<std::vector<int>> tets_of(nn);
  for (int t = 0; t < static_cast<int>(out.tets.size()); ++t)
    for (int v : out.tets[t]) tets_of[v].push_back(t);
  // Nodes of chamfer faces: boundary faces (used by one tetrahedron) whose centroid is off the surface.
  std::vector<char> on_chamfer(nn, 0);
  {
    std::map<std::array<int, 3>, int> count;
    for (const auto& t : out.tets)
      for (int k = 0; k < 4; ++k) {
        std::array<int, 3> f{t[(k + 1) % 4], t[(k + 2) % 4], t[(k + 3) % 4]};
        std::sort(f.begin(), f.end());
        ++count[f];
      }
    for (const auto& [f, n] : count) {
      if (n != 1 || (out.on_symmetry[f[0]] && out.on_symmetry[f[1]] && out.on_symmetry[f[2]])) continue;
      SurfacePoint sp;
      const Eigen::Vector3d c = (out.X[f[0]] + out.X[f[1]] + out.X[f[2]]) / 3.0;
      if (dist.nearest(c, sp) && std::abs(sp.distance) > 1e-3 * reach)
        for (int v : f) on_chamfer[v] = 1;
    }
  }
  // Nearest sharp-edge point of each surface node within reach (brute force over the sharp edges,
  // culled by the reach box: CAD surfaces have hundreds to thousands of them).
  std::vector<std::pair<double, int>> order;
  std::vector<Eigen::Vector3d> target(nn);
  for (int v = 0; v < nn; ++v) {
    if (!out.on_surface[v] || !on_chamfer[v]) continue;
    double best = reach;
    for (const auto& e : sharp) {
      const Eigen::Vector3d lo = e[0].cwiseMin(e[1]).array() - reach, hi = e[0].cwiseMax(e[1]).array() + reach;
      if ((out.X[v].array() < lo.array()).any() || (out.X[v].array() > hi.array()).any()) continue;
      const Eigen::Vector3d d = e[1] - e[0];
      const double t = std::clamp((out.X[v] - e[0]).dot(d) / d.squaredNorm(), 0.0, 1.0);
      const Eigen::Vector3d q = e[0] + t * d;
      const double gap = (q - out.X[v]).norm();
      if (gap < best && !(out.on_symmetry[v] && q.x() != 0.0)) best = gap, target[v] = q;
    }
    if (best < reach && best > 0.0) order.emplace_back(best, v);
  }
  std::sort(order.begin(), order.end());
  int moved = 0;
  for (const auto& [gap, v] : order) {
    const Eigen::Vector3d old = out.X[v];
    std::vector<double> before;
    for (int t : tets_of[v]) {
      const auto& q = out.tets[t];
      before.push_back(tet_min_dihedral_deg(out.X[q[0]], out.X[q[1]], out.X[q[2]], out.X[q[3]]));
    }
    out.X[v] = target[v];
    bool ok = true;
    for (std::size_t i = 0; i < tets_of[v].size() && ok; ++i) {
      const auto& q = out.tets[tets_of[v][i]];
      ok = tet_min_dihedral_deg(out.X[q[0]], out.X[q[1]], out.X[q[2]], out.X[q[3]]) >= std::min(5.0, before[i]);
    }
    if (ok)
      ++moved;
    else
      out.X[v] = old;
  }
  return moved;
}

}  // namespace

namespace {

/// The state of one stuffing, step by step (stuff_surface lists the steps). Node ids: grid vertex
/// v < nv, or nv + index of a cut point.
class Stuffing {
 public:
  Stuffing(const TriSurface& surface, const SurfaceDistance& dist, const StuffingOptions& opt)
      : s_(surface), dist_(dist), opt_(opt) {
    out_.lines = stuffing_grid(surface, opt);
    for (int d = 0; d < 3; ++d) n_[d] = static_cast<int>(out_.lines[d].size());
    nv_ = n_[0] * n_[1] * n_[2];
    X_.resize(nv_);
    for (int j = 0; j < n_[1]; ++j)
      for (int k = 0; k < n_[2]; ++k)
        for (int i = 0; i < n_[0]; ++i) X_[vid(i, j, k)] = Eigen::Vector3d(out_.lines[0][i], out_.lines[1][j], out_.lines[2][k]);
    grid_X_ = X_;
    slab_z_ = slab_planes(opt);
    h_min_ = std::min(opt.h, axis_h(opt, 2));
    zero_tol_ = 1e-9 * h_min_;  // round-off of a distance to a facet the vertex lies on
  }

  StuffedTets run() {
    vertex_phi();
    background_tets();
    cut_points();
    neighbours_and_forced_planes();
    warp();
    // Step 4b: creases. A vertex on the surface whose edge runs on along the surface and leaves it
    // within alpha of the edge (a vertex on a chamber's side wall just above its floor) moves to
    // where the edge leaves it: onto the crease, which the warping of step 4 cannot reach (phi
    // does not change sign along that edge). Without it the one-cell band along every concave edge
    // of a CAD part would be a slanted fillet of solid.
    out_.creased = snap_to_creases(X_, phi_, nbr_, forced_, dist_, opt_.alpha, zero_tol_);
    compact(stencils());
    out_.on_sharp_edges = snap_to_sharp_edges(out_, s_, dist_, 0.9 * h_min_);
    if (opt_.smooth_target_deg > 0.0) {
      SmoothingOptions so;
      so.target_deg = opt_.smooth_target_deg;
      so.forced_z = slab_planes(opt_);
      so.zero_tol = zero_tol_;
      out_.smoothed = smooth_cut_elements(out_, out_.from_cut, dist_, so);
    }
    return std::move(out_);
  }

 private:
  int vid(int i, int j, int k) const { return (j * n_[2] + k) * n_[0] + i; }

  // Step 2: phi at the vertices; far ones by flood fill along grid edges.
  void vertex_phi() {
    phi_.assign(nv_, std::numeric_limits<double>::quiet_NaN());
    double band_phi = 0.0;
    for (int v = 0; v < nv_; ++v) {
      SurfacePoint sp;
      if (dist_.nearest(X_[v], sp)) {
        phi_[v] = std::abs(sp.distance) <= zero_tol_ ? 0.0 : sp.distance;
        band_phi = std::max(band_phi, std::abs(sp.distance));
      }
    }
    std::vector<int> queue;
    for (int v = 0; v < nv_; ++v)
      if (!std::isnan(phi_[v])) queue.push_back(v);
    if (queue.empty()) throw InputError(s_.path + ": internal: no grid vertex lies near the surface");
    for (std::size_t q = 0; q < queue.size(); ++q) {
      const int v = queue[q];
      const int i = v % n_[0], k = (v / n_[0]) % n_[2], j = v / (n_[0] * n_[2]);
      const int nb[6][3] = {{i - 1, j, k}, {i + 1, j, k}, {i, j - 1, k}, {i, j + 1, k}, {i, j, k - 1}, {i, j, k + 1}};
      for (const auto& n : nb) {
        if (n[0] < 0 || n[0] >= n_[0] || n[1] < 0 || n[1] >= n_[1] || n[2] < 0 || n[2] >= n_[2]) continue;
        const int w = vid(n[0], n[1], n[2]);
        if (!std::isnan(phi_[w])) continue;
        phi_[w] = phi_[v] < 0.0 ? -2.0 * band_phi - 1.0 : 2.0 * band_phi + 1.0;  // only the sign is used
        queue.push_back(w);
      }
    }
  }

  // Background tetrahedra of the cells with a corner inside (cells ordered along y, as the
  // built-in mesher's elements).
  void background_tets() {
    const auto splits = cell_splits();
    for (int j = 0; j + 1 < n_[1]; ++j)
      for (int k = 0; k + 1 < n_[2]; ++k)
        for (int i = 0; i + 1 < n_[0]; ++i) {
          bool any = false;
          for (int c = 0; c < 8; ++c) any = any || phi_[vid(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1))] <= 0.0;
          if (!any) continue;
          for (const auto& t : splits[(i + j + k) % 2]) {
            std::array<int, 4> tet;
            for (int m = 0; m < 4; ++m) tet[m] = vid(i + (t[m] & 1), j + ((t[m] >> 1) & 1), k + ((t[m] >> 2) & 1));
            bg_.push_back(tet);
          }
        }
  }

  // Step 3: cut points on edges with a strict sign change, by regula falsi (Illinois) on the
  // exact distance along the edge.
  void cut_points() {
    for (const auto& t : bg_)
      for (int a = 0; a < 4; ++a)
        for (int b = a + 1; b < 4; ++b) {
          const int u = std::min(t[a], t[b]), w = std::max(t[a], t[b]);
          if (!(phi_[u] * phi_[w] < 0.0)) continue;
          if (!cut_of_.try_emplace(edge_key(u, w), static_cast<int>(cut_pos_.size())).second) continue;
          const double tc = edge_root(u, w);
          cut_pos_.push_back(X_[u] + tc * (X_[w] - X_[u]));
          cut_edge_.push_back({u, w});
          cut_t_.push_back(tc);
        }
    out_.cut_points = static_cast<int>(cut_pos_.size());
  }

  /// Where phi = 0 on edge u -> w (fraction from u); phi changes sign along it.
  double edge_root(int u, int w) const {
    double t0 = 0.0, t1 = 1.0, f0 = phi_[u], f1 = phi_[w], tc = f0 / (f0 - f1);
    int side = 0;
    for (int it = 0; it < 60; ++it) {
      tc = (t0 * f1 - t1 * f0) / (f1 - f0);
      SurfacePoint sp;
      if (!dist_.nearest(X_[u] + tc * (X_[w] - X_[u]), sp)) break;  // cannot happen within the band
      const double fc = sp.distance;
      if (std::abs(fc) <= zero_tol_) break;
      if ((fc < 0.0) == (f0 < 0.0)) {
        t0 = tc, f0 = fc;
        if (side == -1) f1 *= 0.5;
        side = -1;
      } else {
        t1 = tc, f1 = fc;
        if (side == 1) f0 *= 0.5;
        side = 1;
      }
    }
    return tc;
  }

  // Grid neighbours (tetrahedron edges) and the forced planes each vertex lies on (bit 0: x = 0
  // of a half model, bit 2: a face of the slab).
  void neighbours_and_forced_planes() {
    forced_.assign(nv_, 0);
    for (int v = 0; v < nv_; ++v) {
      const bool on_x = opt_.half && X_[v].x() == 0.0;
      const bool on_z = std::find(slab_z_.begin(), slab_z_.end(), X_[v].z()) != slab_z_.end();
      forced_[v] = static_cast<char>((on_x ? 1 : 0) | (on_z ? 4 : 0));
    }
    nbr_.assign(nv_, {});
    for (const auto& t : bg_)
      for (int a = 0; a < 4; ++a)
        for (int b = 0; b < 4; ++b)
          if (b != a && std::find(nbr_[t[a]].begin(), nbr_[t[a]].end(), t[b]) == nbr_[t[a]].end()) nbr_[t[a]].push_back(t[b]);
  }

  bool in_plane(int v, int w) const {
    for (int d : {0, 2})
      if (((forced_[v] >> d) & 1) && X_[w][d] != X_[v][d]) return false;
    return true;
  }

  bool off_surface(const Eigen::Vector3d& p) const {
    SurfacePoint sp;
    return !dist_.nearest(p, sp) || std::abs(sp.distance) > zero_tol_;
  }

  // Step 4: warping. Vertices on a forced plane (x = 0 of a half model, the slab's faces) move
  // only along edges within it. Besides L&S's cut points, an edge towards a vertex on the surface
  // offers the point where it first reaches the surface (its "entry"), when that comes before the
  // end: the edge then runs on along the surface (a vertex just inside a roof, above a chamber's
  // side wall, reaches the roof's crease this way; no cut point lies there, phi does not change sign).
  void warp() {
    for (int v = 0; v < nv_; ++v) {
      if (phi_[v] == 0.0) continue;
      double best_d = std::numeric_limits<double>::infinity();
      Eigen::Vector3d best_p = X_[v];
      for (int w : nbr_[v]) {
        if (!in_plane(v, w)) continue;
        double t = 2.0;
        Eigen::Vector3d p = X_[v];
        if (phi_[v] * phi_[w] < 0.0) {  // a cut point of step 3
          const int c = cut_of_.at(edge_key(v, w));
          t = cut_edge_[c][0] == v ? cut_t_[c] : 1.0 - cut_t_[c];
          p = cut_pos_[c];
        } else if (phi_[w] == 0.0 && !off_surface(X_[v] + opt_.alpha * (X_[w] - X_[v]))) {
          double lo = 0.0, hi = opt_.alpha;  // off the surface at lo, on it at hi
          for (int it = 0; it < 50; ++it) {
            const double mid = 0.5 * (lo + hi);
            (off_surface(X_[v] + mid * (X_[w] - X_[v])) ? lo : hi) = mid;
          }
          t = hi;
          p = X_[v] + hi * (X_[w] - X_[v]);
        }
        const double d = t * (X_[w] - X_[v]).norm();
        if (t < opt_.alpha && d < best_d) best_d = d, best_p = p;
      }
      if (!(best_d < std::numeric_limits<double>::infinity())) continue;
      X_[v] = best_p;
      phi_[v] = 0.0;
      ++out_.warped;
    }
  }

  int cut_node(int a, int b) const { return nv_ + cut_of_.at(edge_key(a, b)); }

  // Step 5: stencils, the part of each background tetrahedron with phi <= 0.
  std::vector<std::array<int, 4>> stencils() const {
    std::vector<std::array<int, 4>> tets;
    for (const auto& t : bg_) {
      std::array<int, 4> neg{}, zer{}, pos{};
      int nn = 0, nz = 0, np = 0;
      for (int v : t) {
        if (phi_[v] < 0.0)
          neg[nn++] = v;
        else if (phi_[v] > 0.0)
          pos[np++] = v;
        else
          zer[nz++] = v;
      }
      if (nn == 0) {
        if (nz == 4) {
          const Eigen::Vector3d c = 0.25 * (X_[t[0]] + X_[t[1]] + X_[t[2]] + X_[t[3]]);
          SurfacePoint sp;
          if (dist_.nearest(c, sp) && sp.distance < 0.0) tets.push_back(t);
        }
        continue;
      }
      if (np == 0) {
        tets.push_back(t);
      } else if (nn == 1) {
        std::array<int, 4> e{neg[0], 0, 0, 0};
        int m = 1;
        for (int z = 0; z < nz; ++z) e[m++] = zer[z];
        for (int p = 0; p < np; ++p) e[m++] = cut_node(neg[0], pos[p]);
        tets.push_back(e);
      } else if (nn == 2 && np == 2) {
        split_prism({neg[0], cut_node(neg[0], pos[0]), cut_node(neg[0], pos[1])},
                    {neg[1], cut_node(neg[1], pos[0]), cut_node(neg[1], pos[1])}, tets);
      } else if (nn == 2) {  // one zero, one positive
        split_pyramid(zer[0], {neg[0], neg[1], cut_node(neg[1], pos[0]), cut_node(neg[0], pos[0])}, tets);
      } else {  // three negative, one positive
        split_prism({neg[0], neg[1], neg[2]},
                    {cut_node(neg[0], pos[0]), cut_node(neg[1], pos[0]), cut_node(neg[2], pos[0])}, tets);
      }
    }
    return tets;
  }

  const Eigen::Vector3d& pos_of(int v) const { return v < nv_ ? X_[v] : cut_pos_[v - nv_]; }

  // Every tetrahedron oriented positively, the flat ones dropped (counted, reported), the nodes
  // compacted by first use.
  void compact(const std::vector<std::array<int, 4>>& tets) {
    const double vol_tol = 1e-12 * opt_.h * opt_.h * axis_h(opt_, 2);
    std::vector<std::array<int, 4>> kept;
    kept.reserve(tets.size());
    for (auto t : tets) {
      const double v6 = (pos_of(t[1]) - pos_of(t[0])).cross(pos_of(t[2]) - pos_of(t[0])).dot(pos_of(t[3]) - pos_of(t[0]));
      if (v6 < 0.0) std::swap(t[1], t[2]);
      if (std::abs(v6) > vol_tol)
        kept.push_back(t);
      else
        ++out_.flat_dropped;
    }
    std::vector<int> new_id(nv_ + cut_pos_.size(), -1);
    for (auto& t : kept)
      for (int& v : t) {
        if (new_id[v] < 0) {
          new_id[v] = static_cast<int>(out_.X.size());
          out_.X.push_back(pos_of(v));
          out_.on_surface.push_back(v >= nv_ || phi_[v] == 0.0 ? 1 : 0);
          out_.on_symmetry.push_back(opt_.half && out_.X.back().x() == 0.0 ? 1 : 0);
          out_.from_cut.push_back(v >= nv_ || X_[v] != grid_X_[v] ? 1 : 0);
        }
        v = new_id[v];
      }
    out_.tets = std::move(kept);
    if (out_.tets.empty())
      throw InputError(s_.path + ": no tetrahedron lies inside the surface at mesh.h_mm = " + short_num(opt_.h * 1e3) +
                       "; the solid is thinner than the element size everywhere: use a smaller mesh.h_mm");
  }

  const TriSurface& s_;
  const SurfaceDistance& dist_;
  const StuffingOptions& opt_;
  StuffedTets out_;
  int n_[3] = {0, 0, 0};
  int nv_ = 0;
  double h_min_ = 0.0, zero_tol_ = 0.0;
  std::vector<Eigen::Vector3d> X_, grid_X_;  // current and original positions of the grid vertices
  std::vector<double> slab_z_;               // the slab's forced planes
  std::vector<double> phi_;
  std::vector<std::array<int, 4>> bg_;
  std::unordered_map<std::uint64_t, int, EdgeHash> cut_of_;  // edge -> index into cut_pos_
  std::vector<Eigen::Vector3d> cut_pos_;
  std::vector<std::array<int, 2>> cut_edge_;
  std::vector<double> cut_t_;  // along the edge from its lower vertex id
  std::vector<char> forced_;
  std::vector<std::vector<int>> nbr_;
};

}  // namespace

StuffedTets stuff_surface(const TriSurface& surface, const SurfaceDistance& dist, const StuffingOptions& opt) {
  return Stuffing(surface, dist, opt).run();
}

}  // namespace pneufem
