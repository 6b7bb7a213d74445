// Surfaces given as triangular elements (scenes/inp/surface_elements.cpp), as Gmsh writes a named
// boundary and Abaqus users model a membrane: read as faces of the tetrahedra, the actuator bends as
// with the *SURFACE deck or the built-in model, and triangles off the mesh are refused.
#include <gtest/gtest.h>

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <sstream>
#include <string>
#include <tuple>
#include <vector>

#include "engine/assembly.h"
#include "engine/quasi_static.h"
#include "scenes/build_model.h"
#include "tests/scenes/inp/deck_files.h"

namespace pneufem {
namespace {

using namespace pneufem::test;

/// The faces of a Tet10 mesh's surface as a deck's 6-node triangle elements: the block header
/// line, then one element per face (ids after the mesh's), every second in the other winding when
/// `flip_every_other` (a mesher need not follow the faces' orientation).
std::string surface_as_elements(const Mesh& mesh, const std::string& surface, const std::string& header,
                                bool flip_every_other) {
  std::string out = header + "\n";
  long id = *std::max_element(mesh.element_ids.begin(), mesh.element_ids.end());
  int k = 0;
  for (const FaceRef& f : mesh.surfaces.at(surface)) {
    const int* ln = face_local_nodes(mesh.type, f.local_face);
    std::array<long, 6> n{};
    for (int j = 0; j < 6; ++j) n[static_cast<std::size_t>(j)] = mesh.node_ids[static_cast<std::size_t>(mesh.element(f.element)[ln[j]])];
    if (flip_every_other && k++ % 2) n = {n[0], n[2], n[1], n[5], n[4], n[3]};
    out += std::to_string(++id);
    for (long v : n) out += ", " + std::to_string(v);
    out += "\n";
  }
  return out;
}

/// `deck` without its *SURFACE, NAME=<name> block (a test failure if it has none).
std::string without_surface_block(std::string deck, const std::string& name) {
  const std::size_t a = deck.find("*SURFACE, NAME=" + name + ",");
  if (a == std::string::npos) {
    ADD_FAILURE() << "the deck has no *SURFACE, NAME=" << name;
    return deck;
  }
  return deck.erase(a, deck.find('*', a + 1) - a);
}

// A mesher's deck: Gmsh and others write named boundary surfaces as triangular elements (CPS6 for
// a second-order mesh), not as an element-face *SURFACE. The cavity given so, its triangles in
// either winding, is the cavity of the *SURFACE deck (same faces, a node set of their nodes), and
// the actuator bends the same; line elements are skipped with a note.
TEST_F(InpFiles, TriangularSurfaceElementsAreNamedSurfaces) {
  const Mesh mesh = build_mesh(Scene::load("", {"geometry.chambers=2", "mesh.h_mm=6.0"}));
  std::ostringstream os;
  write_inp_mesh(os, mesh, 1e-3);
  const std::string faces_deck = os.str();
  std::string deck = without_surface_block(faces_deck, "CAVITY");
  deck += surface_as_elements(mesh, "CAVITY", "*ELEMENT, TYPE=CPS6, ELSET=CAVITY", true) +
          "*ELEMENT, TYPE=T3D3, ELSET=EDGE\n999999, 1, 2, 3\n";
  const std::string gmsh_path = write("gmsh.inp", deck), faces_path = write("faces.inp", faces_deck);
  const InpDeck A = read_inp(faces_path, 1e-3), B = read_inp(gmsh_path, 1e-3);
  ASSERT_EQ(B.mesh.num_elements(), A.mesh.num_elements());  // the triangles are not elements
  std::vector<FaceRef> fa = A.mesh.surfaces.at("CAVITY"), fb = B.mesh.surfaces.at("CAVITY");
  auto less = [](const FaceRef& x, const FaceRef& y) { return std::tie(x.element, x.local_face) < std::tie(y.element, y.local_face); };
  std::sort(fa.begin(), fa.end(), less);
  std::sort(fb.begin(), fb.end(), less);
  EXPECT_EQ(fa, fb);
  std::vector<int> nodes;
  for (const FaceRef& f : fa)
    for (int j = 0; j < 6; ++j) nodes.push_back(A.mesh.element(f.element)[face_local_nodes(A.mesh.type, f.local_face)[j]]);
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  EXPECT_EQ(B.mesh.node_sets.at("CAVITY"), nodes);
  EXPECT_EQ(count_containing(B.warnings, "TYPE=CPS6, ELSET=CAVITY read as faces of the tetrahedra"), 1);
  EXPECT_EQ(count_containing(B.warnings, "TYPE=T3D3 skipped"), 1);

  auto angle_at_5kPa = [](const std::string& path) {
    auto bm = build_model(Scene::load("", {"mesh.source=\"inp\"", "mesh.file=\"" + path + "\"",
                                           "mesh.symmetry_set=\"SYMMETRY\"", "load.max_kPa=5.0"}));
    const Assembler asmb(bm->model);
    QuasiStaticRun run(asmb, bm->solver.quasi_static);
    double last = 0.0;
    run.run(bm->load, [&](const StateRecord& r, const Eigen::VectorXd&, const std::vector<double>&) { last = r.angle_deg; });
    return last;
  };
  const double angle_faces = angle_at_5kPa(faces_path), angle_gmsh = angle_at_5kPa(gmsh_path);
  EXPECT_GT(angle_faces, 0.05);
  // The same faces summed in another order: equal to round-off (rel_tol 1e-8 equilibria).
  EXPECT_NEAR(angle_gmsh, angle_faces, 1e-7 * angle_faces);
}

// A deck whose fabric is a membrane: Abaqus users model the inextensible layer as membrane (M3D6)
// or shell elements sharing nodes with the silicone, often embedded in it. The built-in actuator
// with mesh.fabric_model = "membrane" (its membrane on interior faces, the layer's mid-plane),
// written as a deck once with a *SURFACE and once with M3D6 elements, bends as the built-in model
// (same faces, same law; the sums run in another order: to the equilibria's round-off), and an
// embedded sheet named as the cavity is refused.
TEST_F(InpFiles, AMembraneFabricOnADeckSurfaceOrEmbeddedElementsBendsAsTheBuiltInOne) {
  const std::vector<std::string> base = {"geometry.chambers=2", "mesh.h_mm=6.0", "mesh.fabric_model=\"membrane\"",
                                         "load.max_kPa=5.0"};
  const Mesh mesh = build_mesh(Scene::load("", base));
  ASSERT_FALSE(mesh.surfaces.at("FABRIC_MEMBRANE").empty());
  std::ostringstream os;
  write_inp_mesh(os, mesh, 1e-3);
  const std::string faces_deck = os.str();
  const std::string deck = without_surface_block(faces_deck, "FABRIC_MEMBRANE");
  std::string tris = surface_as_elements(mesh, "FABRIC_MEMBRANE", "*ELEMENT, TYPE=M3D6, ELSET=FABRIC_MEMBRANE", false);
  tris += "*MEMBRANE SECTION, ELSET=FABRIC_MEMBRANE, MATERIAL=FABRIC\n0.4\n";
  const std::string faces_path = write("membrane_faces.inp", faces_deck), elements_path = write("membrane_m3d6.inp", deck + tris);
  auto angle = [](const Scene& scene, std::vector<std::string>* warnings) {
    auto bm = build_model(scene);
    EXPECT_EQ(bm->model.membranes.size(), 1u);
    if (warnings) *warnings = bm->warnings;
    const Assembler asmb(bm->model);
    QuasiStaticRun run(asmb, bm->solver.quasi_static);
    double last = 0.0;
    run.run(bm->load, [&](const StateRecord& r, const Eigen::VectorXd&, const std::vector<double>&) { last = r.angle_deg; });
    return last;
  };
  auto deck_scene = [&](const std::string& path, std::vector<std::string> extra = {}) {
    std::vector<std::string> o = base;
    o.insert(o.end(), {"mesh.source=\"inp\"", "mesh.file=\"" + path + "\"", "mesh.symmetry_set=\"SYMMETRY\""});
    o.insert(o.end(), extra.begin(), extra.end());
    return Scene::load("", o);
  };
  const double builtin = angle(Scene::load("", base), nullptr);
  std::vector<std::string> warnings;
  const double on_faces = angle(deck_scene(faces_path), nullptr);
  const double on_elements = angle(deck_scene(elements_path), &warnings);
  EXPECT_GT(builtin, 0.05);
  EXPECT_NEAR(on_faces, builtin, 1e-7 * builtin);
  EXPECT_NEAR(on_elements, builtin, 1e-7 * builtin);
  EXPECT_EQ(count_containing(warnings, "triangles of ELSET=FABRIC_MEMBRANE lie inside the solid"), 1);
  EXPECT_EQ(count_containing(warnings, "*MEMBRANE SECTION, ELSET=FABRIC_MEMBRANE: its elements are read as a surface, "
                                       "without stiffness; to model them as the fabric set mesh.fabric_model"), 1);
  try {
    build_model(deck_scene(elements_path, {"mesh.cavity_surface=\"FABRIC_MEMBRANE\""}));
    ADD_FAILURE() << "an embedded sheet was accepted as the cavity";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("has a face inside the solid"), std::string::npos) << e.what();
  }
  try {
    build_model(deck_scene(elements_path, {"mesh.fabric_surface=\"FABRIC\""}));
    ADD_FAILURE() << "a missing membrane surface was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("surface 'FABRIC' not found (the mesh has: "), std::string::npos) << e.what();
  }
}

TEST_F(InpFiles, SurfaceElementsOffTheMeshAreRejected) {
  // Two tets sharing the face 2-3-4 (a triangle there is an embedded sheet, tested above); a
  // triangle on no face at all.
  const std::string two = "*NODE\n1,0,0,0\n2,1,0,0\n3,0,1,0\n4,0,0,1\n5,1,1,1\n"
                          "*ELEMENT, TYPE=C3D4, ELSET=B\n1, 1, 2, 3, 4\n2, 2, 3, 4, 5\n";
  expect_error(two + "*ELEMENT, TYPE=CPS3, ELSET=S\n10, 1, 2, 5\n", 11,
               {"surface element 10 (ELSET=S) matches no face of the tetrahedra", "corners of a tetrahedron's face"});
  expect_error(two + "*ELEMENT, TYPE=CPS3\n10, 1, 2, 3\n", 10, {"without ELSET=", "name the surface"});
}

}  // namespace
}  // namespace pneufem
