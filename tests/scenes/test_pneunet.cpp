// Tests of the parametric pneu-net mesher (scenes/pneunet.h) against closed-form geometry.
//
// The mesh grid contains every feature plane, so every volume and area below is exact up to
// round-off: tolerances are a few hundred ulps of the summed quantity, not discretisation errors.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <functional>
#include <map>
#include <ostream>
#include <set>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "core/errors.h"
#include "scenes/pneunet.h"

namespace pneufem {
namespace {

// Sums of ~1e5 terms accumulated in long double; coordinates carry ~1 ulp each. 1e-12 relative
// is ~1e4 ulps: far below any geometric mistake (one missing cell is > 1e-5 relative).
constexpr double kRelTol = 1e-12;

/// Closed-form geometry of the actuator (full model; the half model is exactly half).
struct Analytic {
  double solid, fabric, base, end_cap, roof, side_wall, interior_wall;
  double cavity_volume, cavity_area;
  double outer_area;     ///< outer box (full) or outer box without x = 0 (half)
  double symmetry_area;  ///< solid part of x = 0 (half model only)

  explicit Analytic(const PneuNetParams& p) {
    const double W = p.width, L = p.length(), hb = p.base_thickness, H = p.body_height;
    const double a = W - 2 * p.side_wall;  // chamber width
    const double c = H - p.roof;           // chamber height
    const double lc = p.chamber_length, N = p.chambers, wall = p.interior_wall;
    const double cw = p.channel_width, chh = p.channel_height;
    const double tunnels = (N - 1) * wall * cw * chh;  // channel inside the interior walls
    cavity_volume = N * a * lc * c + tunnels;
    solid = W * L * (hb + H) - cavity_volume;
    fabric = W * L * p.fabric_thickness;
    base = W * L * (hb - p.fabric_thickness);
    end_cap = 2 * W * p.end_cap * H;
    roof = W * (L - 2 * p.end_cap) * p.roof;
    side_wall = 2 * p.side_wall * (L - 2 * p.end_cap) * c;
    interior_wall = (N - 1) * wall * a * c - tunnels;
    // Chamber boxes, minus the two channel openings in each interior wall, plus the tunnel walls.
    cavity_area = N * 2 * (a * lc + a * c + lc * c) - 2 * (N - 1) * cw * chh + (N - 1) * wall * 2 * (cw + chh);
    outer_area = 2 * (W * L + W * (hb + H) + L * (hb + H));
    symmetry_area = L * (hb + H) - (N * lc * c + (N - 1) * wall * chh);
    if (p.half) {
      for (double* v : {&solid, &fabric, &base, &end_cap, &roof, &side_wall, &interior_wall, &cavity_volume,
                        &cavity_area})
        *v *= 0.5;
      outer_area *= 0.5;  // x = W/2 whole, x = -W/2 gone, the other four faces halved
    }
  }
};

std::array<Eigen::Vector3d, 3> face_corners(const Mesh& m, FaceRef f) {
  const int* ln = face_local_nodes(m.type, f.local_face);
  const int* n = m.element(f.element);
  return {m.X[n[ln[0]]], m.X[n[ln[1]]], m.X[n[ln[2]]]};
}

double face_area(const Mesh& m, FaceRef f) {
  const auto x = face_corners(m, f);
  return 0.5 * (x[1] - x[0]).cross(x[2] - x[0]).norm();
}

std::map<std::string, long double> region_volumes(const Mesh& m) {
  std::map<std::string, long double> v;
  for (const auto& name : m.region_names) v[name] = 0;
  for (int e = 0; e < m.num_elements(); ++e) v[m.region_names[m.region[e]]] += corner_volume(m, e);
  return v;
}

void expect_rel(long double got, double want, const std::string& what) {
  EXPECT_NEAR(static_cast<double>(got), want, kRelTol * std::abs(want)) << what;
}

struct Case {
  std::string name;
  PneuNetParams p;
};

void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

std::vector<Case> cases() {
  std::vector<Case> c;
  for (bool half : {true, false})
    for (ElementType t : {ElementType::Tet4, ElementType::Tet10}) {
      PneuNetParams p;
      p.half = half;
      p.element = t;
      c.push_back({std::string("default_") + (half ? "half_" : "full_") + (t == ElementType::Tet4 ? "tet4" : "tet10"), p});
    }
  // Other walls, channel and fabric; h divides no feature length; two fabric layers.
  PneuNetParams q;
  q.chambers = 3;
  q.chamber_length = 5e-3;
  q.interior_wall = 3e-3;
  q.side_wall = 5e-3;
  q.roof = 4e-3;
  q.end_cap = 5e-3;
  q.channel_width = 3e-3;
  q.channel_height = 2.5e-3;
  q.fabric_z0 = 1e-3;
  q.fabric_thickness = 0.7e-3;
  q.fabric_layers = 2;
  q.h = 1.7e-3;
  for (bool half : {true, false}) {
    q.half = half;
    q.element = half ? ElementType::Tet10 : ElementType::Tet4;
    c.push_back({std::string("three_chambers_") + (half ? "half_tet10" : "full_tet4"), q});
  }
  PneuNetParams one;  // a single chamber: no interior wall, the channel lies inside the chamber
  one.chambers = 1;
  one.element = ElementType::Tet4;
  c.push_back({"one_chamber_half_tet4", one});
  return c;
}

class PneuNetMesh : public ::testing::TestWithParam<Case> {
 protected:
  /// Builds each case once per test binary.
  static const Mesh& mesh(const Case& c) {
    static std::map<std::string, Mesh> cache;
    auto it = cache.find(c.name);
    if (it == cache.end()) it = cache.emplace(c.name, build_pneunet(c.p)).first;
    return it->second;
  }
};

TEST_P(PneuNetMesh, ElementsArePositiveAndTyped) {
  const auto& [name, p] = GetParam();
  const Mesh& m = mesh(GetParam());
  EXPECT_EQ(m.type, p.element);
  ASSERT_GT(m.num_elements(), 0);
  int bad = 0;
  for (int e = 0; e < m.num_elements(); ++e) bad += corner_volume(m, e) <= 0.0;
  EXPECT_EQ(bad, 0) << "elements with non-positive corner volume";
  EXPECT_EQ(m.node_ids.size(), m.X.size());
  EXPECT_EQ(m.element_ids.size(), static_cast<std::size_t>(m.num_elements()));
  // Every node is used (unused grid nodes inside the cavity were removed).
  std::vector<char> used(m.X.size(), 0);
  for (int v : m.conn) used[v] = 1;
  EXPECT_EQ(std::count(used.begin(), used.end(), 0), 0);
  if (m.type == ElementType::Tet10) {
    static constexpr int kEdge[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};
    double err = 0.0;
    for (int e = 0; e < m.num_elements(); ++e)
      for (int k = 0; k < 6; ++k) {
        const int* n = m.element(e);
        err = std::max(err, (m.X[n[4 + k]] - 0.5 * (m.X[n[kEdge[k][0]]] + m.X[n[kEdge[k][1]]])).norm());
      }
    EXPECT_EQ(err, 0.0) << "mid-edge nodes are exact midpoints";
  }
}

TEST_P(PneuNetMesh, VolumesMatchAnalytic) {
  const auto& [name, p] = GetParam();
  const Mesh& m = mesh(GetParam());
  const Analytic a(p);
  const auto v = region_volumes(m);
  long double total = 0;
  for (const auto& [r, vol] : v) total += vol;
  expect_rel(total, a.solid, "total solid volume");
  ASSERT_EQ(v.size(), 6u);
  expect_rel(v.at(regions::kFabric), a.fabric, "fabric");
  expect_rel(v.at(regions::kBase), a.base, "base");
  expect_rel(v.at(regions::kEndCap), a.end_cap, "end_cap");
  expect_rel(v.at(regions::kRoof), a.roof, "roof");
  expect_rel(v.at(regions::kSideWall), a.side_wall, "side_wall");
  if (p.chambers > 1)
    expect_rel(v.at(regions::kInteriorWall), a.interior_wall, "interior_wall");
  else
    EXPECT_EQ(v.at(regions::kInteriorWall), 0.0L) << "one chamber has no interior wall";
}

TEST_P(PneuNetMesh, RegionsAndElementSets) {
  const auto& [name, p] = GetParam();
  const Mesh& m = mesh(GetParam());
  const MeshStats s = compute_stats(m);
  for (const char* r : {regions::kInteriorWall, regions::kRoof, regions::kSideWall, regions::kEndCap,
                        regions::kBase, regions::kFabric}) {
    ASSERT_TRUE(s.elements_per_region.count(r)) << r;
    if (p.chambers > 1 || std::string(r) != regions::kInteriorWall) {
      EXPECT_GT(s.elements_per_region.at(r), 0) << r;
    }
  }
  const auto& fab = m.element_sets.at("FABRIC");
  const auto& sil = m.element_sets.at("SILICONE");
  EXPECT_EQ(fab.size() + sil.size(), static_cast<std::size_t>(m.num_elements()));
  EXPECT_TRUE(std::is_sorted(fab.begin(), fab.end()));
  EXPECT_TRUE(std::is_sorted(sil.begin(), sil.end()));
  const int rf = m.find_region(regions::kFabric);
  for (int e : fab) EXPECT_EQ(m.region[e], rf);
  for (int e : sil) EXPECT_NE(m.region[e], rf);
}

TEST_P(PneuNetMesh, CavitySurfaceMatchesAnalytic) {
  const auto& [name, p] = GetParam();
  const Mesh& m = mesh(GetParam());
  const Analytic a(p);
  const auto& cav = m.surfaces.at("CAVITY");
  ASSERT_FALSE(cav.empty());
  long double area = 0, vol = 0;
  for (FaceRef f : cav) {
    area += face_area(m, f);
    // Divergence theorem: face_local_nodes order points the normal into the element, i.e. out of
    // the cavity, so sum x0 . (x1 x x2) / 6 = +V_cavity. Faces on x = 0 would add 0 (x . n = 0).
    const auto x = face_corners(m, f);
    vol += x[0].dot(x[1].cross(x[2])) / 6.0;
  }
  expect_rel(area, a.cavity_area, "cavity area");
  // Cancellation of the large x0 . (x1 x x2) terms costs ~2 digits: allow 100x the volume tolerance.
  EXPECT_NEAR(static_cast<double>(vol), a.cavity_volume, 100 * kRelTol * a.cavity_volume) << "cavity volume";
}

TEST_P(PneuNetMesh, ConformingAndBoundaryClassified) {
  const auto& [name, p] = GetParam();
  const Mesh& m = mesh(GetParam());
  const Analytic a(p);
  // Each triangle (sorted corner ids) bounds at most two elements.
  std::map<std::array<int, 3>, int> count;
  for (int e = 0; e < m.num_elements(); ++e)
    for (int f = 0; f < 4; ++f) {
      const int* ln = face_local_nodes(ElementType::Tet4, f);
      std::array<int, 3> k = {m.element(e)[ln[0]], m.element(e)[ln[1]], m.element(e)[ln[2]]};
      std::sort(k.begin(), k.end());
      ++count[k];
    }
  int over = 0;
  for (const auto& [k, n] : count) over += n > 2;
  EXPECT_EQ(over, 0) << "faces shared by more than two elements";

  // Boundary faces are outer-box, symmetry-plane or cavity faces, and these sets are disjoint.
  const double W = p.width, L = p.length(), Z = p.base_thickness + p.body_height;
  const double tol = 1e-12 * L;  // coordinates are exact grid values up to an ulp
  auto on = [&](const std::array<Eigen::Vector3d, 3>& x, int axis, double v) {
    return std::all_of(x.begin(), x.end(), [&](const Eigen::Vector3d& y) { return std::abs(y[axis] - v) < tol; });
  };
  std::set<std::pair<int, int>> cavity;
  for (FaceRef f : m.surfaces.at("CAVITY")) cavity.insert({f.element, f.local_face});
  EXPECT_EQ(cavity.size(), m.surfaces.at("CAVITY").size()) << "duplicate cavity faces";
  long double outer = 0, sym = 0;
  int unexplained = 0, cavity_on_outer = 0;
  std::size_t cavity_boundary = 0;
  for (FaceRef f : boundary_faces(m)) {
    const auto x = face_corners(m, f);
    const bool is_sym = p.half && on(x, 0, 0.0);
    const bool is_outer = on(x, 0, W / 2) || (!p.half && on(x, 0, -W / 2)) || on(x, 1, 0.0) || on(x, 1, L) ||
                          on(x, 2, 0.0) || on(x, 2, Z);
    const bool is_cav = cavity.count({f.element, f.local_face}) > 0;
    cavity_boundary += is_cav;
    if (is_cav && (is_outer || is_sym)) ++cavity_on_outer;
    if (!is_cav && !is_outer && !is_sym) ++unexplained;
    if (is_outer) outer += face_area(m, f);
    if (is_sym) sym += face_area(m, f);
  }
  EXPECT_EQ(unexplained, 0) << "boundary faces on neither the box, the symmetry plane nor the cavity";
  EXPECT_EQ(cavity_on_outer, 0);
  EXPECT_EQ(cavity_boundary, cavity.size()) << "every CAVITY face is a boundary face";
  expect_rel(outer, a.outer_area, "outer area");
  if (p.half) expect_rel(sym, a.symmetry_area, "symmetry plane area");
}

TEST_P(PneuNetMesh, NodeSetsOnTheirPlanes) {
  const auto& [name, p] = GetParam();
  const Mesh& m = mesh(GetParam());
  const double L = p.length();
  auto check = [&](const std::string& set, int axis, double v) {
    ASSERT_TRUE(m.node_sets.count(set)) << set;
    const auto& nodes = m.node_sets.at(set);
    EXPECT_TRUE(std::is_sorted(nodes.begin(), nodes.end()));
    for (int n : nodes) ASSERT_EQ(m.X[n][axis], v) << set << " node " << n;  // grid values, exact
    // ... and no node on the plane is missing.
    std::size_t on_plane = 0;
    for (const auto& x : m.X) on_plane += x[axis] == v;
    EXPECT_EQ(on_plane, nodes.size()) << set;
  };
  check("FIXED", 1, 0.0);
  check("TIP", 1, L);
  EXPECT_EQ(m.node_sets.count("SYMMETRY"), p.half ? 1u : 0u);
  if (p.half) check("SYMMETRY", 0, 0.0);
  // The end cap is solid, so the tip face carries a full tensor grid of nodes.
  std::set<double> xs, zs;
  for (int n : m.node_sets.at("TIP")) {
    xs.insert(m.X[n].x());
    zs.insert(m.X[n].z());
  }
  EXPECT_EQ(m.node_sets.at("TIP").size(), xs.size() * zs.size());
  EXPECT_EQ(m.node_sets.at("FIXED").size(), m.node_sets.at("TIP").size());
}

TEST_P(PneuNetMesh, ElementsOrderedAlongLength) {
  const Mesh& m = mesh(GetParam());
  // y is the outermost loop: the lowest corner y of consecutive elements never decreases.
  double prev = -1.0;
  int back = 0;
  for (int e = 0; e < m.num_elements(); ++e) {
    double y = m.X[m.element(e)[0]].y();
    for (int k = 1; k < 4; ++k) y = std::min(y, m.X[m.element(e)[k]].y());
    back += y < prev;
    prev = y;
  }
  EXPECT_EQ(back, 0);
}

INSTANTIATE_TEST_SUITE_P(Cases, PneuNetMesh, ::testing::ValuesIn(cases()),
                         [](const ::testing::TestParamInfo<Case>& i) { return i.param.name; });

// Hand count of the default grid (h = 2 mm). x planes (half) 0, 1, 4, 11 mm -> 1 + 2 + 4 = 7 cells;
// full: -11, -4, -1, 1, 4, 11 -> 4 + 2 + 1 + 2 + 4 = 13 cells. z planes 0, 1.8, 2.2, 3, 5, 11, 18
// -> 1 + 1 (fabric_layers) + 1 + 1 + 3 + 4 = 11 cells.
TEST(PneuNet, TipNodeCountMatchesGrid) {
  auto tip = [](bool half, ElementType t) {
    PneuNetParams p;
    p.half = half;
    p.element = t;
    return build_pneunet(p).node_sets.at("TIP").size();
  };
  EXPECT_EQ(tip(true, ElementType::Tet4), 8u * 12u);
  EXPECT_EQ(tip(true, ElementType::Tet10), 15u * 23u);  // (2 nx + 1)(2 nz + 1)
  EXPECT_EQ(tip(false, ElementType::Tet4), 14u * 12u);
}

TEST(PneuNet, Deterministic) {
  PneuNetParams p;
  p.element = ElementType::Tet10;
  const Mesh a = build_pneunet(p), b = build_pneunet(p);
  EXPECT_EQ(a.conn, b.conn);
  EXPECT_EQ(a.X, b.X);
  EXPECT_EQ(a.region, b.region);
  EXPECT_EQ(a.node_sets, b.node_sets);
  EXPECT_EQ(a.surfaces, b.surfaces);
}

TEST(PneuNet, DefaultsAreValidAndMatchTheReference) {
  const PneuNetParams p;
  EXPECT_NO_THROW(p.validate());
  EXPECT_NEAR(p.length(), 126e-3, 1e-15);  // CalculiX reference: L = 2*4 + 15*6 + 14*2 mm
}

TEST(PneuNet, InvalidParametersNameTheKey) {
  struct Bad {
    std::function<void(PneuNetParams&)> set;
    std::string key;
  };
  const std::vector<Bad> bad = {
      {[](PneuNetParams& p) { p.width = 0; }, "geometry.width"},
      {[](PneuNetParams& p) { p.base_thickness = -1e-3; }, "geometry.base_thickness"},
      {[](PneuNetParams& p) { p.body_height = std::nan(""); }, "geometry.body_height"},
      {[](PneuNetParams& p) { p.chambers = 0; }, "geometry.chambers"},
      {[](PneuNetParams& p) { p.chamber_length = 0; }, "geometry.chamber_length"},
      {[](PneuNetParams& p) { p.interior_wall = -2e-3; }, "geometry.interior_wall"},
      {[](PneuNetParams& p) { p.end_cap = 0; }, "geometry.end_cap"},
      {[](PneuNetParams& p) { p.side_wall = 11e-3; }, "geometry.side_wall"},       // no room for chambers
      {[](PneuNetParams& p) { p.channel_width = 8e-3; }, "geometry.channel_width"},  // = chamber width
      {[](PneuNetParams& p) { p.roof = 15e-3; }, "geometry.roof"},
      {[](PneuNetParams& p) { p.channel_height = 8e-3; }, "geometry.channel_height"},  // = chamber height
      {[](PneuNetParams& p) { p.fabric_z0 = 0; }, "geometry.fabric_z0"},
      {[](PneuNetParams& p) { p.fabric_thickness = 1.2e-3; }, "geometry.fabric_thickness"},  // top at 3.0
      {[](PneuNetParams& p) { p.h = 0; }, "mesh.h"},
      {[](PneuNetParams& p) { p.h = 1e-4; }, "mesh.h"},  // ~ 10 million cells
      {[](PneuNetParams& p) { p.fabric_layers = 0; }, "mesh.fabric_layers"},
      // A 10 nm gap between the fabric top and the base top cannot be resolved by the voxels.
      {[](PneuNetParams& p) { p.fabric_thickness = 3e-3 - 1.8e-3 - 1e-8; }, "geometry"},
  };
  for (const auto& b : bad) {
    PneuNetParams p;
    b.set(p);
    for (int call = 0; call < 2; ++call) {
      try {
        if (call == 0)
          p.validate();
        else
          (void)build_pneunet(p);
        ADD_FAILURE() << "no InputError for " << b.key;
      } catch (const InputError& e) {
        EXPECT_NE(std::string(e.what()).find(b.key), std::string::npos) << e.what();
      }
    }
  }
}

// Informational: element and node counts of the half Tet10 model (not asserted).
TEST(PneuNet, PrintCounts) {
  for (double h : {2e-3, 1.5e-3}) {
    PneuNetParams p;
    p.h = h;
    const auto t0 = std::chrono::steady_clock::now();
    const Mesh m = build_pneunet(p);
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    const MeshStats s = compute_stats(m);
    std::printf("[ pneunet ] h = %.1f mm half Tet10: %d nodes, %d elements, %zu cavity faces, quality min %.3f "
                "mean %.3f, built in %.0f ms\n",
                h * 1e3, s.nodes, s.elements, m.surfaces.at("CAVITY").size(), s.min_quality, s.mean_quality, ms);
    for (const auto& [r, n] : s.elements_per_region) std::printf("[ pneunet ]   %-14s %d\n", r.c_str(), n);
  }
}

}  // namespace
}  // namespace pneufem
