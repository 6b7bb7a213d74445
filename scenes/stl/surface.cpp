#include "scenes/stl/surface.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <map>
#include <sstream>
#include <tuple>
#include <unordered_map>
#include <unordered_set>

#include <Eigen/Geometry>

#include "core/atomic_file.h"
#include "core/errors.h"
#include "core/number_text.h"

namespace pneufem {

std::string mm_point(const Eigen::Vector3d& p_m) {
  // Appended piece by piece: "(" + std::string trips GCC 12's -Wrestrict false positive (GCC bug 105329).
  std::string s = "(";
  s += short_num(p_m.x() * 1e3);
  s += ", ";
  s += short_num(p_m.y() * 1e3);
  s += ", ";
  s += short_num(p_m.z() * 1e3);
  s += ") mm";
  return s;
}

namespace {

constexpr const char* kRepairHint =
    "export the actuator from CAD as a closed solid body (not a surface or several touching bodies), or "
    "repair the file (MeshLab: Filters > Cleaning and Repairing > Remove Duplicate Vertices, then Close "
    "Holes / Repair non Manifold Edges; Blender: 3D-Print Toolbox > Make Manifold)";

/// Welds vertices with bit-identical coordinates (CAD exporters write shared corners identically).
class Welder {
 public:
  explicit Welder(TriSurface& s) : s_(s) {}
  int add(const Eigen::Vector3d& p) {
    const auto key = std::make_tuple(p.x(), p.y(), p.z());
    auto [it, fresh] = index_.try_emplace(key, static_cast<int>(s_.V.size()));
    if (fresh) s_.V.push_back(p * s_.unit_m);
    return it->second;
  }
  /// Adds a triangle of welded vertex ids; a triangle with a repeated vertex has no area or
  /// orientation and is counted, not kept.
  void triangle(int a, int b, int c) {
    if (a == b || b == c || c == a) {
      ++degenerate_;
      return;
    }
    s_.F.push_back({a, b, c});
  }
  void finish() {
    if (degenerate_ > 0)
      s_.notes.push_back(s_.path + ": " + std::to_string(degenerate_) +
                         " triangle(s) with two identical corners (no area) were dropped");
    if (s_.F.empty()) throw InputError(s_.path + ": no triangles found; is it an STL or OBJ file of a solid?");
  }

 private:
  TriSurface& s_;
  std::map<std::tuple<double, double, double>, int> index_;
  long degenerate_ = 0;
};

std::string read_all(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw InputError("cannot open surface file '" + path + "'; check the path (relative to the scene file)");
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

/// Binary STL: 80-byte header, uint32 count, then per triangle 12 floats (normal, 3 vertices) and
/// a uint16 attribute: 84 + 50 n bytes exactly.
bool is_binary_stl(const std::string& data) {
  if (data.size() < 84) return false;
  std::uint32_t n = 0;
  std::memcpy(&n, data.data() + 80, 4);
  return data.size() == 84 + 50ull * n;
}

void read_binary_stl(const std::string& data, Welder& w) {
  std::uint32_t n = 0;
  std::memcpy(&n, data.data() + 80, 4);
  for (std::uint32_t t = 0; t < n; ++t) {
    const char* rec = data.data() + 84 + 50ull * t;
    int id[3];
    for (int k = 0; k < 3; ++k) {
      float c[3];
      std::memcpy(c, rec + 12 + 12 * k, 12);
      if (!std::isfinite(c[0]) || !std::isfinite(c[1]) || !std::isfinite(c[2]))
        throw InputError("binary STL triangle " + std::to_string(t + 1) + " has a coordinate that is not a finite number");
      id[k] = w.add(Eigen::Vector3d(c[0], c[1], c[2]));
    }
    w.triangle(id[0], id[1], id[2]);
  }
}

/// ASCII STL: "solid", then facets of "facet normal n n n / outer loop / vertex x y z (x3) /
/// endloop / endfacet". The facet normal is ignored (orientation comes from the vertex order).
void read_ascii_stl(const std::string& path, const std::string& data, Welder& w) {
  std::istringstream in(data);
  std::string line;
  long lineno = 0;
  std::vector<int> loop;
  while (std::getline(in, line)) {
    ++lineno;
    std::istringstream ls(line);
    std::string word;
    if (!(ls >> word)) continue;
    std::transform(word.begin(), word.end(), word.begin(), ::tolower);
    if (word == "vertex") {
      double x, y, z;
      if (!(ls >> x >> y >> z) || !std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z))
        throw InputError(path + ":" + std::to_string(lineno) + ": expected 'vertex x y z' with three finite numbers, got '" +
                         line + "'");
      loop.push_back(w.add(Eigen::Vector3d(x, y, z)));
    } else if (word == "endloop") {
      if (loop.size() != 3)
        throw InputError(path + ":" + std::to_string(lineno) + ": a facet has " + std::to_string(loop.size()) +
                         " vertices; STL facets are triangles (re-export the file)");
      w.triangle(loop[0], loop[1], loop[2]);
      loop.clear();
    } else if (word == "outer") {
      loop.clear();
    } else if (word != "solid" && word != "facet" && word != "endfacet" && word != "endsolid") {
      throw InputError(path + ":" + std::to_string(lineno) + ": unexpected '" + word +
                       "' in an ASCII STL (expected facet, outer loop, vertex, endloop, endfacet)");
    }
  }
}

/// OBJ: "v x y z" and "f a b c ..." (a = v, v/vt or v/vt/vn; negative = relative to the end);
/// polygons are split into triangle fans. Other statements are ignored.
void read_obj(const std::string& path, const std::string& data, Welder& w) {
  std::istringstream in(data);
  std::string line;
  long lineno = 0;
  std::vector<int> ids;  // OBJ vertex -> welded id
  while (std::getline(in, line)) {
    ++lineno;
    std::istringstream ls(line);
    std::string word;
    if (!(ls >> word)) continue;
    const std::string where = path + ":" + std::to_string(lineno) + ": ";
    if (word == "v") {
      double x, y, z;
      if (!(ls >> x >> y >> z) || !std::isfinite(x) || !std::isfinite(y) || !std::isfinite(z))
        throw InputError(where + "expected 'v x y z' with three finite numbers, got '" + line + "'");
      ids.push_back(w.add(Eigen::Vector3d(x, y, z)));
    } else if (word == "f") {
      std::vector<int> poly;
      for (std::string tok; ls >> tok;) {
        long k = 0;
        try {
          k = std::stol(tok.substr(0, tok.find('/')));
        } catch (const std::exception&) {
          throw InputError(where + "'" + tok + "' is not a vertex index");
        }
        const long n = static_cast<long>(ids.size());
        const long i = k > 0 ? k - 1 : n + k;
        if (k == 0 || i < 0 || i >= n)
          throw InputError(where + "vertex index " + tok + " refers to no vertex (" + std::to_string(n) + " defined so far)");
        poly.push_back(ids[static_cast<std::size_t>(i)]);
      }
      if (poly.size() < 3) throw InputError(where + "a face needs at least 3 vertices");
      for (std::size_t k = 1; k + 1 < poly.size(); ++k) w.triangle(poly[0], poly[k], poly[k + 1]);
    }
  }
}

std::string lower_ext(const std::string& path) {
  const std::size_t dot = path.find_last_of('.');
  std::string e = dot == std::string::npos ? "" : path.substr(dot);
  std::transform(e.begin(), e.end(), e.begin(), ::tolower);
  return e;
}

/// A point in the file's units, for messages: "(1.5, 2, 0) mm".
std::string where_text(const TriSurface& s, const Eigen::Vector3d& p) {
  const Eigen::Vector3d q = p / s.unit_m;
  std::string out = "(";  // appended piece by piece: GCC 12 warns (-Wrestrict) on a + chain here
  out += short_num(q.x());
  out += ", ";
  out += short_num(q.y());
  out += ", ";
  out += short_num(q.z());
  out += s.unit_m == 1e-3 ? ") mm" : s.unit_m == 1.0 ? ") m" : ") file units";
  return out;
}

using EdgeKey = std::pair<int, int>;
struct EdgeKeyHash {
  std::size_t operator()(const EdgeKey& e) const {
    return std::hash<long long>()((static_cast<long long>(e.first) << 32) ^ static_cast<unsigned>(e.second));
  }
};

/// Per undirected edge: the triangles using it (triangle * 4 + 1 when it runs a -> b with a < b).
using EdgeMap = std::unordered_map<EdgeKey, std::vector<int>, EdgeKeyHash>;

EdgeMap edge_map(const TriSurface& s) {
  EdgeMap m;
  m.reserve(s.F.size() * 2);
  for (int f = 0; f < static_cast<int>(s.F.size()); ++f)
    for (int k = 0; k < 3; ++k) {
      const int a = s.F[f][k], b = s.F[f][(k + 1) % 3];
      m[{std::min(a, b), std::max(a, b)}].push_back(4 * f + (a < b ? 1 : 0));
    }
  return m;
}

void check_manifold(const TriSurface& s, const EdgeMap& edges) {
  long open = 0, nonmanifold = 0;
  std::string first_open, first_nm;
  std::vector<EdgeKey> keys;  // deterministic "first": the smallest vertex pair
  for (const auto& [e, fs] : edges)
    if (fs.size() != 2) keys.push_back(e);
  std::sort(keys.begin(), keys.end());
  for (const EdgeKey& e : keys) {
    const std::size_t n = edges.at(e).size();
    const std::string at = "from " + where_text(s, s.V[e.first]) + " to " + where_text(s, s.V[e.second]);
    if (n == 1) {
      if (open++ == 0) first_open = at;
    } else if (nonmanifold++ == 0) {
      first_nm = at + " (shared by " + std::to_string(n) + " triangles)";
    }
  }
  if (open == 0 && nonmanifold == 0) return;
  std::string msg = s.path + ": the surface is not a closed solid:";
  if (open > 0) {
    msg += ' ';
    msg += std::to_string(open);
    msg += " open edge(s) (used by one triangle only: a hole), the first " + first_open + ";";
  }
  if (nonmanifold > 0) {
    msg += ' ';
    msg += std::to_string(nonmanifold);
    msg += " non-manifold edge(s) (shared by more than two triangles), the first " + first_nm + ";";
  }
  throw InputError(msg + " pneufem needs a watertight, manifold surface to tell inside from outside: " + kRepairHint);
}

/// Edge-connected shells; triangles turned to agree with their neighbours: on a manifold edge the
/// two triangles must run in opposite directions. Returns how many were turned.
long orient_shells(TriSurface& s, const EdgeMap& edges) {
  const int nf = static_cast<int>(s.F.size());
  s.face_shell.assign(nf, -1);
  std::vector<char> flip(nf, 0);
  int shells = 0;
  for (int seed = 0; seed < nf; ++seed) {
    if (s.face_shell[seed] >= 0) continue;
    std::vector<int> stack{seed};
    s.face_shell[seed] = shells;
    while (!stack.empty()) {
      const int f = stack.back();
      stack.pop_back();
      for (int k = 0; k < 3; ++k) {
        const int a = s.F[f][k], b = s.F[f][(k + 1) % 3];
        const bool f_up = (a < b) != static_cast<bool>(flip[f]);  // f runs min -> max, as turned
        for (int code : edges.at({std::min(a, b), std::max(a, b)})) {
          const int g = code / 4;
          if (g == f) continue;
          const bool g_stored_up = code % 4 == 1;
          if (s.face_shell[g] < 0) {
            s.face_shell[g] = shells;
            flip[g] = g_stored_up == f_up ? 1 : 0;  // g must run max -> min
            stack.push_back(g);
          } else if ((g_stored_up != static_cast<bool>(flip[g])) == f_up) {
            throw InputError(s.path + ": the surface cannot be oriented (a Moebius-like band of triangles near " +
                             where_text(s, s.V[a]) + "): it has no inside; " + kRepairHint);
          }
        }
      }
    }
    ++shells;
  }
  // Within a shell the minority is the one that was wrong; the shell's side is decided later.
  std::vector<long> turned(shells, 0), size(shells, 0);
  for (int f = 0; f < nf; ++f) {
    turned[s.face_shell[f]] += flip[f];
    ++size[s.face_shell[f]];
  }
  long flipped = 0;
  for (int f = 0; f < nf; ++f) {
    const int sh = s.face_shell[f];
    const bool minority_turned = 2 * turned[sh] <= size[sh];
    if (static_cast<bool>(flip[f]) == minority_turned) std::swap(s.F[f][1], s.F[f][2]);
  }
  for (int sh = 0; sh < shells; ++sh) flipped += std::min(turned[sh], size[sh] - turned[sh]);
  s.shell_depth.assign(shells, 0);
  return flipped;
}

/// Rays for inside tests: a direction of no simple ratio, so that rays from CAD (axis-aligned)
/// geometry miss its edges and vertices.
const Eigen::Vector3d kRayDirection = Eigen::Vector3d(0.5773502691896258, 0.5772502691896257, 0.5774502691896256).normalized();

/// Möller-Trumbore: does the ray o + t d (t > 0) cross triangle (a, b, c)?
bool ray_hits(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
              const Eigen::Vector3d& c) {
  const Eigen::Vector3d e1 = b - a, e2 = c - a, p = d.cross(e2);
  const double det = e1.dot(p);
  if (std::abs(det) < 1e-300) return false;
  const Eigen::Vector3d t = o - a;
  const double u = t.dot(p) / det;
  if (u < 0.0 || u > 1.0) return false;
  const Eigen::Vector3d q = t.cross(e1);
  const double v = d.dot(q) / det;
  if (v < 0.0 || u + v > 1.0) return false;
  return e2.dot(q) / det > 0.0;
}

/// Nesting depth of each shell (by ray parity from a point of it against every other shell), then
/// each shell turned so that its normals leave the solid, with a note for each one turned.
void orient_outward(TriSurface& s) {
  const int ns = s.shells();
  std::vector<double> volume(ns, 0.0);
  std::vector<int> first(ns, -1);
  for (int f = 0; f < static_cast<int>(s.F.size()); ++f) {
    const auto& t = s.F[f];
    volume[s.face_shell[f]] += s.V[t[0]].dot(s.V[t[1]].cross(s.V[t[2]])) / 6.0;
    if (first[s.face_shell[f]] < 0) first[s.face_shell[f]] = f;
  }
  const Eigen::Vector3d& dir = kRayDirection;
  for (int sh = 0; sh < ns; ++sh) {
    const auto& t = s.F[first[sh]];
    const Eigen::Vector3d o = (s.V[t[0]] + s.V[t[1]] + s.V[t[2]]) / 3.0;
    std::vector<int> hits(ns, 0);
    for (int f = 0; f < static_cast<int>(s.F.size()); ++f)
      if (s.face_shell[f] != sh && ray_hits(o, dir, s.V[s.F[f][0]], s.V[s.F[f][1]], s.V[s.F[f][2]])) ++hits[s.face_shell[f]];
    for (int o2 = 0; o2 < ns; ++o2) s.shell_depth[sh] += hits[o2] % 2;
  }
  for (int sh = 0; sh < ns; ++sh) {
    const bool is_void = s.shell_depth[sh] % 2 == 1;
    if ((volume[sh] < 0.0) == is_void) continue;  // normals already leave the solid
    for (int f = 0; f < static_cast<int>(s.F.size()); ++f)
      if (s.face_shell[f] == sh) std::swap(s.F[f][1], s.F[f][2]);
    const auto& t = s.F[first[sh]];
    s.notes.push_back(s.path + ": the normals of shell " + std::to_string(sh + 1) + " (" +
                      std::to_string(std::count(s.face_shell.begin(), s.face_shell.end(), sh)) + " triangles, near " +
                      where_text(s, s.V[t[0]]) + ", " + (is_void ? "a void" : "a solid's outer boundary") +
                      ") pointed into the solid; they were reversed");
  }
}

}  // namespace

Eigen::Vector3d TriSurface::normal(int f) const {
  const auto& t = F[f];
  return (V[t[1]] - V[t[0]]).cross(V[t[2]] - V[t[0]]).normalized();
}

double TriSurface::area(int f) const {
  const auto& t = F[f];
  return 0.5 * (V[t[1]] - V[t[0]]).cross(V[t[2]] - V[t[0]]).norm();
}

TriSurface read_surface(const std::string& path, double unit_m) {
  TriSurface s;
  s.path = path;
  s.unit_m = unit_m;
  const std::string data = read_all(path);
  const std::string ext = lower_ext(path);
  Welder w(s);
  if (ext == ".obj") {
    read_obj(path, data, w);
  } else if (ext == ".stl") {
    if (is_binary_stl(data))
      read_binary_stl(data, w);
    else if (data.compare(0, 5, "solid") == 0)
      read_ascii_stl(path, data, w);
    else
      throw InputError(path + ": not an STL file: neither binary (84 + 50 n bytes for n triangles; this file has " +
                       std::to_string(data.size()) + " bytes) nor ASCII (starting with 'solid'); re-export it");
  } else {
    throw InputError(path + ": unknown surface format '" + ext + "'; give an .stl (binary or ASCII) or .obj file");
  }
  w.finish();
  return s;
}

namespace {

/// Does segment p -> q cross triangle (a, b, c) (Moeller-Trumbore, 0 < t < 1)?
bool segment_hits(const Eigen::Vector3d& p, const Eigen::Vector3d& q, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                  const Eigen::Vector3d& c) {
  const Eigen::Vector3d d = q - p, e1 = b - a, e2 = c - a, h = d.cross(e2);
  const double det = e1.dot(h);
  // Parallel, or in the triangle's plane: coplanar overlaps are not detected. det = e1 . (d x e2) is
  // a triple product; below 1e-12 of its largest value the segment lies in the plane to round-off
  // (a tilted flat CAD face is many triangles coplanar only to round-off), and u, v, t below would
  // be ratios of round-off errors: such pairs are no crossing.
  if (std::abs(det) <= 1e-12 * d.norm() * e1.norm() * e2.norm()) return false;
  const Eigen::Vector3d t = p - a;
  const double u = t.dot(h) / det;
  if (u < 0.0 || u > 1.0) return false;
  const Eigen::Vector3d w = t.cross(e1);
  const double v = d.dot(w) / det;
  if (v < 0.0 || u + v > 1.0) return false;
  const double at = e2.dot(w) / det;
  return at > 0.0 && at < 1.0;
}

bool triangles_cross(const TriSurface& s, int f, int g) {
  for (int k = 0; k < 3; ++k) {
    if (segment_hits(s.V[s.F[f][k]], s.V[s.F[f][(k + 1) % 3]], s.V[s.F[g][0]], s.V[s.F[g][1]], s.V[s.F[g][2]])) return true;
    if (segment_hits(s.V[s.F[g][k]], s.V[s.F[g][(k + 1) % 3]], s.V[s.F[f][0]], s.V[s.F[f][1]], s.V[s.F[f][2]])) return true;
  }
  return false;
}

/// Pairs of triangles without a common corner whose edges cross each other's interior: a surface
/// through itself (two bodies exported unmerged, a chamber poking through a wall). Candidates from
/// a uniform hash of the triangles' bounding boxes (cells of twice the mean edge length).
void check_self_intersections(const TriSurface& s) {
  const int nf = static_cast<int>(s.F.size());
  double mean = 0.0;
  for (const auto& t : s.F) mean += (s.V[t[1]] - s.V[t[0]]).norm();
  const double cell = 2.0 * mean / nf;
  std::unordered_map<std::uint64_t, std::vector<int>> grid;
  auto key = [](long i, long j, long k) {
    return (static_cast<std::uint64_t>(i & 0x1fffff) << 42) | (static_cast<std::uint64_t>(j & 0x1fffff) << 21) |
           static_cast<std::uint64_t>(k & 0x1fffff);
  };
  for (int f = 0; f < nf; ++f) {
    Eigen::Vector3d lo = s.V[s.F[f][0]], hi = lo;
    for (int v : s.F[f]) lo = lo.cwiseMin(s.V[v]), hi = hi.cwiseMax(s.V[v]);
    const Eigen::Vector3d a = (lo / cell).array().floor(), b = (hi / cell).array().floor();
    if ((b - a).prod() > 1e6) continue;  // a sliver spanning the part: left unchecked
    for (long i = static_cast<long>(a.x()); i <= static_cast<long>(b.x()); ++i)
      for (long j = static_cast<long>(a.y()); j <= static_cast<long>(b.y()); ++j)
        for (long k = static_cast<long>(a.z()); k <= static_cast<long>(b.z()); ++k) grid[key(i, j, k)].push_back(f);
  }
  std::unordered_set<std::uint64_t> tested;
  long crossings = 0;
  int first_f = -1;
  for (const auto& [c, fs] : grid)
    for (std::size_t x = 0; x < fs.size(); ++x)
      for (std::size_t y = x + 1; y < fs.size(); ++y) {
        const int f = std::min(fs[x], fs[y]), g = std::max(fs[x], fs[y]);
        bool shared = false;
        for (int u : s.F[f])
          for (int w : s.F[g]) shared = shared || u == w;
        if (shared || !tested.insert((static_cast<std::uint64_t>(f) << 32) | static_cast<std::uint32_t>(g)).second) continue;
        if (triangles_cross(s, f, g)) {
          ++crossings;
          if (first_f < 0 || f < first_f) first_f = f;
        }
      }
  if (crossings == 0) return;
  const auto& t = s.F[first_f];
  throw InputError(s.path + ": the surface intersects itself: " + std::to_string(crossings) +
                   " pair(s) of triangles cross, the first near " + where_text(s, (s.V[t[0]] + s.V[t[1]] + s.V[t[2]]) / 3.0) +
                   "; inside and outside are then not defined: merge the bodies in CAD (a Boolean union) before "
                   "exporting, or find the faces in MeshLab (Filters > Select > Select Self Intersecting Faces)");
}

}  // namespace

bool shell_encloses(const TriSurface& s, int shell, const Eigen::Vector3d& p) {
  int hits = 0;
  for (int f = 0; f < static_cast<int>(s.F.size()); ++f)
    if (s.face_shell[f] == shell && ray_hits(p, kRayDirection, s.V[s.F[f][0]], s.V[s.F[f][1]], s.V[s.F[f][2]])) ++hits;
  return hits % 2 == 1;
}

void close_and_orient(TriSurface& s) {
  const EdgeMap edges = edge_map(s);
  check_manifold(s, edges);
  check_self_intersections(s);
  const long flipped = orient_shells(s, edges);
  if (flipped > 0) {
    // Which half is "wrong" is decided per shell below; report the minority flipped here.
    s.notes.push_back(s.path + ": " + std::to_string(flipped) +
                      " triangle(s) disagreed with their neighbours' orientation and were turned");
  }
  orient_outward(s);
}

TriSurface read_closed_surface(const std::string& path, double unit_m) {
  TriSurface s = read_surface(path, unit_m);
  close_and_orient(s);
  return s;
}

void append_surface(TriSurface& a, const TriSurface& b, bool as_voids) {
  const int off = static_cast<int>(a.V.size());
  a.V.insert(a.V.end(), b.V.begin(), b.V.end());
  for (auto t : b.F) {
    if (as_voids) std::swap(t[1], t[2]);
    a.F.push_back({t[0] + off, t[1] + off, t[2] + off});
  }
  a.notes.insert(a.notes.end(), b.notes.begin(), b.notes.end());
}

void write_stl(const std::string& path, const TriSurface& s, double unit_m) {
  std::string out = "pneufem surface (binary STL)";
  out.resize(80, ' ');
  const std::uint32_t n = static_cast<std::uint32_t>(s.F.size());
  out.append(reinterpret_cast<const char*>(&n), 4);
  for (int f = 0; f < static_cast<int>(s.F.size()); ++f) {
    const Eigen::Vector3d nn = s.normal(f);
    float rec[12];
    for (int d = 0; d < 3; ++d) rec[d] = static_cast<float>(nn[d]);
    for (int k = 0; k < 3; ++k)
      for (int d = 0; d < 3; ++d) rec[3 + 3 * k + d] = static_cast<float>(s.V[s.F[f][k]][d] / unit_m);
    out.append(reinterpret_cast<const char*>(rec), sizeof rec);
    out.append(2, '\0');
  }
  write_file_atomic(path, out);
}

}  // namespace pneufem
