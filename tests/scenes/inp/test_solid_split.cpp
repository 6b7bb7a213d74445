// Decks of hexahedra, wedges and pyramids split into tetrahedra (scenes/inp/solid_split.h), the split
// itself: each element type for every order of its corner ids, curved quadratic elements, the
// labels and notes of the pieces, conformity between neighbours in generated blocks with random
// node ids and in mixed decks, and bad elements refused. What follows the split (sets, surfaces,
// loads, instances, and the system tests) is in test_solid_split_sets.cpp; hexahedral actuator
// decks and quadrilateral surface elements in test_solid_split_actuator.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <numeric>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "scenes/inp/deck.h"
#include "scenes/inp/solid_split.h"
#include "tests/scenes/inp/solid_split_helpers.h"

namespace pneufem {
namespace {

using namespace test;

// ------------------------------------------------------------------------------------------------
// Geometry of a tetrahedral mesh
// ------------------------------------------------------------------------------------------------

std::array<int, 3> sorted_corners(const Mesh& m, const FaceRef& f) {
  const int* ln = face_local_nodes(m.type, f.local_face);
  const int* n = m.element(f.element);
  std::array<int, 3> k = {n[ln[0]], n[ln[1]], n[ln[2]]};
  std::sort(k.begin(), k.end());
  return k;
}

/// How many tetrahedra have each face (by its corners); conforming = every count is 1 or 2.
std::map<std::array<int, 3>, int> face_counts(const Mesh& m) {
  std::map<std::array<int, 3>, int> c;
  for (int e = 0; e < m.num_elements(); ++e)
    for (int f = 0; f < 4; ++f) ++c[sorted_corners(m, FaceRef{e, f})];
  return c;
}

/// The same by all six nodes of a Tet10 face: equal to face_counts when neighbours share their
/// mid-edge nodes too.
std::map<std::array<int, 6>, int> face_counts6(const Mesh& m) {
  std::map<std::array<int, 6>, int> c;
  for (int e = 0; e < m.num_elements(); ++e)
    for (int f = 0; f < 4; ++f) {
      const int* ln = face_local_nodes(m.type, f);
      std::array<int, 6> k{};
      for (int j = 0; j < 6; ++j) k[static_cast<std::size_t>(j)] = m.element(e)[ln[j]];
      std::sort(k.begin(), k.end());
      ++c[k];
    }
  return c;
}

double mesh_volume(const Mesh& m) {
  double v = 0.0;
  for (int e = 0; e < m.num_elements(); ++e) v += corner_volume(m, e);
  return v;
}

double min_volume(const Mesh& m) {
  double v = INFINITY;
  for (int e = 0; e < m.num_elements(); ++e) v = std::min(v, corner_volume(m, e));
  return v;
}

// ------------------------------------------------------------------------------------------------
// One element split directly
// ------------------------------------------------------------------------------------------------

/// A deck of one element of type t with nodes X and ids, split.
InpDeck split_one(SolidType t, const std::vector<Vec>& X, const std::vector<long>& ids) {
  InpDeck d;
  d.mesh.type = solid_quadratic(t) ? ElementType::Tet10 : ElementType::Tet4;
  d.mesh.X = X;
  d.mesh.node_ids = ids;
  d.mesh.element_ids = {57};
  d.mesh.region = {d.mesh.region_id("default")};
  SolidElements s;
  std::vector<int> nodes(X.size());
  std::iota(nodes.begin(), nodes.end(), 0);
  s.add(t, nodes);
  split_solids(s, d, [](int) { return std::string("one.inp:3"); });
  return d;
}

/// Exact volumes and boundary areas of the test elements (frustum: h/3 (A1 + A2 + sqrt(A1 A2))).
struct Exact {
  double volume, surface;
};
Exact exact_of(SolidType t) {
  auto trap_area = [](double a, double b, double h) { return 0.5 * (a + b) * h; };
  if (t == SolidType::C3D8) {
    const double slant = std::hypot(0.5, 1.2);
    return {1.2 / 3 * (4 + 1 + 2), 4 + 1 + 4 * trap_area(2, 1, slant)};
  }
  if (t == SolidType::C3D6) {
    const std::vector<Vec> X = frustum_wedge();
    const double A1 = 2.0, A2 = 0.5;
    double s = A1 + A2;
    for (int a = 0; a < 3; ++a) {  // trapezoids: two triangles each (planar)
      const int b = (a + 1) % 3;
      s += area(X[a], X[b], X[b + 3]) + area(X[a], X[b + 3], X[a + 3]);
    }
    return {1.0 / 3 * (A1 + A2 + std::sqrt(A1 * A2)), s};
  }
  const std::vector<Vec> X = skew_pyramid();
  double s = 2.0;
  for (int a = 0; a < 4; ++a) s += area(X[a], X[(a + 1) % 4], X[4]);
  return {2.0 * 1.5 / 3, s};
}

/// Faces of an element (corner lists, the Abaqus order of solid_split.h, 0-based).
std::vector<std::vector<int>> corner_faces(SolidType t) {
  if (t == SolidType::C3D8) return {{0, 1, 2, 3}, {4, 7, 6, 5}, {0, 4, 5, 1}, {1, 5, 6, 2}, {2, 6, 7, 3}, {3, 7, 4, 0}};
  if (t == SolidType::C3D6) return {{0, 1, 2}, {3, 5, 4}, {0, 3, 4, 1}, {1, 4, 5, 2}, {2, 5, 3, 0}};
  return {{0, 1, 2, 3}, {0, 4, 1}, {1, 4, 2}, {2, 4, 3}, {3, 4, 0}};
}

/// Checks one split (returns the number of tetrahedra): positive volumes, the volume, and that the
/// boundary of the pieces is the element's faces cut along the diagonals through their smallest ids.
int check_split(SolidType t, const std::vector<Vec>& X, const std::vector<long>& ids) {
  const InpDeck d = split_one(t, X, ids);
  const Mesh& m = d.mesh;
  const int nt = m.num_elements();
  EXPECT_EQ(m.num_nodes(), static_cast<int>(X.size())) << "a linear split adds no node";
  EXPECT_GT(min_volume(m), 0.0);
  const Exact ex = exact_of(t);
  EXPECT_NEAR(mesh_volume(m), ex.volume, 1e-12 * ex.volume);
  const std::vector<std::vector<int>> faces = corner_faces(t);
  const auto counts = face_counts(m);
  int expected_boundary = 0;
  for (const auto& f : faces) expected_boundary += f.size() == 4 ? 2 : 1;
  int boundary = 0;
  double surface = 0.0;
  for (int e = 0; e < nt; ++e)
    for (int lf = 0; lf < 4; ++lf) {
      const std::array<int, 3> k = sorted_corners(m, FaceRef{e, lf});
      const int c = counts.at(k);
      EXPECT_TRUE(c == 1 || c == 2);
      if (c == 2) continue;
      ++boundary;
      surface += face_area(m, FaceRef{e, lf});
      // On exactly one element face; on a quadrilateral, it holds both ends of the diagonal
      // through the corner of smallest id.
      int on = 0;
      for (const auto& f : faces) {
        if (!std::all_of(k.begin(), k.end(), [&](int n) { return std::count(f.begin(), f.end(), n) == 1; })) continue;
        ++on;
        if (f.size() == 3) continue;
        int j = 0;
        for (int q = 1; q < 4; ++q)
          if (ids[static_cast<std::size_t>(f[q])] < ids[static_cast<std::size_t>(f[j])]) j = q;
        EXPECT_TRUE(std::count(k.begin(), k.end(), f[j]) == 1 && std::count(k.begin(), k.end(), f[(j + 2) % 4]) == 1)
            << "triangle off the smallest-id diagonal";
      }
      EXPECT_EQ(on, 1);
    }
  EXPECT_EQ(boundary, expected_boundary);
  EXPECT_NEAR(surface, ex.surface, 1e-12 * ex.surface);
  return nt;
}

TEST(SolidSplit, TypeNamesAndTheirFormulationVariants) {
  EXPECT_EQ(solid_type("C3D8"), SolidType::C3D8);
  EXPECT_EQ(solid_type("C3D8RH"), SolidType::C3D8);
  EXPECT_EQ(solid_type("C3D8IH"), SolidType::C3D8);
  EXPECT_EQ(solid_type("C3D20R"), SolidType::C3D20);
  EXPECT_EQ(solid_type("C3D20RH"), SolidType::C3D20);
  EXPECT_EQ(solid_type("C3D15H"), SolidType::C3D15);
  EXPECT_EQ(solid_type("C3D6"), SolidType::C3D6);
  EXPECT_EQ(solid_type("C3D5H"), SolidType::C3D5);
  EXPECT_EQ(solid_type("C3D10M"), SolidType::C3D10);
  EXPECT_EQ(solid_type("C3D4H"), SolidType::C3D4);
  for (const char* bad : {"C3D27", "C3D15V", "C3D8T", "C3D", "C3D88", "CPS4", ""})
    EXPECT_FALSE(solid_type(bad).has_value()) << bad;
  EXPECT_EQ(solid_nodes(SolidType::C3D20), 20);
  EXPECT_EQ(solid_faces(SolidType::C3D15), 5);
  EXPECT_EQ(solid_faces(SolidType::C3D8), 6);
}

TEST(SolidSplit, IsoparametricMapsInterpolateTheirNodesAndKeepConstants) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (SolidType t : {SolidType::C3D4, SolidType::C3D10, SolidType::C3D6, SolidType::C3D15, SolidType::C3D8,
                      SolidType::C3D20}) {
    const int nn = solid_nodes(t);
    std::vector<Vec> X(static_cast<std::size_t>(nn));
    for (Vec& x : X) x = Vec(u(rng), u(rng), u(rng));
    std::vector<int> nodes(static_cast<std::size_t>(nn));
    std::iota(nodes.begin(), nodes.end(), 0);
    for (int k = 0; k < nn; ++k)
      EXPECT_LT((solid_point(t, nodes.data(), X, solid_reference_node(t, k)) - X[static_cast<std::size_t>(k)]).norm(), 1e-13)
          << solid_name(t) << " node " << k + 1;
    const std::vector<Vec> same(static_cast<std::size_t>(nn), Vec(0.3, -2.0, 5.0));  // partition of unity
    const Vec xi = 0.25 * (solid_reference_node(t, 0) + solid_reference_node(t, 1) + solid_reference_node(t, nn - 1) +
                           solid_reference_node(t, nn / 2));
    EXPECT_LT((solid_point(t, nodes.data(), same, xi) - Vec(0.3, -2.0, 5.0)).norm(), 1e-13) << solid_name(t);
  }
}

// Every order of the corner ids, i.e. every diagonal configuration the rule can produce: 8! for the
// hexahedron (so no configuration needs an interior point), 6! for the wedge, 5! for the pyramid.
TEST(SolidSplit, EveryOrderOfCornerIdsSplitsTheHexahedronInto5Or6) {
  // Corner a of the reference cube has coordinates (bit 0, bit 1, bit 2) of kBits[a].
  static constexpr int kBits[8] = {0, 1, 3, 2, 4, 5, 7, 6};
  const std::vector<std::vector<int>> faces = corner_faces(SolidType::C3D8);
  std::vector<long> ids = {11, 12, 13, 14, 15, 16, 17, 18};
  std::map<int, int> pieces;
  do {
    // 5 exactly when no face away from the smallest corner v is cut through the corner opposite v.
    const int v = static_cast<int>(std::min_element(ids.begin(), ids.end()) - ids.begin());
    const int o = static_cast<int>(std::find(kBits, kBits + 8, kBits[v] ^ 7) - kBits);
    bool through_o = false;
    for (const auto& f : faces) {
      if (std::count(f.begin(), f.end(), v)) continue;
      int j = 0;
      for (int q = 1; q < 4; ++q)
        if (ids[static_cast<std::size_t>(f[q])] < ids[static_cast<std::size_t>(f[j])]) j = q;
      through_o = through_o || f[j] == o || f[(j + 2) % 4] == o;
    }
    const int nt = check_split(SolidType::C3D8, frustum_hex(), ids);
    ASSERT_EQ(nt, through_o ? 6 : 5);
    ++pieces[nt];
    if (::testing::Test::HasFailure()) return;
  } while (std::next_permutation(ids.begin(), ids.end()));
  EXPECT_GT(pieces[5], 0);
  EXPECT_GT(pieces[6], 0);
}

TEST(SolidSplit, EveryOrderOfCornerIdsSplitsTheWedgeInto3AndThePyramidInto2) {
  std::vector<long> ids = {3, 5, 7, 9, 11, 13};
  do {
    ASSERT_EQ(check_split(SolidType::C3D6, frustum_wedge(), ids), 3);
    if (::testing::Test::HasFailure()) return;
  } while (std::next_permutation(ids.begin(), ids.end()));
  ids = {3, 5, 7, 9, 11};
  do {
    ASSERT_EQ(check_split(SolidType::C3D5, skew_pyramid(), ids), 2);
    if (::testing::Test::HasFailure()) return;
  } while (std::next_permutation(ids.begin(), ids.end()));
}

/// Nodes of one quadratic element at phi(reference node); phi in the element's space, so its
/// isoparametric map is phi itself.
std::vector<Vec> curved_element(SolidType t, const Map& phi) {
  std::vector<Vec> X;
  for (int k = 0; k < solid_nodes(t); ++k) X.push_back(phi(solid_reference_node(t, k)));
  return X;
}

TEST(SolidSplit, QuadraticElementsKeepTheirCurvedGeometry) {
  // Complete quadratic maps (in the C3D20 and C3D15 spaces): every Tet10 node must sit at phi of
  // its reference point, the new ones on cut diagonals included (straight mid-points would not).
  const Map phi = [](const Vec& s) {
    return Vec(s.x() + 0.15 * s.y() * s.y() + 0.05 * s.z(), s.y() + 0.1 * s.z() * s.z() - 0.1 * s.x() * s.y(),
               1.5 * s.z() + 0.12 * s.x() * s.x());
  };
  std::mt19937 rng(3);
  for (SolidType t : {SolidType::C3D20, SolidType::C3D15}) {
    const int nn = solid_nodes(t);
    const int nc = t == SolidType::C3D20 ? 8 : 6;
    for (int trial = 0; trial < 30; ++trial) {
      std::vector<long> ids(static_cast<std::size_t>(nn));
      std::iota(ids.begin(), ids.end(), 1L);
      std::shuffle(ids.begin(), ids.end(), rng);
      const InpDeck d = split_one(t, curved_element(t, phi), ids);
      const Mesh& m = d.mesh;
      ASSERT_EQ(m.type, ElementType::Tet10);
      ASSERT_GT(m.num_nodes(), nn) << "cut diagonals get new nodes";
      std::vector<int> used(static_cast<std::size_t>(m.num_nodes()), 0);
      for (int e = 0; e < m.num_elements(); ++e) {
        const int* n = m.element(e);
        std::array<Vec, 4> xi;
        for (int a = 0; a < 4; ++a) {
          ASSERT_LT(n[a], nc) << "tetrahedron corners are element corners";
          xi[static_cast<std::size_t>(a)] = solid_reference_node(t, n[a]);
        }
        static constexpr int E[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};
        for (int k = 0; k < 6; ++k) {
          const Vec expect = phi(0.5 * (xi[E[k][0]] + xi[E[k][1]]));
          EXPECT_LT((m.X[static_cast<std::size_t>(n[4 + k])] - expect).norm(), 1e-12) << solid_name(t) << " trial " << trial;
        }
        for (int a = 0; a < 10; ++a) ++used[static_cast<std::size_t>(n[a])];
      }
      EXPECT_TRUE(std::all_of(used.begin(), used.end(), [](int c) { return c > 0; })) << "every node is used";
    }
  }
}

TEST(SolidSplit, TetrahedraNameTheDeckElementTheyCameFrom) {
  std::vector<long> ids = {21, 22, 23, 24, 25, 26, 27, 28};
  const InpDeck d = split_one(SolidType::C3D8, frustum_hex(), ids);
  const Mesh& m = d.mesh;
  ASSERT_GE(m.num_elements(), 5);
  EXPECT_EQ(m.element_ids[0], 57) << "the first tetrahedron keeps the element's id";
  std::set<long> unique(m.element_ids.begin(), m.element_ids.end());
  EXPECT_EQ(unique.size(), m.element_ids.size());
  ASSERT_EQ(m.element_sources.size(), static_cast<std::size_t>(m.num_elements()));
  for (int e = 0; e < m.num_elements(); ++e) {
    const std::string label = m.element_label(e);
    EXPECT_NE(label.find("element " + std::to_string(m.element_ids[static_cast<std::size_t>(e)]) + " (tet " +
                        std::to_string(e + 1) + " of C3D8 57, region 'default')"),
              std::string::npos)
        << label;
  }
  EXPECT_EQ(count_containing(d.warnings, "one.inp:3: split into tetrahedra"), 1);
  EXPECT_EQ(count_containing(d.warnings, "1 C3D8 into " + std::to_string(m.num_elements()) + " C3D4"), 1);
  EXPECT_EQ(count_containing(d.warnings, "mesh.promote_to_tet10 = true"), 1);
}

// ------------------------------------------------------------------------------------------------
// Generated decks
// ------------------------------------------------------------------------------------------------

TEST_F(SolidDecks, BlocksOfHexahedraSplitConformingly) {
  const Eigen::Matrix3d A = shear();
  const Map map = [&](const Vec& s) { return Vec(A * s); };
  double cube_surface = 0.0;
  for (int d = 0; d < 3; ++d) cube_surface += 2.0 * A.col((d + 1) % 3).cross(A.col((d + 2) % 3)).norm();
  std::map<int, int> pieces;
  for (bool quadratic : {false, true})
    for (unsigned seed = 1; seed <= 6; ++seed) {
      const HexBlock b(2, 2, 2, quadratic, seed, map);
      const InpDeck d = read(b.nodes() + b.elements(quadratic ? "*ELEMENT, TYPE=C3D20R, ELSET=BLOCK" : "*ELEMENT, TYPE=C3D8H, ELSET=BLOCK"));
      const Mesh& m = d.mesh;
      ASSERT_EQ(m.type, quadratic ? ElementType::Tet10 : ElementType::Tet4);
      EXPECT_GT(min_volume(m), 0.0);
      EXPECT_NEAR(mesh_volume(m), A.determinant(), 1e-12);
      // Conforming: every triangle in one tetrahedron (boundary) or two (inside), and the
      // boundary ones on the block's boundary, covering it once.
      double boundary_area = 0.0;
      const auto counts = face_counts(m);
      for (int e = 0; e < m.num_elements(); ++e)
        for (int f = 0; f < 4; ++f) {
          const int c = counts.at(sorted_corners(m, FaceRef{e, f}));
          ASSERT_TRUE(c == 1 || c == 2) << "seed " << seed;
          if (c == 2) continue;
          boundary_area += face_area(m, FaceRef{e, f});
          const int* ln = face_local_nodes(m.type, f);
          for (int a = 0; a < 3; ++a) {
            const Vec s = A.inverse() * m.X[static_cast<std::size_t>(m.element(e)[ln[a]])];
            EXPECT_TRUE((s.array() < 1e-12).any() || (s.array() > 1 - 1e-12).any()) << "an inner face has one tetrahedron";
          }
        }
      EXPECT_NEAR(boundary_area, cube_surface, 1e-12 * cube_surface);
      EXPECT_EQ(static_cast<std::size_t>(m.num_elements()), m.element_sets.at("BLOCK").size());
      if (quadratic) {
        // Neighbours share the mid-edge nodes of their common faces (new diagonal nodes included),
        // which sit half-way along the straight edges.
        const auto counts6 = face_counts6(m);
        std::map<int, int> hist3, hist6;
        for (const auto& [k, c] : counts) ++hist3[c];
        for (const auto& [k, c] : counts6) ++hist6[c];
        EXPECT_EQ(hist3, hist6) << "seed " << seed;
        for (int e = 0; e < m.num_elements(); ++e) {
          static constexpr int E[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};
          const int* n = m.element(e);
          for (int k = 0; k < 6; ++k)
            EXPECT_LT((m.X[n[4 + k]] - 0.5 * (m.X[n[E[k][0]]] + m.X[n[E[k][1]]])).norm(), 1e-12);
        }
      }
      std::set<long> ids(m.element_ids.begin(), m.element_ids.end()), nids(m.node_ids.begin(), m.node_ids.end());
      EXPECT_EQ(ids.size(), m.element_ids.size());
      EXPECT_EQ(nids.size(), m.node_ids.size());
      for (const ElementSource& src : m.element_sources) ++pieces[src.pieces];
      EXPECT_EQ(count_containing(d.warnings, quadratic ? "C3D20R is read as C3D20" : "C3D8H is read as C3D8"), 1);
      EXPECT_EQ(count_containing(d.warnings, "8 " + std::string(quadratic ? "C3D20" : "C3D8") + " into " +
                                                 std::to_string(m.num_elements())),
                1);
      EXPECT_EQ(count_containing(d.warnings, "other diagonal"), 0);
    }
  EXPECT_GT(pieces[5], 0);
  EXPECT_GT(pieces[6], 0);
}

/// A C3D8 cube with a C3D5 pyramid on its face y = 0, two C3D6 wedges on top (triangles at x = 0
/// and x = 1, so a quadrilateral faces the cube) and a C3D4 on a wedge's triangle.
std::string mixed_deck(const std::array<long, 8>& cube_ids) {
  std::ostringstream os;
  os.precision(17);
  const std::array<Vec, 8> cube = {Vec(0, 0, 0), Vec(1, 0, 0), Vec(1, 1, 0), Vec(0, 1, 0),
                                   Vec(0, 0, 1), Vec(1, 0, 1), Vec(1, 1, 1), Vec(0, 1, 1)};
  os << "*NODE\n";
  for (int a = 0; a < 8; ++a) os << cube_ids[static_cast<std::size_t>(a)] << ", " << cube[a].x() << ", " << cube[a].y() << ", " << cube[a].z() << "\n";
  const long c1 = cube_ids[0], c2 = cube_ids[1], c3 = cube_ids[2], c4 = cube_ids[3], c5 = cube_ids[4], c6 = cube_ids[5],
             c7 = cube_ids[6], c8 = cube_ids[7];
  // Top layer z = 2: 101 (0,0,2), 102 (1,0,2), 103 (1,1,2), 104 (0,1,2); pyramid apex 105; tet apex 106.
  os << "101, 0, 0, 2\n102, 1, 0, 2\n103, 1, 1, 2\n104, 0, 1, 2\n105, 0.5, -0.5, 0.5\n106, 1.5, 0.6, 1.4\n";
  os << "*ELEMENT, TYPE=C3D8, ELSET=CUBE\n1, " << c1 << ", " << c2 << ", " << c3 << ", " << c4 << ", " << c5 << ", "
     << c6 << ", " << c7 << ", " << c8 << "\n";
  // Base 1-2-3-4 counter-clockwise seen from the apex (at y < 0): the cube face y = 0 as c1 c2 c6 c5.
  os << "*ELEMENT, TYPE=C3D5, ELSET=PYRAMID\n2, " << c1 << ", " << c2 << ", " << c6 << ", " << c5 << ", 105\n";
  // Wedges over the y-z square A = (y0, z1), B = (y1, z1), C = (y1, z2), D = (y0, z2), cut along A-C,
  // extruded along x: wedge ABC (triangle at x = 0 first) and wedge ACD.
  os << "*ELEMENT, TYPE=C3D6, ELSET=WEDGES\n3, " << c5 << ", " << c8 << ", 104, " << c6 << ", " << c7 << ", 103\n4, " << c5
     << ", 104, 101, " << c6 << ", 103, 102\n";
  // The tetrahedron on the triangle of wedge 3 at x = 1 (c6, c7, 103), apex beyond it.
  os << "*ELEMENT, TYPE=C3D4, ELSET=TET\n5, " << c6 << ", " << c7 << ", 103, 106\n";
  return os.str();
}

TEST_F(SolidDecks, MixedDecksOfCubesPyramidsWedgesAndTetrahedra) {
  std::mt19937 rng(11);
  std::array<long, 8> ids = {1, 2, 3, 4, 5, 6, 7, 8};
  for (int trial = 0; trial < 12; ++trial) {
    const InpDeck d = read(mixed_deck(ids));
    const Mesh& m = d.mesh;
    EXPECT_GT(min_volume(m), 0.0);
    const double tet = std::abs((Vec(1, 1, 2) - Vec(1, 0, 1)).cross(Vec(1, 1, 1) - Vec(1, 0, 1)).dot(Vec(1.5, 0.6, 1.4) - Vec(1, 0, 1))) / 6;
    EXPECT_NEAR(mesh_volume(m), 1.0 + 1.0 / 6 + 1.0 + tet, 1e-12);
    for (const auto& [k, c] : face_counts(m)) ASSERT_TRUE(c == 1 || c == 2) << "trial " << trial;
    EXPECT_EQ(m.element_sets.at("PYRAMID").size(), 2u);
    EXPECT_EQ(m.element_sets.at("WEDGES").size(), 6u);
    ASSERT_EQ(m.element_sets.at("TET").size(), 1u);
    const int t = m.element_sets.at("TET")[0];
    EXPECT_EQ(m.element_ids[static_cast<std::size_t>(t)], 5);
    EXPECT_EQ(m.element_label(t), "element 5 (region 'tet')") << "the deck's own tetrahedra keep their label";
    EXPECT_EQ(count_containing(d.warnings, "1 C3D5 into 2, 2 C3D6 into 6, 1 C3D8 into"), 1) << d.warnings.front();
    EXPECT_EQ(count_containing(d.warnings, "other diagonal"), 0);
    EXPECT_EQ(count_containing(d.warnings, "volume"), 0);
    std::shuffle(ids.begin(), ids.end(), rng);
  }
}

TEST_F(SolidDecks, TetrahedraOnAQuadrilateralAlongTheOtherDiagonalAreReported) {
  // Two C3D4 on the cube's face y = 0 (corners c1 c2 c6 c5) cut along c1-c6.
  auto deck = [](long smallest_on_face) {
    std::array<long, 8> ids = {21, 22, 23, 24, 25, 26, 27, 28};
    ids[static_cast<std::size_t>(smallest_on_face)] = 1;
    std::ostringstream os;
    os << "*NODE\n";
    const std::array<Vec, 8> cube = {Vec(0, 0, 0), Vec(1, 0, 0), Vec(1, 1, 0), Vec(0, 1, 0),
                                     Vec(0, 0, 1), Vec(1, 0, 1), Vec(1, 1, 1), Vec(0, 1, 1)};
    for (int a = 0; a < 8; ++a) os << ids[static_cast<std::size_t>(a)] << ", " << cube[a].x() << ", " << cube[a].y() << ", " << cube[a].z() << "\n";
    os << "99, 0.5, -0.5, 0.5\n*ELEMENT, TYPE=C3D8\n1";
    for (long id : ids) os << ", " << id;
    os << "\n*ELEMENT, TYPE=C3D4\n2, " << ids[0] << ", " << ids[1] << ", " << ids[5] << ", 99\n3, " << ids[0] << ", " << ids[5]
       << ", " << ids[4] << ", 99\n";
    return os.str();
  };
  const InpDeck matching = read(deck(0));  // smallest id at c1: the split cuts along c1-c6 too
  EXPECT_EQ(count_containing(matching.warnings, "other diagonal"), 0);
  for (const auto& [k, c] : face_counts(matching.mesh)) EXPECT_TRUE(c == 1 || c == 2);
  const InpDeck crossing = read(deck(1));  // smallest at c2: the split cuts along c2-c5
  EXPECT_EQ(count_containing(crossing.warnings, "1 quadrilateral face(s) meet tetrahedra of the deck that cut them along "
                                                "the other diagonal (first: face S3 of C3D8 1)"),
            1);
  EXPECT_EQ(count_containing(crossing.warnings, "C3D5 pyramids"), 1);
}

// ------------------------------------------------------------------------------------------------
// Bad input
// ------------------------------------------------------------------------------------------------

TEST_F(SolidDecks, InvertedDegenerateAndCollapsedElementsAreRefused) {
  expect_error(kCube + "*ELEMENT, TYPE=C3D8\n57, 5, 6, 7, 8, 1, 2, 3, 4\n", 11,
               {"element 57 (C3D8) is inverted or degenerate", "negative volume", "check the node order",
                "counter-clockwise seen from the opposite face 5-6-7-8"});
  expect_error(kCube + "9, 0.5, 0.5, 0\n*ELEMENT, TYPE=C3D5\n3, 1, 2, 3, 4, 9\n", 12,
               {"element 3 (C3D5) is inverted or degenerate", "zero volume", "seen from the apex 5"});
  expect_error(kCube + "*ELEMENT, TYPE=C3D6\n4, 1, 2, 3, 5, 6, 7\n*ELEMENT, TYPE=C3D6\n5, 1, 3, 2, 5, 7, 6\n", 13,
               {"element 5 (C3D6) is inverted", "corners 1-2-3 counter-clockwise"});
  expect_error(kCube + "*ELEMENT, TYPE=C3D8\n6, 1, 2, 3, 4, 5, 6, 7, 7\n", 11,
               {"element 6 (C3D8) lists node 7 twice", "collapsed", "C3D6 wedge"});
}

TEST_F(SolidDecks, WrongNodeCountsFacesAndTypes) {
  expect_error(kCube + "*ELEMENT, TYPE=C3D8R\n1, 1, 2, 3, 4, 5, 6, 7\n", 11,
               {"element 1 lists 7 nodes but a C3D8 has 8", "list all its nodes"});
  expect_error(kCube + "*ELEMENT, TYPE=C3D20\n1, 1, 2, 3, 4, 5, 6, 7, 8\n", 11,
               {"element 1 lists 8 nodes but a C3D20 has 20"});
  expect_error(kCube + "*ELEMENT, TYPE=C3D6\n1, 1, 2, 3, 5, 6, 7\n*SURFACE, NAME=S\n1, S6\n", 13,
               {"S6 names face 6 of element 1, a C3D6 with faces 1-5", "use S1..S5"});
  expect_error(kCube + "*ELEMENT, TYPE=C3D8\n1, 1, 2, 3, 4, 5, 6, 7, 8\n*DLOAD\n1, P7, 1.0\n", 13,
               {"P7 names face 7 of element 1, a C3D8 with faces 1-6", "use P1..P6"});
  expect_error(kCube + "*ELEMENT, TYPE=C3D27\n", 10, {"element type C3D27 is not supported", "C3D8 and C3D20"});
  expect_error(kCube + "*ELEMENT, TYPE=C3D8\n1, 1, 2, 3, 4, 5, 6, 7, 8\n*ELEMENT, TYPE=C3D10\n", 12,
               {"mixes element orders with the C3D8 elements of ", "bad.inp:10;", "all linear: C3D4, C3D5, C3D6, C3D8"});
}

}  // namespace
}  // namespace pneufem
