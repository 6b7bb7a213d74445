#include "scenes/stl/smoothing.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <numbers>

#include <Eigen/Geometry>

namespace pneufem {

double tet_min_dihedral_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                            const Eigen::Vector3d& d) {
  if ((b - a).cross(c - a).dot(d - a) <= 0.0) return 0.0;
  const Eigen::Vector3d p[4] = {a, b, c, d};
  // Dihedral angle at edge (i, j): between the faces (i, j, k) and (i, j, l).
  static constexpr int kPairs[6][4] = {{0, 1, 2, 3}, {0, 2, 1, 3}, {0, 3, 1, 2}, {1, 2, 0, 3}, {1, 3, 0, 2}, {2, 3, 0, 1}};
  double lo = 180.0;
  for (const auto& q : kPairs) {
    const Eigen::Vector3d e = (p[q[1]] - p[q[0]]).normalized();
    Eigen::Vector3d u = p[q[2]] - p[q[0]], w = p[q[3]] - p[q[0]];
    u -= u.dot(e) * e;
    w -= w.dot(e) * e;
    lo = std::min(lo, std::acos(std::clamp(u.normalized().dot(w.normalized()), -1.0, 1.0)) * 180.0 / std::numbers::pi);
  }
  return lo;
}

namespace {

/// How a vertex may move: not at all, freely, or within the plane through it with normal `n`.
struct Freedom {
  enum Kind { Fixed, Free, Plane } kind = Fixed;
  Eigen::Vector3d n = Eigen::Vector3d::Zero();
  bool on_surface = false;  ///< Plane of a flat face: stay on the surface, with the face's normal
};

/// Unit normals of the boundary faces (faces of one tetrahedron) around each vertex, outward.
std::vector<std::vector<Eigen::Vector3d>> boundary_normals(const StuffedTets& st) {
  std::map<std::array<int, 3>, std::pair<int, std::array<int, 4>>> faces;  // sorted face -> (count, its tet and the opposite)
  for (const auto& t : st.tets)
    for (int k = 0; k < 4; ++k) {
      std::array<int, 3> f{t[(k + 1) % 4], t[(k + 2) % 4], t[(k + 3) % 4]};
      std::sort(f.begin(), f.end());
      auto [it, fresh] = faces.try_emplace(f, 0, std::array<int, 4>{f[0], f[1], f[2], t[k]});
      ++it->second.first;
    }
  std::vector<std::vector<Eigen::Vector3d>> out(st.X.size());
  for (const auto& [f, cv] : faces) {
    if (cv.first != 1) continue;
    const auto& q = cv.second;
    Eigen::Vector3d n = (st.X[q[1]] - st.X[q[0]]).cross(st.X[q[2]] - st.X[q[0]]);
    if (n.dot(st.X[q[0]] - st.X[q[3]]) < 0.0) n = -n;  // away from the opposite vertex
    if (!(n.norm() > 0.0)) continue;
    n.normalize();
    for (int v : f) out[v].push_back(n);
  }
  return out;
}

Freedom freedom_of(int v, const StuffedTets& st, const std::vector<Eigen::Vector3d>& normals, const SmoothingOptions& o) {
  Freedom fr;
  int planes = 0;
  if (st.on_symmetry[v]) ++planes, fr.n = Eigen::Vector3d::UnitX();
  if (std::find(o.forced_z.begin(), o.forced_z.end(), st.X[v].z()) != o.forced_z.end()) ++planes, fr.n = Eigen::Vector3d::UnitZ();
  if (st.on_surface[v]) {
    if (planes > 0 || normals.empty()) return fr;  // Fixed
    for (const auto& n : normals)
      if (n.dot(normals.front()) < 1.0 - 1e-9) return fr;  // an edge or a curved face: Fixed
    fr.kind = Freedom::Plane;
    fr.n = normals.front();
    fr.on_surface = true;
    return fr;
  }
  if (planes > 1) return fr;
  if (planes == 0 && !normals.empty()) return fr;  // on the mesh's boundary but not flagged: leave it
  fr.kind = planes == 1 ? Freedom::Plane : Freedom::Free;
  return fr;
}

/// Search directions of a freedom: the axes, or two tangents and their diagonals.
std::vector<Eigen::Vector3d> directions(const Freedom& fr) {
  std::vector<Eigen::Vector3d> d;
  if (fr.kind == Freedom::Free) {
    for (int k = 0; k < 3; ++k) d.push_back(Eigen::Vector3d::Unit(k)), d.push_back(-Eigen::Vector3d::Unit(k));
    return d;
  }
  const Eigen::Vector3d a = std::abs(fr.n.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  const Eigen::Vector3d t1 = fr.n.cross(a).normalized(), t2 = fr.n.cross(t1);
  for (const Eigen::Vector3d& t : {t1, t2, Eigen::Vector3d((t1 + t2).normalized()), Eigen::Vector3d((t1 - t2).normalized())})
    d.push_back(t), d.push_back(-t);
  return d;
}

class Smoother {
 public:
  Smoother(StuffedTets& st, const SurfaceDistance& dist, const SmoothingOptions& o) : st_(st), dist_(dist), o_(o) {
    tets_of_.resize(st.X.size());
    for (int t = 0; t < static_cast<int>(st.tets.size()); ++t)
      for (int v : st.tets[t]) tets_of_[v].push_back(t);
    normals_ = boundary_normals(st);
  }

  double quality(int t) const {
    const auto& q = st_.tets[t];
    return tet_min_dihedral_deg(st_.X[q[0]], st_.X[q[1]], st_.X[q[2]], st_.X[q[3]]);
  }

  double star(int v) const {
    double lo = 180.0;
    for (int t : tets_of_[v]) lo = std::min(lo, quality(t));
    return lo;
  }

  /// Pattern search on vertex v; true when it moved.
  bool improve(int v) {
    const Freedom fr = freedom_of(v, st_, normals_[v], o_);
    if (fr.kind == Freedom::Fixed) return false;
    double shortest = std::numeric_limits<double>::infinity();
    for (int t : tets_of_[v])
      for (int w : st_.tets[t])
        if (w != v) shortest = std::min(shortest, (st_.X[w] - st_.X[v]).norm());
    const auto dirs = directions(fr);
    double best = star(v);
    bool moved = false;
    for (double step = 0.25 * shortest; step > 0.25 * shortest / 32.0; step *= 0.5)
      for (bool again = true; again;) {
        again = false;
        for (const auto& d : dirs) {
          const Eigen::Vector3d old = st_.X[v], q = old + step * d;
          if (fr.on_surface && !stays_on_face(q, fr.n)) continue;
          st_.X[v] = q;
          const double s = star(v);
          if (s > best + 1e-9) {
            best = s;
            moved = again = true;
            break;
          }
          st_.X[v] = old;
        }
      }
    return moved;
  }

  int run() {
    int moves = 0;
    for (int sweep = 0; sweep < o_.sweeps; ++sweep) {
      std::vector<std::pair<double, int>> worst;
      for (int t = 0; t < static_cast<int>(st_.tets.size()); ++t)
        if (eligible_[t]) {
          const double q = quality(t);
          if (q < o_.target_deg) worst.emplace_back(q, t);
        }
      std::sort(worst.begin(), worst.end());
      int this_sweep = 0;
      for (const auto& [q, t] : worst)
        for (int v : st_.tets[t])
          if (quality(t) < o_.target_deg && improve(v)) ++this_sweep;
      moves += this_sweep;
      if (this_sweep == 0) break;
    }
    return moves;
  }

  std::vector<char> eligible_;

 private:
  /// q lies on the surface on a facet of normal n (the same flat face).
  bool stays_on_face(const Eigen::Vector3d& q, const Eigen::Vector3d& n) const {
    SurfacePoint sp;
    if (!dist_.nearest(q, sp) || std::abs(sp.distance) > o_.zero_tol) return false;
    const auto& s = dist_.surface();
    return s.normal(sp.face).dot(n) > 1.0 - 1e-9;
  }

  StuffedTets& st_;
  const SurfaceDistance& dist_;
  const SmoothingOptions& o_;
  std::vector<std::vector<int>> tets_of_;
  std::vector<std::vector<Eigen::Vector3d>> normals_;
};

}  // namespace

int smooth_cut_elements(StuffedTets& st, const std::vector<char>& from_cut, const SurfaceDistance& dist,
                        const SmoothingOptions& opt) {
  Smoother sm(st, dist, opt);
  sm.eligible_.assign(st.tets.size(), 0);
  for (std::size_t t = 0; t < st.tets.size(); ++t)
    for (int v : st.tets[t]) sm.eligible_[t] = sm.eligible_[t] || from_cut[v];
  return sm.run();
}

}  // namespace pneufem
