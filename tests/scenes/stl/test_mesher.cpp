// Closed surfaces to tetrahedra (scenes/stl/mesher.h): the built-in pneu-net's own surface gives
// the built-in mesh's solid, a curved tube is meshed by the cut-and-warp path, and the sets
// (CAVITY, FIXED, TIP, SYMMETRY, FABRIC) are the ones the engine needs.
#include <cstdio>
#include <filesystem>
#include <numbers>
#include <set>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "engine/tet_element.h"
#include "scenes/pneunet.h"
#include "scenes/stl/mesher.h"
#include "tests/scenes/stl/test_shapes.h"
#include "tests/support/input_error.h"

namespace pneufem {
namespace {

using test::error_of;

double mesh_volume(const Mesh& m) {
  double v = 0.0;
  for (int e = 0; e < m.num_elements(); ++e) v += corner_volume(m, e);
  return v;
}

double set_volume(const Mesh& m, const std::string& set) {
  double v = 0.0;
  for (int e : m.element_sets.at(set)) v += corner_volume(m, e);
  return v;
}

/// The spec the scene gives for the default actuator: slab = the fabric layer, half model.
StlMeshSpec default_spec(const PneuNetParams& p) {
  StlMeshSpec s;
  s.stuffing.h = p.h;
  s.stuffing.half = p.half;
  s.stuffing.has_slab = true;
  s.stuffing.slab_z0 = p.fabric_z0;
  s.stuffing.slab_z1 = p.fabric_z0 + p.fabric_thickness;
  s.stuffing.slab_cells = p.fabric_layers;
  return s;
}

TriSurface closed(TriSurface s) {
  close_and_orient(s);
  return s;
}

TEST(StlMesher, PneuNetSurfaceGivesTheBuiltInSolid) {
  for (double h : {2e-3, 4e-3, 6e-3}) {
    PneuNetParams p;  // the default actuator, half model, Tet10
    p.h = h;
    const Mesh built_in = build_pneunet(p);
    StlMeshReport rep;
    const Mesh m = mesh_closed_surface(closed(test::pneunet_surface(p)), default_spec(p), &rep);
    std::printf("h = %g mm: %s", h * 1e3, describe(rep).c_str());
    // Every face of this actuator is an axis-aligned plane carrying facets, at least h/10 from the
    // next, so the background grid is the built-in mesher's grid and nothing is cut or moved: the
    // same cells, the same 5-tet split, the same nodes (numbered alike: both by first use).
    EXPECT_EQ(m.num_elements(), built_in.num_elements()) << h;
    ASSERT_EQ(m.num_nodes(), built_in.num_nodes()) << h;
    EXPECT_EQ(rep.cut_points + rep.warped + rep.creased + rep.on_sharp_edges, 0) << h;
    double max_dx = 0.0;
    for (int n = 0; n < m.num_nodes(); ++n) max_dx = std::max(max_dx, (m.X[n] - built_in.X[n]).norm());
    EXPECT_EQ(max_dx, 0.0) << h;  // grid lines computed by the same formula from the same planes
    EXPECT_EQ(m.conn, built_in.conn) << h;
    EXPECT_EQ(m.region_names, built_in.region_names) << h;  // the same tags by the same rules
    EXPECT_EQ(m.region, built_in.region) << h;
    // Volumes exact up to round-off of the sum (1e-12 relative).
    EXPECT_NEAR(mesh_volume(m), mesh_volume(built_in), 1e-12 * mesh_volume(built_in));
    EXPECT_NEAR(set_volume(m, "FABRIC"), set_volume(built_in, "FABRIC"), 1e-12 * mesh_volume(built_in));
    EXPECT_EQ(m.surfaces.at("CAVITY").size(), built_in.surfaces.at("CAVITY").size());
    EXPECT_EQ(m.node_sets.at("FIXED"), built_in.node_sets.at("FIXED"));
    EXPECT_EQ(m.node_sets.at("TIP"), built_in.node_sets.at("TIP"));
    EXPECT_EQ(m.node_sets.at("SYMMETRY"), built_in.node_sets.at("SYMMETRY"));
  }
}

TEST(StlMesher, MembraneFabricGivesTheBuiltInMembraneMesh) {
  // A membrane fabric (slab_mid): the slab's mid-plane becomes a grid plane, the slab's elements
  // silicone, and FABRIC_MEMBRANE the faces on the mid-plane, as the built-in mesher does.
  for (const int layers : {1, 2}) {
    PneuNetParams p;
    p.chambers = 3;
    p.h = 4e-3;
    p.fabric_layers = layers;
    p.fabric_model = FabricModel::Membrane;
    const Mesh built_in = build_pneunet(p);
    StlMeshSpec spec = default_spec(p);
    spec.stuffing.slab_mid = true;
    const Mesh m = mesh_closed_surface(closed(test::pneunet_surface(p)), spec);
    ASSERT_EQ(m.num_nodes(), built_in.num_nodes()) << layers;
    double max_dx = 0.0;
    for (int n = 0; n < m.num_nodes(); ++n) max_dx = std::max(max_dx, (m.X[n] - built_in.X[n]).norm());
    EXPECT_LE(max_dx, 1e-18) << layers;  // the mid-plane z0 + (z1 - z0) / 2 against z0 + t / 2: round-off at most
    EXPECT_EQ(m.conn, built_in.conn) << layers;
    EXPECT_EQ(m.region, built_in.region) << layers;
    EXPECT_TRUE(m.element_sets.at("FABRIC").empty());
    auto face_nodes = [](const Mesh& mm) {
      std::set<std::array<int, 3>> out;
      for (const FaceRef& f : mm.surfaces.at("FABRIC_MEMBRANE")) {
        const int* fn = face_local_nodes(mm.type, f.local_face);
        std::array<int, 3> t{mm.element(f.element)[fn[0]], mm.element(f.element)[fn[1]], mm.element(f.element)[fn[2]]};
        std::sort(t.begin(), t.end());
        out.insert(t);
      }
      return out;
    };
    const auto a = face_nodes(m), b = face_nodes(built_in);
    EXPECT_FALSE(a.empty());
    EXPECT_EQ(a, b) << layers;
    EXPECT_EQ(m.surfaces.at("FABRIC_MEMBRANE").size(), a.size());  // each face once
  }
}

TEST(StlMesher, UniformLatticeCutsTheBoxesToTheSurface) {
  // Without feature planes the grid ignores the CAD faces: every chamber wall is cut and warped.
  PneuNetParams p;
  p.chambers = 4;
  p.h = 1e-3;
  StlMeshSpec spec = default_spec(p);
  spec.stuffing.feature_planes = false;
  StlMeshReport rep;
  const Mesh m = mesh_closed_surface(closed(test::pneunet_surface(p)), spec, &rep);
  std::printf("%s", describe(rep).c_str());
  const Mesh built_in = build_pneunet(p);
  EXPECT_GT(rep.warped, 0);
  // Warped vertices lie on the surface; corner tets of the stencils only cut the box corners, so
  // the volume is within 2 % (a cut corner at h = 1 mm loses at most h^3/6 per corner).
  EXPECT_NEAR(mesh_volume(m), mesh_volume(built_in), 0.02 * mesh_volume(built_in));
  // The cut's worst tetrahedra are smoothed (scenes/stl/smoothing.h): measured 15.1 deg, 8.0
  // without smoothing.
  EXPECT_GT(rep.min_dihedral_deg, 12.0);
  // The clamped face and the tip are grid planes even without feature planes (the end planes),
  // so they are meshed flat and whole but for the chamfers the cut of the side faces leaves along
  // their edges: the faces of TIP and FIXED cover the end face (11 x 18 mm, half model) to within
  // 0.5 % (measured 0.3 %; 1.2 % of the tip was missing when the tip plane was cut).
  const double end_area = 0.5 * p.width * (p.base_thickness + p.body_height);
  for (const char* set : {"FIXED", "TIP"}) {
    const auto& nodes = m.node_sets.at(set);
    const std::set<int> in(nodes.begin(), nodes.end());
    double area = 0.0;
    for (const FaceRef& f : boundary_faces(m)) {
      const int* fn = face_local_nodes(m.type, f.local_face);
      const int* el = m.element(f.element);
      if (in.count(el[fn[0]]) && in.count(el[fn[1]]) && in.count(el[fn[2]]))
        area += 0.5 * (m.X[el[fn[1]]] - m.X[el[fn[0]]]).cross(m.X[el[fn[2]]] - m.X[el[fn[0]]]).norm();
    }
    std::printf("%s: %.4f of the end face\n", set, area / end_area);
    EXPECT_GT(area, 0.995 * end_area) << set;
    EXPECT_LE(area, end_area * (1.0 + 1e-12)) << set;
  }
  for (int e = 0; e < m.num_elements(); ++e) ASSERT_GT(tet10_distortion(m, e).min_scaled_jacobian, 0.1) << e;
}

TEST(StlMesher, CurvedTubeIsMeshedWithMidNodesOnTheSurface) {
  const TriSurface t = closed(test::tube_surface(0.006, 0.0035, 0.04, 0.003, 48));
  StlMeshSpec spec;
  spec.stuffing.h = 1.5e-3;
  spec.stuffing.has_slab = true;
  spec.stuffing.slab_z0 = -0.0058;
  spec.stuffing.slab_z1 = -0.005;
  StlMeshReport rep;
  const Mesh m = mesh_closed_surface(t, spec, &rep);
  std::printf("%s", describe(rep).c_str());
  const double poly = 24.0 * std::sin(2.0 * std::numbers::pi / 48.0);
  const double exact = poly * (0.006 * 0.006 * 0.04 - 0.0035 * 0.0035 * 0.034);
  // Straight-sided corner volume: chords of the curved walls lose O(h^2 / R) per unit area.
  EXPECT_NEAR(mesh_volume(m), exact, 0.03 * exact);
  EXPECT_GT(rep.midnodes_on_surface, 0);
  EXPECT_FALSE(m.surfaces.at("CAVITY").empty());
  EXPECT_FALSE(m.element_sets.at("FABRIC").empty());
  EXPECT_FALSE(m.node_sets.at("FIXED").empty());
  EXPECT_FALSE(m.node_sets.at("TIP").empty());
}

TEST(StlMesher, AnActuatorAlongXGetsTheRegionsOfOneAlongY) {
  // The 2-chamber actuator turned 90 degrees about z, (x, y, z) -> (y, -x, z) (exact in floating
  // point), clamped at its lowest x: the same cells (the grid's axes swap), so every region holds
  // the same number of elements and the same volume as the actuator along y clamped at y-.
  PneuNetParams p;
  p.chambers = 2;
  p.h = 2e-3;
  StlMeshSpec spec = default_spec(p);
  spec.stuffing.half = false;  // the half model's symmetry plane is x = 0
  const Mesh along_y = mesh_closed_surface(closed(test::pneunet_surface(p)), spec);
  TriSurface turned = test::pneunet_surface(p);
  for (auto& v : turned.V) v = Eigen::Vector3d(v.y(), -v.x(), v.z());
  spec.fixed_face = "x-";
  const Mesh along_x = mesh_closed_surface(closed(std::move(turned)), spec);
  ASSERT_EQ(along_x.region_names.size(), along_y.region_names.size());
  for (std::size_t r = 0; r < along_y.region_names.size(); ++r) {
    const std::string& name = along_y.region_names[r];
    const auto it = std::find(along_x.region_names.begin(), along_x.region_names.end(), name);
    ASSERT_NE(it, along_x.region_names.end()) << name;
    const auto rx = static_cast<std::uint16_t>(it - along_x.region_names.begin());
    double vy = 0.0, vx = 0.0;
    int ny = 0, nx = 0;
    for (int e = 0; e < along_y.num_elements(); ++e)
      if (along_y.region[e] == r) vy += corner_volume(along_y, e), ++ny;
    for (int e = 0; e < along_x.num_elements(); ++e)
      if (along_x.region[e] == rx) vx += corner_volume(along_x, e), ++nx;
    EXPECT_EQ(nx, ny) << name;
    EXPECT_GT(ny, 0) << name;
    EXPECT_NEAR(vx, vy, 1e-12 * vy) << name;
  }
  EXPECT_EQ(along_x.node_sets.at("FIXED").size(), along_y.node_sets.at("FIXED").size());
  // Clamped on a face normal to z, the frame has no length axis across z up: body and fabric.
  spec.fixed_face = "z-";
  const Mesh upright = mesh_closed_surface(closed(test::pneunet_surface(p)), spec);
  std::set<std::string> names(upright.region_names.begin(), upright.region_names.end());
  EXPECT_TRUE(names.count("body") == 1 && names.count("roof") == 0);
}

TEST(StlMesher, AnActuatorTurnedInCadIsClampedOnItsWholeEndFace) {
  // The 2-chamber actuator turned 20 degrees about z, as CAD would export it: written as a binary
  // STL (float coordinates) and read back, clamped by mesh.fixed_face = "plane". Its end faces are
  // flat only to the floats' ~1e-7 relative rounding; with the planes' tolerance at 1e-9 of the
  // part's size the tip was "not a flat face" (and the clamp only the faces that happened to fit).
  // Both end faces are now found: their faces' area against the end face's 22 x 18 mm, short of
  // it by the chamfers the cut leaves along the face's edges (measured 98.5 % FIXED, 97.8 % TIP at
  // h = 1.5; an end normal to an axis is a grid plane instead and is found to 99.7 %).
  PneuNetParams p;
  p.chambers = 2;
  const double a = 20.0 * std::numbers::pi / 180.0;
  TriSurface s = test::pneunet_surface(p);
  for (auto& v : s.V) v = Eigen::Vector3d(std::cos(a) * v.x() - std::sin(a) * v.y(), std::sin(a) * v.x() + std::cos(a) * v.y(), v.z());
  const std::string file = (std::filesystem::temp_directory_path() / "pneufem_turned_actuator.stl").string();
  write_stl(file, s, 1e-3);
  const TriSurface read = read_closed_surface(file, 1e-3);
  StlMeshSpec spec = default_spec(p);
  spec.stuffing.half = false;  // turned: no longer mirror-symmetric about x = 0
  spec.stuffing.h = 1.5e-3;
  spec.fixed_face = "plane";
  spec.fixed_point = Eigen::Vector3d::Zero();
  spec.fixed_normal = Eigen::Vector3d(std::sin(a), -std::cos(a), 0.0);
  StlMeshReport rep;
  const Mesh m = mesh_closed_surface(read, spec, &rep);
  std::printf("%s", describe(rep).c_str());
  for (const char* set : {"FIXED", "TIP"}) {
    std::vector<char> in(m.num_nodes(), 0);
    for (int n : m.node_sets.at(set)) in[n] = 1;
    double area = 0.0;
    for (const FaceRef& fr : boundary_faces(m)) {
      const int* fn = face_local_nodes(m.type, fr.local_face);
      const int* el = m.element(fr.element);
      if (in[el[fn[0]]] && in[el[fn[1]]] && in[el[fn[2]]])
        area += 0.5 * (m.X[el[fn[1]]] - m.X[el[fn[0]]]).cross(m.X[el[fn[2]]] - m.X[el[fn[0]]]).norm();
    }
    const double end_face = p.width * (p.base_thickness + p.body_height);
    std::printf("%s: %.2f %% of the end face\n", set, 100.0 * area / end_face);
    EXPECT_GT(area, 0.97 * end_face) << set;
    EXPECT_LT(area, (1.0 + 1e-6) * end_face) << set;
  }
}

TEST(StlMesher, BadInputsAreClearErrors) {
  PneuNetParams p;
  p.chambers = 2;
  const TriSurface s = closed(test::pneunet_surface(p));
  StlMeshSpec spec = default_spec(p);
  // An inlet point in the silicone (the base), in the air, and a solid with no void.
  spec.cavity_inlet = Eigen::Vector3d(0.0, 0.005, 0.001);
  EXPECT_NE(error_of([&] { mesh_closed_surface(s, spec); }).find("lies in the solid"), std::string::npos);
  spec.cavity_inlet = Eigen::Vector3d(0.0, -0.005, 0.001);
  EXPECT_NE(error_of([&] { mesh_closed_surface(s, spec); }).find("lies outside the actuator"), std::string::npos);
  spec.cavity_inlet.reset();
  std::array<std::vector<double>, 3> lines{{{-0.01, 0.01}, {0.0, 0.02}, {0.0, 0.01}}};
  const TriSurface block = closed(test::grid_solid_surface(lines, [](const Eigen::Vector3d&) { return true; }));
  EXPECT_NE(error_of([&] { mesh_closed_surface(block, spec); }).find("cavity not found: the surface has no closed interior void"),
            std::string::npos);
  // A fixed plane that is no face of the actuator.
  spec.fixed_face = "plane";
  spec.fixed_point = Eigen::Vector3d(0.0, 0.003, 0.0);
  spec.fixed_normal = Eigen::Vector3d(0.0, -1.0, 0.0);
  const std::string e = error_of([&] { mesh_closed_surface(s, spec); });
  EXPECT_NE(e.find("fixed face not found"), std::string::npos) << e;
  // A wall thinner than the cells: a hollow box whose 0.3 mm lid lies between grid planes of a
  // uniform 2 mm grid is lost or thickened by the stencils, which moves the volume by far more than 5 %.
  {
    std::array<std::vector<double>, 3> l{{{-0.01, -0.008, 0.008, 0.01}, {0.0, 0.002, 0.018, 0.02}, {0.0, 0.002, 0.0057, 0.006}}};
    const TriSurface hollow = closed(test::grid_solid_surface(
        l, [](const Eigen::Vector3d& x) { return !(std::abs(x.x()) < 0.008 && x.y() > 0.002 && x.y() < 0.018 && x.z() > 0.002 && x.z() < 0.0057); }));
    StlMeshSpec thin;
    thin.stuffing.h = 2e-3;
    thin.stuffing.feature_planes = false;
    thin.wall_cells = 0;  // no refinement across it (test_thin_walls.cpp resolves such a lid)
    const std::string lost = error_of([&] { mesh_closed_surface(hollow, thin); });
    EXPECT_NE(lost.find("walls, chambers or channels thinner than about one element"), std::string::npos) << lost;
  }
  spec.fixed_face = "w+";
  EXPECT_NE(error_of([&] { mesh_closed_surface(s, spec); }).find("mesh.fixed_face must be"), std::string::npos);
  // A tip that is no flat face normal to the length: the free end sloped (y grows with z; still
  // planar, but only its top edge reaches the farthest y), so no face of the mesh lies on the tip plane.
  {
    TriSurface sloped = test::pneunet_surface(p);
    const double L = p.length();
    for (auto& v : sloped.V)
      if (std::abs(v.y() - L) < 1e-12) v.y() += 0.25 * v.z();
    const std::string tip = error_of([&] { mesh_closed_surface(closed(sloped), default_spec(p)); });
    EXPECT_NE(tip.find("mesh.fixed_face = \"y-\": the tip (the end opposite the fixed face) is not a flat face"),
              std::string::npos)
        << tip;
    EXPECT_NE(tip.find("y = 26.5 mm"), std::string::npos) << tip;  // L = 22 mm + 0.25 * 18 mm
  }
}

}  // namespace
}  // namespace pneufem
