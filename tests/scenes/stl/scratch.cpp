#include <cstdio>
#include <set>
#include <map>
#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include "scenes/pneunet.h"
#include "scenes/stl/mesher.h"
#include "tests/scenes/stl/test_shapes.h"
namespace pneufem {
double area_of(const Mesh& m, const std::vector<FaceRef>& fs, Eigen::Vector3d* n_sum) {
  double a = 0; *n_sum = Eigen::Vector3d::Zero();
  for (auto f : fs) { const int* fn = face_local_nodes(m.type, f.local_face); const int* el = m.element(f.element);
    Eigen::Vector3d c = (m.X[el[fn[1]]]-m.X[el[fn[0]]]).cross(m.X[el[fn[2]]]-m.X[el[fn[0]]]); a += 0.5*c.norm(); *n_sum += 0.5*c; }
  return a;
}
void show(const char* name, const Mesh& m) {
  double v=0, vf=0; for (int e=0;e<m.num_elements();++e){ v+=corner_volume(m,e);} for(int e: m.element_sets.at("FABRIC")) vf+=corner_volume(m,e);
  Eigen::Vector3d n; double a = area_of(m, m.surfaces.at("CAVITY"), &n);
  std::map<std::string,double> cat;
  for (auto f : m.surfaces.at("CAVITY")) { const int* fn = face_local_nodes(m.type, f.local_face); const int* el = m.element(f.element);
    Eigen::Vector3d c = (m.X[el[fn[1]]]-m.X[el[fn[0]]]).cross(m.X[el[fn[2]]]-m.X[el[fn[0]]]); double a = 0.5*c.norm(); Eigen::Vector3d n = c.normalized();
    Eigen::Vector3d ctr = (m.X[el[fn[0]]]+m.X[el[fn[1]]]+m.X[el[fn[2]]])/3*1e3;
    std::string k = "slanted"; for (int d=0; d<3; ++d) { if (n[d] > 0.999999) k = std::string("+") + "xyz"[d]; if (n[d] < -0.999999) k = std::string("-") + "xyz"[d]; }
    if (k == "slanted") { char b[80]; std::snprintf(b, 80, "slanted z~%.1f x~%.1f", ctr.z(), ctr.x()); k = b; }
    cat[k] += a*1e6; }
  for (auto& [k,v] : cat) std::printf("   %s %.3f\n", k.c_str(), v);
  std::printf("%s: elems %d nodes %d vol %.6g fabric %.6g cavity faces %zu area %.6g nsum (%.3g %.3g %.3g) fixed %zu tip %zu sym %zu\n", name, m.num_elements(), m.num_nodes(), v*1e9, vf*1e9,
   m.surfaces.at("CAVITY").size(), a*1e6, n.x()*1e6, n.y()*1e6, n.z()*1e6, m.node_sets.at("FIXED").size(), m.node_sets.at("TIP").size(), m.node_sets.at("SYMMETRY").size());
}
TEST(Scratch, Write) {
  for (int n : {15, 4, 2}) { PneuNetParams p; p.chambers = n; write_stl("/tmp/stlscratch/pneunet" + std::to_string(n) + ".stl", test::pneunet_surface(p), 1e-3); }
}
TEST(Scratch, Compare) {
  PneuNetParams p; p.chambers = 4; p.h = 1e-3; p.element = ElementType::Tet4;
  show("built-in", build_pneunet(p));
  TriSurface s = test::pneunet_surface(p); close_and_orient(s);
  StlMeshSpec spec; spec.stuffing.h = p.h; spec.stuffing.half = true; spec.stuffing.has_slab = true; spec.stuffing.slab_z0 = 1.8e-3; spec.stuffing.slab_z1=2.2e-3;
  spec.element = ElementType::Tet4;
  for (bool fp : {true, false}) { spec.stuffing.feature_planes = fp; StlMeshReport r; Mesh m = mesh_closed_surface(s, spec, &r); show(fp ? "stl-feature" : "stl-uniform", m);
    if (!fp) { std::set<std::pair<int,int>> cav; for (auto f : m.surfaces.at("CAVITY")) cav.insert({f.element, f.local_face});
      int shown = 0; std::map<std::string,int> hist;
      for (auto f : boundary_faces(m)) { if (cav.count({f.element,f.local_face})) continue; const int* fn = face_local_nodes(m.type, f.local_face); const int* el = m.element(f.element);
        Eigen::Vector3d c = (m.X[el[fn[0]]]+m.X[el[fn[1]]]+m.X[el[fn[2]]])/3*1e3; 
        if (c.x() < 1e-9 || c.x() > 10.999 || c.y() < 1e-9 || c.y() > 37.999 || c.z() < 1e-9 || c.z() > 17.999) continue;
        char b[64]; std::snprintf(b, 64, "z=%.2f", c.z()); hist[b]++;
        if (shown++ < 10) std::printf("lost face centroid (%.3f %.3f %.3f)\n", c.x(), c.y(), c.z()); }
      for (auto& [k,v] : hist) std::printf("%s: %d\n", k.c_str(), v); } std::printf("%s", describe(r).c_str()); }
}
}
namespace pneufem {
TEST(Scratch, Alpha) {
  TriSurface t = test::tube_surface(0.006, 0.0035, 0.04, 0.003, 48); close_and_orient(t);
  for (double a : {0.2, 0.25, 0.3, 0.35, 0.4, 0.45}) for (double h : {1.5e-3, 1e-3}) {
    StlMeshSpec spec; spec.stuffing.h = h; spec.stuffing.alpha = a; spec.stuffing.has_slab = true; spec.stuffing.slab_z0 = -0.0058; spec.stuffing.slab_z1 = -0.005;
    StlMeshReport r; Mesh m = mesh_closed_surface(t, spec, &r);
    double v = 0; for (int e = 0; e < m.num_elements(); ++e) v += corner_volume(m, e);
    std::printf("alpha %.2f h %.1f: min %.1f max %.1f rr %.3f  <10deg %d  <20deg %d tets %d vol %.4f kept straight %d\n", a, h*1e3, r.min_dihedral_deg, r.max_dihedral_deg, r.min_radius_ratio, r.dihedral_histogram[0], r.dihedral_histogram[0]+r.dihedral_histogram[1], r.tets, v*1e9, r.midnodes_kept_straight);
  }
}
}
#include "scenes/inp/reader.h"
namespace pneufem {
void quality(const char* name, const Mesh& m) {
  double lo = 180, hi = 0; std::vector<int> hist(18, 0);
  for (int e = 0; e < m.num_elements(); ++e) { auto [a, b] = dihedral_range_deg(m, e); lo = std::min(lo, a); hi = std::max(hi, b); hist[std::min(17, int(a / 10))]++; }
  MeshStats st = compute_stats(m);
  std::printf("%s: %d elements, %d nodes, dihedral %.1f..%.1f, radius ratio min %.3f mean %.3f; hist:", name, st.elements, st.nodes, lo, hi, st.min_quality, st.mean_quality);
  for (int c : hist) std::printf(" %d", c); std::printf("\n");
}
TEST(Scratch, Gmsh) {
  InpDeck d = read_inp(std::string(PNEUFEM_TEST_DATA_DIR) + "/ccx_gmsh/pneunet_gmsh_h6_half.inp", 1e-3);
  quality("gmsh h6 half", d.mesh);
  PneuNetParams p; TriSurface s = test::pneunet_surface(p); close_and_orient(s);
  for (double h : {6e-3, 4e-3, 2e-3}) for (bool fp : {true, false}) {
    StlMeshSpec spec; spec.stuffing.h = h; spec.stuffing.half = true; spec.stuffing.has_slab = true; spec.stuffing.slab_z0 = 1.8e-3; spec.stuffing.slab_z1 = 2.2e-3; spec.stuffing.feature_planes = fp;
    StlMeshReport r; Mesh m = mesh_closed_surface(s, spec, &r);
    char b[64]; std::snprintf(b, 64, "stl h%.0f %s", h * 1e3, fp ? "feature" : "uniform"); quality(b, m); std::printf("%s", describe(r).c_str());
  }
  PneuNetParams q; q.h = 6e-3; quality("built-in h6", build_pneunet(q));
}
}
