#include "scenes/inp/solid_split.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <map>
#include <sstream>
#include <stdexcept>
#include <unordered_map>

#include <Eigen/Geometry>

#include "core/errors.h"
#include "core/message_text.h"

namespace pneufem {

namespace {

/// Topology and reference geometry of one element shape (0-based, conventions of solid_split.h).
struct ShapeTables {
  int corners;
  int faces;
  int edges;
  std::array<std::array<int, 4>, 6> face;    ///< corners of S1..Sn in the Abaqus order; -1 ends a triangle
  std::array<std::array<int, 2>, 12> edge;   ///< corner pairs, in the order of the mid-edge nodes
  std::array<std::array<double, 3>, 8> ref;  ///< reference coordinates of the corners
};

constexpr ShapeTables kTet = {4, 4, 6,
                              {{{0, 1, 2, -1}, {0, 3, 1, -1}, {1, 3, 2, -1}, {2, 3, 0, -1}}},
                              {{{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}}},
                              {{{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}}}};
constexpr ShapeTables kPyramid = {5, 5, 8,
                                  {{{0, 1, 2, 3}, {0, 4, 1, -1}, {1, 4, 2, -1}, {2, 4, 3, -1}, {3, 4, 0, -1}}},
                                  {{{0, 1}, {1, 2}, {2, 3}, {3, 0}, {0, 4}, {1, 4}, {2, 4}, {3, 4}}},
                                  {{{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, {0, 0, 1}}}};
constexpr ShapeTables kWedge = {6, 5, 9,
                                {{{0, 1, 2, -1}, {3, 5, 4, -1}, {0, 3, 4, 1}, {1, 4, 5, 2}, {2, 5, 3, 0}}},
                                {{{0, 1}, {1, 2}, {2, 0}, {3, 4}, {4, 5}, {5, 3}, {0, 3}, {1, 4}, {2, 5}}},
                                {{{0, 0, -1}, {1, 0, -1}, {0, 1, -1}, {0, 0, 1}, {1, 0, 1}, {0, 1, 1}}}};
constexpr ShapeTables kHex = {
    8, 6, 12,
    {{{0, 1, 2, 3}, {4, 7, 6, 5}, {0, 4, 5, 1}, {1, 5, 6, 2}, {2, 6, 7, 3}, {3, 7, 4, 0}}},
    {{{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6}, {6, 7}, {7, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}}},
    {{{-1, -1, -1}, {1, -1, -1}, {1, 1, -1}, {-1, 1, -1}, {-1, -1, 1}, {1, -1, 1}, {1, 1, 1}, {-1, 1, 1}}}};

struct TypeInfo {
  const char* name;
  int nodes;
  bool quadratic;
  const ShapeTables* shape;
};

const TypeInfo& info(SolidType t) {
  static const std::array<TypeInfo, 7> table = {{{"C3D4", 4, false, &kTet},
                                                 {"C3D10", 10, true, &kTet},
                                                 {"C3D5", 5, false, &kPyramid},
                                                 {"C3D6", 6, false, &kWedge},
                                                 {"C3D15", 15, true, &kWedge},
                                                 {"C3D8", 8, false, &kHex},
                                                 {"C3D20", 20, true, &kHex}}};
  return table[static_cast<std::size_t>(t)];
}

int face_size(const ShapeTables& s, int f) { return s.face[static_cast<std::size_t>(f)][3] < 0 ? 3 : 4; }

bool face_has(const ShapeTables& s, int f, int corner) {
  const auto& c = s.face[static_cast<std::size_t>(f)];
  return std::find(c.begin(), c.begin() + face_size(s, f), corner) != c.begin() + face_size(s, f);
}

/// Index of the mid-edge node of the element edge (a, b) among the edges, or -1 if (a, b) is no edge.
int edge_index(const ShapeTables& s, int a, int b) {
  for (int k = 0; k < s.edges; ++k) {
    const auto& e = s.edge[static_cast<std::size_t>(k)];
    if ((e[0] == a && e[1] == b) || (e[0] == b && e[1] == a)) return k;
  }
  return -1;
}

Eigen::Vector3d ref(const ShapeTables& s, int corner) {
  const auto& r = s.ref[static_cast<std::size_t>(corner)];
  return Eigen::Vector3d(r[0], r[1], r[2]);
}

/// Shape function values of a type at reference point xi (not for the pyramid): the interpolations
/// of Abaqus Theory Guide, "Solid isoparametric quadrilaterals and hexahedra" and "Triangular,
/// tetrahedral, and wedge elements" (same node numbering).
///   tetrahedra: L = (1 - xi - eta - zeta, xi, eta, zeta); corners L_a (C3D10: L_a (2 L_a - 1)),
///     mid-edge 4 L_a L_b;
///   bricks, corner a at r_a in {-1, 1}^3: (1 + xi r_a)(1 + eta s_a)(1 + zeta t_a) / 8, times
///     (xi r_a + eta s_a + zeta t_a - 2) for C3D20; C3D20 mid-edge node with r_a = 0 (and likewise):
///     (1 - xi^2)(1 + eta s_a)(1 + zeta t_a) / 4;
///   wedges, L = (1 - g - h, g, h), corner a at r = r_a = -+1: L_a (1 + r r_a) / 2 (C3D15:
///     L_a (2 L_a - 1)(1 + r r_a) / 2 - L_a (1 - r^2) / 2); C3D15 mid-edge in a triangle
///     2 L_a L_b (1 + r r_a), on a vertical edge L_a (1 - r^2).
void shape_values(SolidType t, const Eigen::Vector3d& xi, double* N) {
  const TypeInfo& ti = info(t);
  const ShapeTables& s = *ti.shape;
  if (s.corners == 4) {  // barycentric L0 = 1 - xi - eta - zeta, L1 = xi, L2 = eta, L3 = zeta
    const std::array<double, 4> L = {1.0 - xi.sum(), xi[0], xi[1], xi[2]};
    for (int a = 0; a < 4; ++a) N[a] = ti.quadratic ? L[a] * (2.0 * L[a] - 1.0) : L[a];
    if (ti.quadratic)
      for (int k = 0; k < 6; ++k) N[4 + k] = 4.0 * L[s.edge[k][0]] * L[s.edge[k][1]];
    return;
  }
  if (s.corners == 8) {
    for (int a = 0; a < 8; ++a) {
      const Eigen::Vector3d r = ref(s, a);
      const double p = (1 + xi[0] * r[0]) * (1 + xi[1] * r[1]) * (1 + xi[2] * r[2]) / 8.0;
      N[a] = ti.quadratic ? p * (xi.dot(r) - 2.0) : p;
    }
    if (ti.quadratic)
      for (int k = 0; k < 12; ++k) {
        const Eigen::Vector3d m = 0.5 * (ref(s, s.edge[k][0]) + ref(s, s.edge[k][1]));  // one coordinate is 0
        double v = 0.25;
        for (int d = 0; d < 3; ++d) v *= m[d] == 0.0 ? 1.0 - xi[d] * xi[d] : 1.0 + xi[d] * m[d];
        N[8 + k] = v;
      }
    return;
  }
  // Wedge: triangle coordinates (L, g, h) times linear or quadratic functions of r.
  const std::array<double, 3> L = {1.0 - xi[0] - xi[1], xi[0], xi[1]};
  const double r = xi[2];
  for (int a = 0; a < 6; ++a) {
    const double ra = a < 3 ? -1.0 : 1.0, l = L[static_cast<std::size_t>(a % 3)];
    N[a] = ti.quadratic ? 0.5 * l * (2.0 * l - 1.0) * (1.0 + r * ra) - 0.5 * l * (1.0 - r * r) : 0.5 * l * (1.0 + r * ra);
  }
  if (ti.quadratic)
    for (int k = 0; k < 9; ++k) {
      const int a = s.edge[k][0], b = s.edge[k][1];
      N[6 + k] = k < 6 ? 2.0 * L[a % 3] * L[b % 3] * (1.0 + r * (a < 3 ? -1.0 : 1.0))  // in a triangle
                       : L[a % 3] * (1.0 - r * r);                                      // vertical edge
    }
}

/// Signed volume of a tetrahedron.
double tet_volume(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                  const Eigen::Vector3d& d) {
  return (b - a).cross(c - a).dot(d - a) / 6.0;
}

using LocalTet = std::array<int, 4>;  // element corners

/// The two triangles (or the one) of face f, a quadrilateral cut along the diagonal through its
/// corner of smallest id; in the face's corner order.
int face_triangles(const ShapeTables& s, int f, const long* id, std::array<std::array<int, 3>, 2>& tri) {
  const auto& c = s.face[static_cast<std::size_t>(f)];
  if (face_size(s, f) == 3) {
    tri[0] = {c[0], c[1], c[2]};
    return 1;
  }
  int k = 0;
  for (int j = 1; j < 4; ++j)
    if (id[c[j]] < id[c[k]]) k = j;
  tri[0] = {c[k], c[(k + 1) % 4], c[(k + 2) % 4]};
  tri[1] = {c[k], c[(k + 2) % 4], c[(k + 3) % 4]};
  return 2;
}

/// Tetrahedra of one pyramid, wedge or hexahedron whose corners have the ids `id`, positively
/// oriented in the reference element (solid_split.h: the cone from the smallest corner, or the
/// 5-tetrahedron split of a hexahedron).
int decompose(const ShapeTables& s, const long* id, std::array<LocalTet, 6>& tets) {
  int v = 0;
  for (int c = 1; c < s.corners; ++c)
    if (id[c] < id[v]) v = c;
  int n = 0;
  if (&s == &kHex) {
    // Corners by how many reference coordinates differ from v's: 0 (v), 1 (neighbours), 2 (across a
    // face), 3 (the opposite corner o). The even ones span the central tetrahedron of the 5-split,
    // which exists when every face away from v is cut along its even diagonal, i.e. not through o.
    auto differ = [&](int a, int b) { return static_cast<int>((ref(s, a) - ref(s, b)).cwiseAbs().count()); };
    bool five = true;
    for (int f = 0; f < s.faces; ++f) {
      if (face_has(s, f, v)) continue;
      std::array<std::array<int, 3>, 2> tri{};
      face_triangles(s, f, id, tri);
      five = five && differ(tri[0][0], v) % 2 == 0;  // the diagonal runs from tri[0][0]
    }
    if (five) {
      LocalTet centre{};
      int m = 0;
      for (int b = 0; b < 8; ++b) {
        if (differ(b, v) % 2 == 0) {
          centre[static_cast<std::size_t>(m++)] = b;
          continue;
        }
        LocalTet corner{b, 0, 0, 0};
        int k = 1;
        for (int a = 0; a < 8; ++a)
          if (differ(a, b) == 1) corner[static_cast<std::size_t>(k++)] = a;
        tets[static_cast<std::size_t>(n++)] = corner;
      }
      tets[static_cast<std::size_t>(n++)] = centre;
    }
  }
  if (n == 0)
    for (int f = 0; f < s.faces; ++f) {
      if (face_has(s, f, v)) continue;
      std::array<std::array<int, 3>, 2> tri{};
      const int nt = face_triangles(s, f, id, tri);
      for (int k = 0; k < nt; ++k) tets[static_cast<std::size_t>(n++)] = {tri[k][0], tri[k][1], tri[k][2], v};
    }
  for (int k = 0; k < n; ++k) {
    LocalTet& t = tets[static_cast<std::size_t>(k)];
    if (tet_volume(ref(s, t[0]), ref(s, t[1]), ref(s, t[2]), ref(s, t[3])) < 0.0) std::swap(t[1], t[2]);
  }
  return n;
}

/// How to write an element's nodes so that its split tetrahedra have positive volume.
std::string node_order_hint(SolidType t) {
  switch (t) {
    case SolidType::C3D5:
      return "base 1-2-3-4 counter-clockwise seen from the apex 5";
    case SolidType::C3D6:
    case SolidType::C3D15:
      return "corners 1-2-3 counter-clockwise seen from the opposite triangle 4-5-6, node 4 opposite node 1";
    default:
      return "corners 1-2-3-4 counter-clockwise seen from the opposite face 5-6-7-8, node 5 opposite node 1";
  }
}

}  // namespace

std::optional<SolidType> solid_type(const std::string& type) {
  // Formulation variants of the Abaqus library that share the node layout of their base type.
  static const std::array<const char*, 10> suffixes = {"", "H", "R", "I", "M", "S", "RH", "IH", "MH", "HS"};
  for (int k = 0; k < 7; ++k) {
    const std::string base = info(static_cast<SolidType>(k)).name;
    if (type.compare(0, base.size(), base) != 0) continue;
    const std::string rest = type.substr(base.size());
    if (std::find(suffixes.begin(), suffixes.end(), rest) != suffixes.end()) return static_cast<SolidType>(k);
  }
  return std::nullopt;
}

const char* solid_name(SolidType t) { return info(t).name; }
int solid_nodes(SolidType t) { return info(t).nodes; }
int solid_faces(SolidType t) { return info(t).shape->faces; }
bool solid_quadratic(SolidType t) { return info(t).quadratic; }

Eigen::Vector3d solid_reference_node(SolidType t, int k) {
  const ShapeTables& s = *info(t).shape;
  if (k < s.corners) return ref(s, k);
  const auto& e = s.edge[static_cast<std::size_t>(k - s.corners)];
  return 0.5 * (ref(s, e[0]) + ref(s, e[1]));
}

Eigen::Vector3d solid_point(SolidType t, const int* nodes, const std::vector<Eigen::Vector3d>& X,
                            const Eigen::Vector3d& xi) {
  if (t == SolidType::C3D5) throw std::logic_error("solid_point: no isoparametric map for the pyramid");
  std::array<double, 20> N{};
  shape_values(t, xi, N.data());
  Eigen::Vector3d x = Eigen::Vector3d::Zero();
  for (int a = 0; a < info(t).nodes; ++a) x += N[static_cast<std::size_t>(a)] * X[static_cast<std::size_t>(nodes[a])];
  return x;
}

namespace {

/// The largest id of each id scope (one scope when the mesh has none): new ids continue them.
struct IdScopes {
  bool element_scoped = false, node_scoped = false;
  std::vector<long> last_element_id, last_node_id;  // per scope

  static long& last_id(std::vector<long>& last, std::size_t scope) {
    if (scope >= last.size()) last.resize(scope + 1, 0);
    return last[scope];
  }
};

IdScopes id_scopes(const Mesh& mesh, int ns, int n_original) {
  IdScopes sc;
  sc.element_scoped = mesh.element_scope.size() == static_cast<std::size_t>(ns);
  sc.node_scoped = mesh.node_scope.size() == static_cast<std::size_t>(n_original);
  for (std::size_t e = 0; e < mesh.element_ids.size(); ++e) {
    long& last = IdScopes::last_id(sc.last_element_id, sc.element_scoped ? mesh.element_scope[e] : 0);
    last = std::max(last, mesh.element_ids[e]);
  }
  for (std::size_t n = 0; n < mesh.node_ids.size(); ++n) {
    long& last = IdScopes::last_id(sc.last_node_id, sc.node_scoped ? mesh.node_scope[n] : 0);
    last = std::max(last, mesh.node_ids[n]);
  }
  return sc;
}

/// The solids as tetrahedra, solid after solid, as split_element builds them.
struct Tetrahedra {
  std::vector<int> conn;
  std::vector<int> first_tet;  ///< per solid (and one past the last): its first tetrahedron
  std::vector<long> ids;
  std::vector<std::uint16_t> region;
  std::vector<ElementSource> sources;
  std::vector<std::uint16_t> element_scope;
  // New mid-nodes on cut diagonals, keyed by the diagonal's corner nodes, and the nodes of the face
  // (or element) each lies on, which decide its sets and boundary dofs.
  std::unordered_map<std::uint64_t, int> diagonal_node;
  std::vector<std::vector<int>> support;
  std::map<SolidType, std::pair<int, int>> split_count;  // type -> elements, tetrahedra
};

/// The mid-node of the diagonal (a, b) (local corners of solid `n`, not an edge of it): made at its
/// first use, with the nodes of the face (or element) it lies on.
int diagonal_mid_node(Mesh& mesh, SolidType t, const int* n, int a, int b, IdScopes& sc, Tetrahedra& out) {
  const TypeInfo& ti = info(t);
  const ShapeTables& sh = *ti.shape;
  const auto [lo, hi] = std::minmax(n[a], n[b]);
  const std::uint64_t key = (static_cast<std::uint64_t>(lo) << 32) | static_cast<std::uint32_t>(hi);
  auto [it, fresh] = out.diagonal_node.try_emplace(key, mesh.num_nodes());
  if (fresh) {
    mesh.X.push_back(solid_point(t, n, mesh.X, 0.5 * (ref(sh, a) + ref(sh, b))));
    const std::uint16_t node_scope = sc.node_scoped ? mesh.node_scope[static_cast<std::size_t>(n[0])] : 0;
    mesh.node_ids.push_back(++IdScopes::last_id(sc.last_node_id, node_scope));
    if (sc.node_scoped) mesh.node_scope.push_back(node_scope);
    std::vector<int> on;
    int f = 0;
    while (f < sh.faces && !(face_has(sh, f, a) && face_has(sh, f, b))) ++f;
    if (f == sh.faces) {
      on.assign(n, n + ti.nodes);  // a body diagonal: inside the element
    } else {
      const auto& fc = sh.face[static_cast<std::size_t>(f)];
      for (int j = 0; j < 4; ++j) {
        on.push_back(n[fc[static_cast<std::size_t>(j)]]);
        on.push_back(n[sh.corners + edge_index(sh, fc[static_cast<std::size_t>(j)], fc[(j + 1) % 4])]);
      }
    }
    out.support.push_back(std::move(on));
  }
  return it->second;
}

/// Solid `s` as tetrahedra appended to `out` (a deck's own tetrahedron as it is); InputError for a
/// collapsed, inverted or degenerate element.
void split_element(const SolidElements& solids, int s, Mesh& mesh, const std::function<std::string(int)>& where,
                   IdScopes& sc, Tetrahedra& out) {
  const bool quadratic = mesh.type == ElementType::Tet10;
  const SolidType t = solids.type[static_cast<std::size_t>(s)];
  const TypeInfo& ti = info(t);
  const ShapeTables& sh = *ti.shape;
  const int* n = solids.element(s);
  const long id = mesh.element_ids[static_cast<std::size_t>(s)];
  const std::uint16_t scope = sc.element_scoped ? mesh.element_scope[static_cast<std::size_t>(s)] : 0;
  auto label = [&] { return "element " + std::to_string(id) + " (" + ti.name + ")"; };
  for (int a = 0; a < ti.nodes; ++a)
    for (int b = a + 1; b < ti.nodes; ++b)
      if (n[a] == n[b])
        throw InputError(printable(where(s) + ": " + label() + " lists node " +
                         std::to_string(mesh.node_ids[static_cast<std::size_t>(n[a])]) +
                         " twice (a collapsed element); write it as the element it collapses to (C3D6 wedge, C3D5 "
                         "pyramid or C3D4 tetrahedron) with distinct nodes"));
  out.first_tet[static_cast<std::size_t>(s)] = static_cast<int>(out.ids.size());
  const std::uint16_t r = mesh.region[static_cast<std::size_t>(s)];
  if (&sh == &kTet) {  // the deck's own tetrahedra stay as they are
    out.conn.insert(out.conn.end(), n, n + mesh.npe());
    out.ids.push_back(id);
    out.region.push_back(r);
    out.element_scope.push_back(scope);
    out.sources.push_back(ElementSource{id, 0, 0, {}});
    return;
  }
  std::array<long, 8> cid{};
  for (int c = 0; c < sh.corners; ++c) cid[static_cast<std::size_t>(c)] = mesh.node_ids[static_cast<std::size_t>(n[c])];
  std::array<LocalTet, 6> tets{};
  const int nt = decompose(sh, cid.data(), tets);
  // Zero volume up to round-off relative to the element size: an inverted or flat element.
  double size = 0.0;
  for (int c = 1; c < sh.corners; ++c) size = std::max(size, (mesh.X[n[c]] - mesh.X[n[0]]).norm());
  for (int k = 0; k < nt; ++k) {
    const LocalTet& lt = tets[static_cast<std::size_t>(k)];
    const double V = tet_volume(mesh.X[n[lt[0]]], mesh.X[n[lt[1]]], mesh.X[n[lt[2]]], mesh.X[n[lt[3]]]);
    if (!(V > 1e-10 * size * size * size)) {
      std::ostringstream msg;
      msg << where(s) << ": " << label() << " is inverted or degenerate: its tetrahedron on nodes "
          << mesh.node_ids[n[lt[0]]] << ", " << mesh.node_ids[n[lt[1]]] << ", " << mesh.node_ids[n[lt[2]]] << ", "
          << mesh.node_ids[n[lt[3]]] << " has " << (V < 0.0 ? "negative" : "zero") << " volume; check the node order ("
          << ti.name << ": " << node_order_hint(t) << ") or remesh this element (too distorted to split)";
      throw InputError(printable(msg.str()));
    }
    for (int c : lt) out.conn.push_back(n[c]);
    if (quadratic)
      for (int k_tet = 0; k_tet < kTet.edges; ++k_tet) {
        const auto& e = kTet.edge[static_cast<std::size_t>(k_tet)];
        const int a = lt[static_cast<std::size_t>(e[0])], b = lt[static_cast<std::size_t>(e[1])];
        const int k_edge = edge_index(sh, a, b);
        out.conn.push_back(k_edge >= 0 ? n[sh.corners + k_edge] : diagonal_mid_node(mesh, t, n, a, b, sc, out));
      }
    out.ids.push_back(k == 0 ? id : ++IdScopes::last_id(sc.last_element_id, scope));
    out.region.push_back(r);
    out.element_scope.push_back(scope);
    ElementSource src{id, static_cast<std::uint8_t>(k + 1), static_cast<std::uint8_t>(nt), {}};
    std::strncpy(src.type.data(), ti.name, src.type.size() - 1);
    out.sources.push_back(src);
  }
  auto& count = out.split_count[t];
  ++count.first;
  count.second += nt;
}

// Node sets and boundary dofs reach the new nodes whose face lies wholly in them.
void extend_node_sets(Mesh& mesh, InpDeck& deck, const SplitSets& also, int n_original,
                      const std::vector<std::vector<int>>& support) {
  const int n_new = mesh.num_nodes() - n_original;
  auto remap_node_set = [&](std::vector<int>& nodes) {
    if (n_new == 0) return;
    std::vector<char> in(static_cast<std::size_t>(n_original), 0);
    for (int i : nodes) in[static_cast<std::size_t>(i)] = 1;
    for (int k = 0; k < n_new; ++k)
      if (std::all_of(support[k].begin(), support[k].end(), [&](int i) { return in[static_cast<std::size_t>(i)] != 0; }))
        nodes.push_back(n_original + k);
  };
  for (auto& [name, nodes] : mesh.node_sets) remap_node_set(nodes);
  for (auto* sets : also.node_sets)
    for (auto& [name, nodes] : *sets) remap_node_set(nodes);
  if (n_new > 0 && !deck.fixed_dofs.empty()) {
    std::vector<std::array<char, 3>> fixed(static_cast<std::size_t>(n_original), {0, 0, 0});
    for (const auto& [node, dof] : deck.fixed_dofs) fixed[static_cast<std::size_t>(node)][static_cast<std::size_t>(dof)] = 1;
    for (int k = 0; k < n_new; ++k)
      for (int d = 0; d < 3; ++d)
        if (std::all_of(support[k].begin(), support[k].end(), [&](int i) { return fixed[static_cast<std::size_t>(i)][d] != 0; }))
          deck.fixed_dofs.emplace_back(n_original + k, d);
  }
}

// Element sets, surfaces and pressure faces move to the tetrahedra.
void move_sets_to_tetrahedra(const SolidElements& solids, const Tetrahedra& tets, Mesh& mesh, InpDeck& deck,
                             const SplitSets& also) {
  const std::vector<int>& first_tet = tets.first_tet;
  const int npe = mesh.npe();
  auto remap_element_set = [&](std::vector<int>& members) {
    std::vector<int> out;
    for (int s : members)
      for (int e = first_tet[static_cast<std::size_t>(s)]; e < first_tet[static_cast<std::size_t>(s) + 1]; ++e)
        out.push_back(e);
    members = std::move(out);
  };
  for (auto& [name, members] : mesh.element_sets) remap_element_set(members);
  for (auto* sets : also.element_sets)
    for (auto& [name, members] : *sets) remap_element_set(members);
  // The tetrahedron faces that tile face f of solid s: those with all three corners on it.
  auto tile = [&](const FaceRef& face, auto&& emit) {
    const int s = face.element;
    const ShapeTables& sh = *info(solids.type[static_cast<std::size_t>(s)]).shape;
    const int e0 = first_tet[static_cast<std::size_t>(s)];
    if (&sh == &kTet) return emit(FaceRef{e0, face.local_face});
    const int* n = solids.element(s);
    const auto& fc = sh.face[static_cast<std::size_t>(face.local_face)];
    const int* fc_end = fc.data() + face_size(sh, face.local_face);
    for (int e = e0; e < first_tet[static_cast<std::size_t>(s) + 1]; ++e)
      for (int lf = 0; lf < 4; ++lf) {
        const int* ln = kTet.face[static_cast<std::size_t>(lf)].data();
        const int* tn = tets.conn.data() + static_cast<std::size_t>(e) * npe;
        if (std::all_of(ln, ln + 3, [&](int j) {
              return std::any_of(fc.data(), fc_end, [&](int c) { return n[c] == tn[j]; });
            }))
          emit(FaceRef{e, lf});
      }
  };
  auto remap_surface = [&](std::vector<FaceRef>& faces) {
    std::vector<FaceRef> out;
    for (const FaceRef& f : faces) tile(f, [&](const FaceRef& g) { out.push_back(g); });
    faces = std::move(out);
  };
  for (auto& [name, faces] : mesh.surfaces) remap_surface(faces);
  for (auto* surfaces : also.surfaces)
    for (auto& [name, faces] : *surfaces) remap_surface(faces);
  std::vector<InpPressure> pressure;
  for (const InpPressure& p : deck.pressure_faces)
    tile(p.face, [&](const FaceRef& g) { pressure.push_back(InpPressure{g, p.magnitude}); });
  deck.pressure_faces = std::move(pressure);
}

// A deck's own tetrahedra glued to a quadrilateral face along its other diagonal leave the mesh
// non-conforming there (a pyramid belongs between hexahedra and tetrahedra); split elements cut
// every shared face alike. A warning names the first such face.
void warn_nonconforming(const SolidElements& solids, const std::vector<int>& first_tet, const Mesh& mesh, InpDeck& deck,
                        const std::function<std::string(int)>& where) {
  const int ns = solids.size();
  auto sorted = [](std::array<int, 3> k) {
    std::sort(k.begin(), k.end());
    return k;
  };
  std::vector<std::array<int, 3>> deck_tet_faces;
  for (int s = 0; s < ns; ++s) {
    if (info(solids.type[static_cast<std::size_t>(s)]).shape != &kTet) continue;
    const int* tn = mesh.element(first_tet[static_cast<std::size_t>(s)]);
    for (int lf = 0; lf < kTet.faces; ++lf) {
      const auto& ln = kTet.face[static_cast<std::size_t>(lf)];
      deck_tet_faces.push_back(sorted({tn[ln[0]], tn[ln[1]], tn[ln[2]]}));
    }
  }
  std::sort(deck_tet_faces.begin(), deck_tet_faces.end());
  auto deck_tet_face = [&](const std::array<int, 3>& k) {
    return std::binary_search(deck_tet_faces.begin(), deck_tet_faces.end(), k);
  };
  int mismatched = 0, first_mismatch = -1;
  std::string mismatch;
  for (int s = 0; s < ns; ++s) {
    const SolidType t = solids.type[static_cast<std::size_t>(s)];
    const ShapeTables& sh = *info(t).shape;
    if (&sh == &kTet) continue;
    const int* n = solids.element(s);
    for (int f = 0; f < sh.faces; ++f) {
      if (face_size(sh, f) != 4) continue;
      const auto& c = sh.face[static_cast<std::size_t>(f)];
      int k = 0;  // our diagonal runs from the corner of smallest id; the other from the next one
      for (int j = 1; j < 4; ++j)
        if (mesh.node_ids[n[c[j]]] < mesh.node_ids[n[c[k]]]) k = j;
      const int a = n[c[(k + 1) % 4]], b = n[c[(k + 2) % 4]], d = n[c[(k + 3) % 4]], o = n[c[k]];
      if (deck_tet_face(sorted({a, b, d})) || deck_tet_face(sorted({a, d, o}))) {
        if (mismatched++ == 0) {
          first_mismatch = s;
          mismatch = "face S" + std::to_string(f + 1) + " of " + solid_name(t) + " " +
                     std::to_string(mesh.element_ids[static_cast<std::size_t>(first_tet[static_cast<std::size_t>(s)])]);
        }
      }
    }
  }
  if (mismatched > 0)
    deck.warnings.push_back(where(first_mismatch) + ": " + std::to_string(mismatched) +
                            " quadrilateral face(s) meet tetrahedra of the deck that cut them along the other diagonal "
                            "(first: " + mismatch +
                            "), so the mesh does not conform there; put C3D5 pyramids between hexahedra or wedges and "
                            "tetrahedra, or mesh that region with one element shape");
}

/// The note of what was split into what (at the first split element, `first_split`).
std::string split_note(const std::map<SolidType, std::pair<int, int>>& split_count, bool quadratic, int n_new,
                       const std::string& first_split) {
  std::ostringstream note;
  note << first_split << ": split into tetrahedra for pneufem's engine:";
  bool comma = false;
  for (const auto& [t, count] : split_count) {
    note << (comma ? "," : "") << " " << count.first << " " << solid_name(t) << " into " << count.second;
    comma = true;
  }
  note << (quadratic ? " C3D10" : " C3D4")
       << " (each quadrilateral face cut along the diagonal through its smallest node id, so neighbours match)";
  if (quadratic)
    note << "; " << n_new << " new node(s) on the cut diagonals";
  else
    note << "; linear tetrahedra lock for nearly incompressible silicone: mesh.promote_to_tet10 = true (recommended) "
            "makes them Tet10";
  return note.str();
}

}  // namespace

void split_solids(const SolidElements& solids, InpDeck& deck, const std::function<std::string(int)>& where,
                  const SplitSets& also) {
  Mesh& mesh = deck.mesh;
  const int ns = solids.size();
  const int n_original = mesh.num_nodes();
  IdScopes sc = id_scopes(mesh, ns, n_original);
  Tetrahedra tets;
  tets.first_tet.assign(static_cast<std::size_t>(ns) + 1, 0);
  for (int s = 0; s < ns; ++s) split_element(solids, s, mesh, where, sc, tets);
  tets.first_tet[static_cast<std::size_t>(ns)] = static_cast<int>(tets.ids.size());

  const int n_new = mesh.num_nodes() - n_original;
  extend_node_sets(mesh, deck, also, n_original, tets.support);
  move_sets_to_tetrahedra(solids, tets, mesh, deck, also);

  mesh.conn = std::move(tets.conn);
  mesh.element_ids = std::move(tets.ids);
  mesh.region = std::move(tets.region);
  if (sc.element_scoped) mesh.element_scope = std::move(tets.element_scope);
  if (tets.split_count.empty()) return;
  mesh.element_sources = std::move(tets.sources);

  warn_nonconforming(solids, tets.first_tet, mesh, deck, where);
  int first_split = 0;
  while (info(solids.type[static_cast<std::size_t>(first_split)]).shape == &kTet) ++first_split;
  deck.warnings.push_back(split_note(tets.split_count, mesh.type == ElementType::Tet10, n_new, where(first_split)));
}

void promote_deck_to_tet10(InpDeck& deck) {
  if (deck.mesh.type == ElementType::Tet10) return;
  const int n_original = deck.mesh.num_nodes();
  deck.mesh = promote_to_tet10(deck.mesh);
  if (deck.fixed_dofs.empty()) return;
  std::vector<std::array<char, 3>> fixed(static_cast<std::size_t>(deck.mesh.num_nodes()), {0, 0, 0});
  for (const auto& [node, dof] : deck.fixed_dofs) fixed[static_cast<std::size_t>(node)][static_cast<std::size_t>(dof)] = 1;
  // Each new mid-edge node once, in node order (the dofs' order of appearance continues with them).
  std::vector<std::array<int, 2>> corners(deck.mesh.X.size(), {-1, -1});
  for (int e = 0; e < deck.mesh.num_elements(); ++e) {
    const int* n = deck.mesh.element(e);
    for (int k = 0; k < 6; ++k)
      if (n[4 + k] >= n_original) corners[static_cast<std::size_t>(n[4 + k])] = {n[kTet.edge[k][0]], n[kTet.edge[k][1]]};
  }
  for (int m = n_original; m < deck.mesh.num_nodes(); ++m) {
    const auto [a, b] = corners[static_cast<std::size_t>(m)];
    for (int d = 0; d < 3; ++d)
      if (fixed[static_cast<std::size_t>(a)][d] && fixed[static_cast<std::size_t>(b)][d]) deck.fixed_dofs.emplace_back(m, d);
  }
}

}  // namespace pneufem
