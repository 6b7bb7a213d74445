// STL / OBJ reading, the watertight and manifold check, and orientation (scenes/stl/surface.h); the
// signed distance to the surface is test_distance.cpp.
#include <filesystem>
#include <fstream>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "scenes/stl/surface.h"
#include "tests/scenes/stl/test_shapes.h"
#include "tests/support/input_error.h"

namespace pneufem {
namespace {

namespace fs = std::filesystem;
using test::error_of;

fs::path tmp(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / "pneufem_test_stl";
  fs::create_directories(d);
  return d / name;
}

/// A box [0, a] x [0, b] x [0, c] (m).
TriSurface box(double a, double b, double c) {
  std::array<std::vector<double>, 3> lines{{{0.0, a}, {0.0, b}, {0.0, c}}};
  return test::grid_solid_surface(lines, [](const Eigen::Vector3d&) { return true; });
}

double enclosed_volume(const TriSurface& s) {
  double v = 0.0;
  for (const auto& t : s.F) v += s.V[t[0]].dot(s.V[t[1]].cross(s.V[t[2]])) / 6.0;
  return v;
}

void write_text(const fs::path& p, const std::string& text) {
  std::ofstream(p) << text;
}

TEST(StlReader, BinaryRoundTripWeldsVertices) {
  const TriSurface b = box(0.002, 0.003, 0.004);
  write_stl(tmp("box.stl").string(), b, 1e-3);
  const TriSurface r = read_closed_surface(tmp("box.stl").string(), 1e-3);
  EXPECT_EQ(r.V.size(), 8u);  // 12 triangles x 3 corners welded into the 8 corners of the box
  EXPECT_EQ(r.F.size(), 12u);
  EXPECT_EQ(r.shells(), 1);
  // 2 x 3 x 4 mm written as float mm: float rounding of 2, 3, 4 is exact, so the volume is too
  // (up to double round-off of the sum, 1e-15 relative).
  EXPECT_NEAR(enclosed_volume(r), 24e-9, 1e-15 * 24e-9 * 10);
  EXPECT_TRUE(r.notes.empty());
}

TEST(StlReader, AsciiAndObjReadTheSameBox) {
  write_text(tmp("tet.stl"),
             "solid t\n"
             "facet normal 0 0 -1\n outer loop\n vertex 0 0 0\n vertex 0 1 0\n vertex 1 0 0\n endloop\nendfacet\n"
             "facet normal 0 -1 0\n outer loop\n vertex 0 0 0\n vertex 1 0 0\n vertex 0 0 1\n endloop\nendfacet\n"
             "facet normal -1 0 0\n outer loop\n vertex 0 0 0\n vertex 0 0 1\n vertex 0 1 0\n endloop\nendfacet\n"
             "facet normal 1 1 1\n outer loop\n vertex 1 0 0\n vertex 0 1 0\n vertex 0 0 1\n endloop\nendfacet\n"
             "endsolid t\n");
  write_text(tmp("tet.obj"), "# a tetrahedron\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
  for (const char* name : {"tet.stl", "tet.obj"}) {
    const TriSurface s = read_closed_surface(tmp(name).string(), 1e-3);
    EXPECT_EQ(s.V.size(), 4u) << name;
    // The unit tetrahedron in mm: 1/6 mm^3 (exact inputs; round-off only).
    EXPECT_NEAR(enclosed_volume(s), 1e-9 / 6.0, 1e-24) << name;
  }
}

TEST(StlReader, MalformedFilesNameTheLine) {
  write_text(tmp("bad.stl"), "solid t\nfacet normal 0 0 1\n outer loop\n vertex 0 0 x\n");
  EXPECT_NE(error_of([] { read_surface(tmp("bad.stl").string(), 1e-3); }).find("bad.stl:4: expected 'vertex x y z'"),
            std::string::npos);
  write_text(tmp("bad.obj"), "v 0 0 0\nf 1 2 3\n");
  EXPECT_NE(error_of([] { read_surface(tmp("bad.obj").string(), 1e-3); }).find("bad.obj:2: vertex index 2 refers to no vertex"),
            std::string::npos);
  write_text(tmp("bad.ply"), "ply\n");
  EXPECT_NE(error_of([] { read_surface(tmp("bad.ply").string(), 1e-3); }).find("give an .stl"), std::string::npos);
}

TEST(StlReader, OpenSurfaceIsRefusedWithCountLocationAndFix) {
  TriSurface b = box(0.002, 0.002, 0.002);
  b.F.pop_back();  // a hole: the three edges of the missing triangle are used once
  const std::string e = error_of([&] { close_and_orient(b); });
  EXPECT_NE(e.find("3 open edge(s)"), std::string::npos) << e;
  EXPECT_NE(e.find("the first from ("), std::string::npos) << e;
  EXPECT_NE(e.find("Close Holes"), std::string::npos) << e;
}

TEST(StlReader, NonManifoldEdgesAreRefused) {
  TriSurface b = box(0.002, 0.002, 0.002);
  b.F.push_back(b.F.front());  // a duplicated triangle: its three edges now have three triangles
  const std::string e = error_of([&] { close_and_orient(b); });
  EXPECT_NE(e.find("3 non-manifold edge(s)"), std::string::npos) << e;
  EXPECT_NE(e.find("shared by 3 triangles"), std::string::npos) << e;
}

TEST(StlReader, SelfIntersectingSurfacesAreRefused) {
  // Two closed boxes exported as one body, overlapping: each is watertight, the union is not a
  // surface of one solid.
  TriSurface a = box(0.004, 0.004, 0.004);
  TriSurface b = box(0.004, 0.004, 0.004);
  for (auto& v : b.V) v += Eigen::Vector3d(0.002, 0.001, 0.0015);
  append_surface(a, b);
  const std::string e = error_of([&] { close_and_orient(a); });
  EXPECT_NE(e.find("the surface intersects itself"), std::string::npos) << e;
  EXPECT_NE(e.find("pair(s) of triangles cross, the first near ("), std::string::npos) << e;
  EXPECT_NE(e.find("Boolean union"), std::string::npos) << e;
  // Nested without touching (a void in a solid) is no intersection.
  TriSurface t = test::tube_surface(0.006, 0.0035, 0.04, 0.003, 24);
  EXPECT_EQ(error_of([&] { close_and_orient(t); }), "(no error)");
}

TEST(StlReader, TiltedFlatFacesOfManyTrianglesAreNoSelfIntersection) {
  // A CAD face that is flat but tilted is many triangles that are coplanar only to round-off; two
  // of them without a common corner are no crossing. Before 2026-11-29 the segment test treated only
  // an exactly zero determinant as coplanar, and round-off determinants of ~1e-20 made crossings of
  // such pairs (found on the 2-chamber actuator with a sloped free end: 3 "crossing" pairs). A box
  // of 4 x 4 x 4 cells (every face 32 triangles), turned about a skew axis, and the sloped actuator.
  std::array<std::vector<double>, 3> lines{{{0.0, 0.001, 0.002, 0.003, 0.004}, {0.0, 0.001, 0.002, 0.003, 0.004},
                                            {0.0, 0.001, 0.002, 0.003, 0.004}}};
  TriSurface b = test::grid_solid_surface(lines, [](const Eigen::Vector3d&) { return true; });
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.3, Eigen::Vector3d(1.0, 2.0, 3.0).normalized()).toRotationMatrix();
  for (auto& v : b.V) v = R * v + Eigen::Vector3d(0.0123, -0.0071, 0.0042);
  EXPECT_EQ(error_of([&] { close_and_orient(b); }), "(no error)");
  EXPECT_NEAR(enclosed_volume(b), 0.004 * 0.004 * 0.004, 1e-12 * 0.004 * 0.004 * 0.004);
  PneuNetParams p;
  p.chambers = 2;
  TriSurface sloped = test::pneunet_surface(p);
  for (auto& v : sloped.V)
    if (std::abs(v.y() - p.length()) < 1e-12) v.y() += 0.25 * v.z();
  EXPECT_EQ(error_of([&] { close_and_orient(sloped); }), "(no error)");
  // A real crossing at a small angle is still found: the second box of the test above, tilted 1 degree.
  TriSurface a = test::grid_solid_surface(lines, [](const Eigen::Vector3d&) { return true; });
  TriSurface c = a;
  const Eigen::Matrix3d tilt = Eigen::AngleAxisd(std::numbers::pi / 180.0, Eigen::Vector3d::UnitX()).toRotationMatrix();
  for (auto& v : c.V) v = tilt * v + Eigen::Vector3d(0.0015, 0.0015, 0.0015);
  append_surface(a, c);
  EXPECT_NE(error_of([&] { close_and_orient(a); }).find("the surface intersects itself"), std::string::npos);
}

TEST(StlReader, InvertedNormalsAreFixedWithANote) {
  // The box written inside out, and one triangle of it turned back: both repaired.
  TriSurface b = box(0.002, 0.002, 0.002);
  for (auto& t : b.F) std::swap(t[1], t[2]);
  std::swap(b.F[3][1], b.F[3][2]);
  close_and_orient(b);
  EXPECT_NEAR(enclosed_volume(b), 8e-9, 1e-20);
  ASSERT_EQ(b.notes.size(), 2u);
  EXPECT_NE(b.notes[0].find("1 triangle(s) disagreed"), std::string::npos) << b.notes[0];
  EXPECT_NE(b.notes[1].find("were reversed"), std::string::npos) << b.notes[1];
}

TEST(StlReader, VoidShellsAreNestedAndTurnedToFaceTheVoid) {
  TriSurface t = test::tube_surface(0.006, 0.0035, 0.04, 0.003, 24);
  close_and_orient(t);
  ASSERT_EQ(t.shells(), 2);
  EXPECT_EQ(t.shell_depth[0], 0);
  EXPECT_EQ(t.shell_depth[1], 1);  // the bore is a void
  ASSERT_EQ(t.notes.size(), 1u);   // the bore was written with outward normals: turned
  EXPECT_NE(t.notes[0].find("a void"), std::string::npos) << t.notes[0];
  // Solid volume = outer prism - bore prism (24-gons: (n/2) r^2 sin(2 pi / n) per unit length).
  const double poly = 12.0 * std::sin(2.0 * std::numbers::pi / 24.0);
  EXPECT_NEAR(enclosed_volume(t), poly * (0.006 * 0.006 * 0.04 - 0.0035 * 0.0035 * 0.034), 1e-18);
}

}  // namespace
}  // namespace pneufem
