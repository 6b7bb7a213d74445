// mesh.source = "stl" end to end: the default actuator written as an STL from the built-in
// geometry's dimensions, meshed through the scene keys, bends as the built-in mesh does; a second,
// curved actuator (a capped tube with a strain-limiting strip) runs; bad inputs name their key.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "engine/assembly.h"
#include "engine/quasi_static.h"
#include "scenes/build_model.h"
#include "scenes/pneunet.h"
#include "scenes/stl_scene.h"
#include "tests/scenes/stl/test_shapes.h"
#include "tests/support/input_error.h"

namespace pneufem {
namespace {

namespace fs = std::filesystem;
using test::error_of;

fs::path tmp(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / "pneufem_test_stl_scene";
  fs::create_directories(d);
  return d / name;
}

/// The built-in actuator of `p`, as an STL in mm; returns its path.
std::string pneunet_stl(const PneuNetParams& p, const std::string& name) {
  const fs::path f = tmp(name);
  write_stl(f.string(), test::pneunet_surface(p), 1e-3);
  return f.string();
}

/// Bending angle (deg) at each pressure level (> 0) of the scene's staircase, in pressure order
/// (the model is elastic: loading and unloading reports of a level agree).
std::vector<double> staircase_angles(const Scene& s) {
  auto bm = build_model(s);
  Assembler A(bm->model);
  QuasiStaticRun run(A, bm->solver.quasi_static);
  std::map<double, double> by_pressure;
  run.run(bm->load, [&](const StateRecord& r, const Eigen::VectorXd&, const std::vector<double>&) {
    if (r.pressure_Pa > 0.0) by_pressure[r.pressure_Pa] = r.angle_deg;
  });
  std::vector<double> angles;
  for (const auto& [p, a] : by_pressure) angles.push_back(a);
  return angles;
}

/// The bending angle (deg) of the tip face's plane fitted with each point weighted by its share of
/// the face's area (bench/stl/tip_angle.py: the three mid-edge nodes of each quadratic tip triangle,
/// a third of its area each), for the built-in frame (clamped at y = 0, bending towards -z). The
/// node-weighted plane (engine/angle.h) depends on where a mesh puts its tip nodes when the face
/// warps; this one is the plane of the continuous face, the same for any mesh of it.
double area_weighted_angle_deg(const Model& model, const Eigen::VectorXd& u) {
  std::vector<char> on_tip(model.mesh.num_nodes(), 0);
  for (int n : model.angle.tip_nodes) on_tip[n] = 1;
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  double W = 0.0;
  std::vector<std::pair<Eigen::Vector3d, double>> pts;
  for (const FaceRef& fr : boundary_faces(model.mesh)) {
    const int* fn = face_local_nodes(model.mesh.type, fr.local_face);
    const int* el = model.mesh.element(fr.element);
    if (!(on_tip[el[fn[0]]] && on_tip[el[fn[1]]] && on_tip[el[fn[2]]])) continue;
    const Eigen::Vector3d& a = model.mesh.X[el[fn[0]]];
    const double area = 0.5 * (model.mesh.X[el[fn[1]]] - a).cross(model.mesh.X[el[fn[2]]] - a).norm();
    for (int k = 3; k < 6; ++k) {
      const int n = el[fn[k]];
      const Eigen::Vector3d x = model.mesh.X[n] + u.segment<3>(3 * n);
      pts.emplace_back(x, area / 3.0);
      c += area / 3.0 * x;
      W += area / 3.0;
    }
  }
  c /= W;
  Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
  for (const auto& [x, w] : pts) C += w * (x - c) * (x - c).transpose();
  Eigen::Vector3d n = Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(C).eigenvectors().col(0);
  if (n.y() < 0.0) n = -n;
  return std::atan2(-n.z(), n.y()) * 180.0 / std::acos(-1.0);
}

/// Like staircase_angles, by the area-weighted tip plane too: {pneufem's angle, by area} per level.
std::vector<std::pair<double, double>> staircase_angles_both(const Scene& s) {
  auto bm = build_model(s);
  Assembler A(bm->model);
  QuasiStaticRun run(A, bm->solver.quasi_static);
  std::map<double, std::pair<double, double>> by_pressure;
  run.run(bm->load, [&](const StateRecord& r, const Eigen::VectorXd& u, const std::vector<double>&) {
    if (r.pressure_Pa > 0.0) by_pressure[r.pressure_Pa] = {r.angle_deg, area_weighted_angle_deg(bm->model, u)};
  });
  std::vector<std::pair<double, double>> angles;
  for (const auto& [p, a] : by_pressure) angles.push_back(a);
  return angles;
}

std::vector<std::string> stl_sets(const std::string& file, std::vector<std::string> more = {}) {
  std::vector<std::string> s{"mesh.source=\"stl\"", "mesh.file=\"" + file + "\""};
  s.insert(s.end(), more.begin(), more.end());
  return s;
}

// One loading: 0 -> 20 kPa in 5 kPa levels, one report per level (the default staircase's first
// trial, shortened to keep the test at a few seconds per model).
const std::vector<std::string> kLoad = {"load.max_kPa=20.0", "load.trials=1", "load.output_every_s=0.0"};

TEST(StlScene, DefaultActuatorFromStlBendsAsTheBuiltInMesh) {
  // The default actuator written as an STL from its dimensions, at a coarse h = 4 mm (the test's
  // budget; test_mesher.cpp shows the same identity at h = 2 and 6).
  PneuNetParams p;
  const std::string file = pneunet_stl(p, "default_actuator.stl");
  std::vector<std::string> common = kLoad;
  common.insert(common.end(), {"mesh.h_mm=4.0", "load.max_kPa=10.0"});
  const auto t0 = std::chrono::steady_clock::now();
  const std::vector<double> built_in = staircase_angles(Scene::load("", common));
  const auto t1 = std::chrono::steady_clock::now();
  const std::vector<double> from_stl = staircase_angles(Scene::load("", stl_sets(file, common)));
  const auto t2 = std::chrono::steady_clock::now();
  ASSERT_EQ(built_in.size(), 2u);
  ASSERT_EQ(from_stl.size(), 2u);
  for (std::size_t i = 0; i < built_in.size(); ++i) {
    std::printf("%g kPa: built-in %.4f deg, STL %.4f deg\n", 5.0 * (i + 1), built_in[i], from_stl[i]);
    // The same nodes, elements and sets (test_mesher.cpp): the same discrete problem, so the
    // angles agree to round-off of the solver (rel_tol 1e-8), far inside the 2 %.
    EXPECT_NEAR(from_stl[i], built_in[i], 1e-9 * std::abs(built_in[i]));
  }
  std::printf("built-in %.1f s, STL %.1f s\n", std::chrono::duration<double>(t1 - t0).count(),
              std::chrono::duration<double>(t2 - t1).count());
}

TEST(StlScene, DefaultActuatorFromStlBendsAsCalculixOnGmshsMesh) {
  // Issue 33 item 3, "and of CalculiX on the gmsh deck": the default actuator's STL meshed by
  // pneufem at the default h = 2 mm (feature planes: the built-in mesh), against CalculiX 2.20 on
  // gmsh's mesh of the same actuator at h = 2 (bench/calculix/results/default_h2_half_full.csv:
  // 34 934 nodes, 21 055 C3D10; the h = 6 deck of tests/data/ccx_gmsh is too coarse for a 2 %
  // comparison of two different meshes: at h = 6 and 4 gmsh's and pneufem's meshes are 18 and 8 %
  // apart at 5 kPa, both far from converged; bench/notes/2026-11-29-stl3.md). 5 and 10 kPa (the test's budget; 20 kPa measured).
  PneuNetParams p;
  const std::string file = pneunet_stl(p, "default_actuator_h2.stl");
  std::vector<std::string> sets = kLoad;
  sets.insert(sets.end(), {"mesh.h_mm=2.0", "load.max_kPa=10.0"});
  const auto got = staircase_angles_both(Scene::load("", stl_sets(file, sets)));
  ASSERT_EQ(got.size(), 2u);
  std::map<long, double> ccx;  // CalculiX's plane-fit angle (pneufem's definition) by pressure
  {
    std::ifstream in(std::string(PNEUFEM_TEST_DATA_DIR) + "/../../bench/calculix/results/default_h2_half_full.csv");
    std::string line;
    ASSERT_TRUE(std::getline(in, line));  // time,pressure_kPa,angle_deg,angle_planefit_deg,...
    while (std::getline(in, line)) {
      std::stringstream row(line);
      std::string cell[4];
      for (auto& c : cell) std::getline(row, c, ',');
      ccx[std::lround(std::stod(cell[1]))] = std::stod(cell[3]);
    }
  }
  // The area-weighted angle of CalculiX's solution on that deck, measured on pneufem's solution of
  // the same deck (read through mesh.source = "inp", whose node-weighted angle is CalculiX's within
  // 0.11 % at 5-20 kPa, as on the h = 6 deck of CalculixReference.GmshDeckBendsAsCalculixSolvesIt):
  // bench/notes/2026-11-29-stl3.md.
  const double ccx_by_area[2] = {0.971872, 2.357556};
  for (int i = 0; i < 2; ++i) {
    const double by_nodes = got[i].first, by_area = got[i].second, ref = ccx.at(5 * (i + 1));
    std::printf("%d kPa: STL h = 2 %.6f deg (CalculiX on gmsh's mesh %.6f, %+.2f %%); by area %.6f (%.6f, %+.2f %%)\n",
                5 * (i + 1), by_nodes, ref, 100.0 * (by_nodes / ref - 1.0), by_area, ccx_by_area[i],
                100.0 * (by_area / ccx_by_area[i] - 1.0));
    // By area, the two meshes' solutions agree within the 2 % (measured -0.39 / -0.56 %;
    // -0.68 / -0.75 % at 15 / 20 kPa).
    EXPECT_NEAR(by_area, ccx_by_area[i], 0.02 * ccx_by_area[i]);
    // By pneufem's node-weighted angle the 2 % is missed by 0.15 points at 5 kPa (measured
    // -2.15 / -2.09 %, -2.02 / -1.94 % at 15 / 20 kPa): the plane through the tip nodes depends
    // on where each mesh puts them while the face warps (0.035 mm rms at 5 kPa), which moves it
    // by ~1.5 % between these two meshes of one solution. 2.5 % holds the measured value; a lost
    // cavity face or a wrong slab moves the angle far more.
    EXPECT_NEAR(by_nodes, ref, 0.025 * ref);
  }
}

TEST(StlScene, MembraneFabricBendsAsTheBuiltInMembrane) {
  // mesh.fabric_model = "membrane" on the STL path: the membrane on the slab's mid-plane, its
  // thickness that of mesh.fabric_slab_mm (0.4 mm, the default geometry's); 3 chambers, h = 4 mm.
  PneuNetParams p;
  p.chambers = 3;
  const std::string file = pneunet_stl(p, "three_chambers_membrane.stl");
  std::vector<std::string> common = kLoad;
  common.insert(common.end(), {"geometry.chambers=3", "mesh.h_mm=4.0", "load.max_kPa=5.0", "mesh.fabric_model=\"membrane\""});
  const std::vector<double> built_in = staircase_angles(Scene::load("", common));
  const std::vector<double> from_stl = staircase_angles(Scene::load("", stl_sets(file, common)));
  ASSERT_EQ(built_in.size(), 1u);
  ASSERT_EQ(from_stl.size(), 1u);
  std::printf("5 kPa, membrane fabric: built-in %.6f deg, STL %.6f deg\n", built_in[0], from_stl[0]);
  // The same nodes (to round-off of the mid-plane's z), elements and membrane faces
  // (test_mesher.cpp): the same discrete problem up to the solver's tolerance.
  EXPECT_NEAR(from_stl[0], built_in[0], 1e-9 * std::abs(built_in[0]));
  // Without a slab there is no plane for the membrane: refused, naming the key.
  const std::string e = error_of([&] { build_mesh(Scene::load("", stl_sets(file, {"mesh.fabric_model=\"membrane\"", "mesh.fabric_slab_mm=[]"}))); });
  EXPECT_NE(e.find("key 'mesh.fabric_model'"), std::string::npos) << e;
}

TEST(StlScene, UniformGridBendsCloseToTheBuiltInMesh) {
  // The general path: a grid that ignores the CAD faces (mesh.feature_planes = false), so every
  // face of the chambers is cut, warped and its edges recovered by snapping. At h = 1 mm (4
  // chambers, BENCHMARKS.md section 10) it bends within 0.7 % of the built-in mesh at 5-20 kPa;
  // that run takes ~10 min, so the test runs 2 chambers at h = 1.5 mm and 5 kPa, where the 2 mm
  // walls get two cells each (mesh.wall_cells = 2) and their own one in the built-in grid:
  // measured -10.5 % (-14.5 % with wall_cells = 0). At 5 kPa this short actuator's tip face warps
  // as much as it turns, and the angle (the plane through the tip nodes, each weighted alike)
  // scatters by +-6 % between meshes; weighted by area the STL mesh is within 0.3 % here
  // (bench/notes/2026-11-28-stl-thin-walls.md). The 20 % bound guards the path (a cavity face
  // set lost, a wall thickened by the stencils moves the angle by far more), not the
  // discretisation's accuracy at this h.
  PneuNetParams p;
  p.chambers = 2;
  const std::string file = pneunet_stl(p, "two_chambers_uniform.stl");
  std::vector<std::string> common = kLoad;
  common.insert(common.end(), {"geometry.chambers=2", "mesh.h_mm=1.5", "load.max_kPa=5.0"});
  const auto built_in = staircase_angles_both(Scene::load("", common));
  common.push_back("mesh.feature_planes=false");
  const auto cut = staircase_angles_both(Scene::load("", stl_sets(file, common)));
  ASSERT_EQ(built_in.size(), 1u);
  ASSERT_EQ(cut.size(), 1u);
  std::printf("5 kPa: built-in %.6f deg, uniform grid %.6f deg (%+.2f %%); by area %.6f, %.6f (%+.2f %%)\n",
              built_in[0].first, cut[0].first, 100.0 * (cut[0].first / built_in[0].first - 1.0), built_in[0].second,
              cut[0].second, 100.0 * (cut[0].second / built_in[0].second - 1.0));
  EXPECT_NEAR(cut[0].first, built_in[0].first, 0.20 * std::abs(built_in[0].first));
  // By the area-weighted tip plane, the measure that does not depend on where a mesh puts its tip
  // nodes, the general path is held to the 2 % (measured -0.28 %, 2026-11-28).
  EXPECT_NEAR(cut[0].second, built_in[0].second, 0.02 * std::abs(built_in[0].second));
}

TEST(StlScene, CurvedTubeActuatorRunsEndToEnd) {
  // A second geometry: a capped silicone tube (outer radius 6 mm, closed bore 3.5 mm, 40 mm long)
  // with a strain-limiting strip z in [-5.8, -5] mm along its bottom; it is round, so every
  // surface is cut and warped and the mid-nodes are curved onto it.
  TriSurface t = test::tube_surface(0.006, 0.0035, 0.04, 0.003, 48);
  write_stl(tmp("tube.stl").string(), t, 1e-3);
  std::vector<std::string> sets = kLoad;
  sets.insert(sets.end(), {"mesh.h_mm=1.5", "mesh.fabric_slab_mm=[-5.8, -5.0]", "mesh.cavity_inlet_mm=[0.0, 20.0, 0.0]",
                           "load.max_kPa=10.0"});
  const Scene s = Scene::load("", stl_sets(tmp("tube.stl").string(), sets));
  std::vector<std::string> notes;
  StlMeshReport rep;
  const Mesh m = stl_scene_mesh(s, &notes, &rep);
  std::printf("%s", describe(rep).c_str());
  ASSERT_EQ(notes.size(), 1u);  // the bore was written facing out: turned, with a note
  EXPECT_NE(notes[0].find("were reversed"), std::string::npos);
  const std::vector<double> a = staircase_angles(s);
  ASSERT_EQ(a.size(), 2u);
  for (double v : a) std::printf("tube: %.4f deg\n", v);
  // The strip is on the -z side: the tube curls towards it (positive angle), more at 10 kPa.
  EXPECT_GT(a[0], 0.1);
  EXPECT_GT(a[1], a[0]);
}

TEST(StlScene, ChambersAsASecondFileGiveTheSameMesh) {
  // mesh.cavity_file: the outer block and the chambers as two closed surfaces (the chambers'
  // normals pointing out of them, as CAD writes a solid) mesh as the one file with the voids.
  PneuNetParams p;
  p.chambers = 3;
  const std::string one = pneunet_stl(p, "three_chambers.stl");
  const auto [block, chambers] = test::pneunet_block_and_chambers(p);
  write_stl(tmp("block.stl").string(), block, 1e-3);
  write_stl(tmp("chambers.stl").string(), chambers, 1e-3);
  const Mesh a = build_mesh(Scene::load("", stl_sets(one)));
  std::vector<std::string> notes;
  const Mesh b = build_mesh(
      Scene::load("", stl_sets(tmp("block.stl").string(), {"mesh.cavity_file=\"" + tmp("chambers.stl").string() + "\""})),
      &notes);
  EXPECT_EQ(a.num_elements(), b.num_elements());
  EXPECT_EQ(a.num_nodes(), b.num_nodes());
  EXPECT_EQ(a.surfaces.at("CAVITY").size(), b.surfaces.at("CAVITY").size());
  EXPECT_EQ(a.region, b.region);
  EXPECT_TRUE(notes.empty()) << notes.front();  // nothing was repaired: no note
  // Both a point and a file: refused; a cavity file outside the block: refused.
  const std::string both = error_of([&] {
    build_mesh(Scene::load("", stl_sets(tmp("block.stl").string(), {"mesh.cavity_file=\"" + tmp("chambers.stl").string() + "\"",
                                                                     "mesh.cavity_inlet_mm=[0.0, 7.0, 8.0]"})));
  });
  EXPECT_NE(both.find("not both"), std::string::npos) << both;
}

TEST(StlScene, BadInputsNameTheirKey) {
  PneuNetParams p;
  p.chambers = 2;
  const std::string file = pneunet_stl(p, "two_chambers.stl");
  // An open surface: the last triangle cut off.
  {
    TriSurface s = test::pneunet_surface(p);
    s.F.pop_back();
    write_stl(tmp("open.stl").string(), s, 1e-3);
  }
  const std::string open = error_of([&] { build_mesh(Scene::load("", stl_sets(tmp("open.stl").string()))); });
  EXPECT_NE(open.find("key 'mesh.file'"), std::string::npos) << open;
  EXPECT_NE(open.find("3 open edge(s)"), std::string::npos) << open;
  const std::string cav = error_of([&] { build_mesh(Scene::load("", stl_sets(file, {"mesh.cavity_inlet_mm=[0.0, 1.0, 1.0]"}))); });
  EXPECT_NE(cav.find("key 'mesh.cavity_inlet_mm': cavity not found"), std::string::npos) << cav;
  const std::string fixed = error_of([&] {
    build_mesh(Scene::load("", stl_sets(file, {"mesh.fixed_face=\"plane\"", "mesh.fixed_point_mm=[0.0, 5.0, 0.0]"})));
  });
  EXPECT_NE(fixed.find("key 'mesh.fixed_face'"), std::string::npos) << fixed;
  EXPECT_NE(fixed.find("fixed face not found"), std::string::npos) << fixed;
  const std::string none = error_of([&] { build_mesh(Scene::load("", {"mesh.source=\"stl\""})); });
  EXPECT_NE(none.find("key 'mesh.file'"), std::string::npos) << none;
  const std::string slab = error_of([&] { build_mesh(Scene::load("", stl_sets(file, {"mesh.fabric_slab_mm=[2.0]"}))); });
  EXPECT_NE(slab.find("key 'mesh.fabric_slab_mm'"), std::string::npos) << slab;
  {
    TriSurface shifted = test::pneunet_surface(p);
    for (auto& v : shifted.V) v.x() += 0.011;  // x in [0, 22] mm: not mirror-symmetric about x = 0
    write_stl(tmp("shifted.stl").string(), shifted, 1e-3);
  }
  const std::string half = error_of([&] { build_mesh(Scene::load("", stl_sets(tmp("shifted.stl").string()))); });
  EXPECT_NE(half.find("key 'mesh.half'"), std::string::npos) << half;
  EXPECT_NE(half.find("set mesh.half = false"), std::string::npos) << half;
  EXPECT_EQ(error_of([&] {
              build_mesh(Scene::load("", stl_sets(tmp("shifted.stl").string(), {"mesh.half=false", "mesh.h_mm=4.0"})));
            }),
            "(no error)");
  const std::string range = error_of([&] { build_mesh(Scene::load("", stl_sets(file, {"mesh.fabric_slab_mm=[1.8, 2000.0]"}))); });
  EXPECT_NE(range.find("key 'mesh.fabric_slab_mm'"), std::string::npos) << range;
  const std::string unit = error_of([&] { build_mesh(Scene::load("", stl_sets(file, {"mesh.length_unit=\"m\""}))); });
  EXPECT_NE(unit.find("mesh.length_unit"), std::string::npos) << unit;  // 1000x too large: the size limits say so
}

}  // namespace
}  // namespace pneufem
