// Hexahedral decks of a small actuator through the scene (build_model): as C3D20 and as promoted
// C3D8, as an Abaqus/CAE deck (an instance of a part) against its flat deck, and a scene's error
// naming the deck's element; and quadrilateral surface elements (Gmsh's named surfaces of a
// hexahedral mesh): the faces they cover, the same actuator, an embedded membrane sheet, and
// quadrilaterals on no face refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "core/errors.h"
#include "engine/assembly.h"
#include "engine/quasi_static.h"
#include "scenes/build_model.h"
#include "scenes/inp/deck.h"
#include "scenes/scene.h"
#include "tests/scenes/inp/solid_split_helpers.h"

namespace pneufem {
namespace {

using namespace test;

// ------------------------------------------------------------------------------------------------
// A hexahedral actuator deck through the scene
// ------------------------------------------------------------------------------------------------

// A small actuator as a deck of hexahedra: a 3 x 6 x 3 cell beam along y with a closed 1 x 4 x 1
// cell cavity and a thin stiff FABRIC layer at the bottom, fixed at y = 0 (lengths in mm).
Vec actuator_mm(const Vec& s) {  // x 0..12, y 0..36, z: fabric 0..0.4, then two layers of 4 mm
  const double z = s.z() <= 1.0 / 3 ? 1.2 * s.z() : 0.4 + 12.0 * (s.z() - 1.0 / 3);
  return Vec(12.0 * s.x(), 36.0 * s.y(), z);
}
bool actuator_cavity(int i, int j, int k) { return i == 1 && k == 1 && j >= 1 && j <= 4; }

/// The cavity's walls: (element id, face number) of the cells around it that face it (S1 z-,
/// S2 z+, S3 y-, S4 x+, S5 y+, S6 x-).
std::vector<std::pair<long, int>> actuator_walls(const HexBlock& b) {
  std::vector<std::pair<long, int>> walls;
  for (int j = 1; j <= 4; ++j)
    walls.insert(walls.end(),
                 {{b.element(0, j, 1), 4}, {b.element(2, j, 1), 6}, {b.element(1, j, 0), 2}, {b.element(1, j, 2), 1}});
  walls.insert(walls.end(), {{b.element(1, 0, 1), 5}, {b.element(1, 5, 1), 3}});
  return walls;
}

/// *ELSET FABRIC (the bottom layer of cells) and SILICONE (the others).
std::string actuator_elsets(const HexBlock& b) {
  std::string fabric = "*ELSET, ELSET=FABRIC\n", silicone = "*ELSET, ELSET=SILICONE\n";
  for (int k = 0; k < 3; ++k)
    for (int j = 0; j < 6; ++j)
      for (int i = 0; i < 3; ++i)
        if (!actuator_cavity(i, j, k)) (k == 0 ? fabric : silicone) += std::to_string(b.element(i, j, k)) + "\n";
  return fabric + silicone;
}

/// The bending angle at the end of the scene's load, and the model's warnings.
double actuator_angle(const std::string& path, std::vector<std::string> extra, std::vector<std::string>* warnings) {
  extra.insert(extra.end(), {"mesh.source=\"inp\"", "mesh.file=\"" + path + "\"", "load.max_kPa=5.0"});
  auto bm = build_model(Scene::load("", extra));
  if (warnings) *warnings = bm->warnings;
  EXPECT_EQ(bm->model.mesh.type, ElementType::Tet10);
  // The cavity's 18 quadrilaterals, two triangles each, all on the boundary.
  EXPECT_EQ(bm->model.pressure_faces.size(), 36u);
  const Assembler asmb(bm->model);
  QuasiStaticRun qs(asmb, bm->solver.quasi_static);
  double last = 0.0;
  qs.run(bm->load, [&](const StateRecord& r, const Eigen::VectorXd&, const std::vector<double>&) { last = r.angle_deg; });
  return last;
}

// The actuator through the scene: as C3D20 (split to Tet10) and as the same corners in C3D8 with
// mesh.promote_to_tet10 it is the same Tet10 mesh (the same cuts, the same straight mid-edge
// nodes), numbered differently: the same angle, to the equilibria's round-off. Without promotion
// the linear tetrahedra lock: the note says so.
TEST_F(SolidDecks, AHexahedralActuatorDeckBendsTheSameAsC3D20AndAsPromotedC3D8) {
  HexBlock b(3, 6, 3, true, 31, actuator_mm);
  b.remove_cells(actuator_cavity);
  std::string surface = "*SURFACE, NAME=CAVITY\n";
  for (const auto& [element, face] : actuator_walls(b))
    surface += std::to_string(element) + ", S" + std::to_string(face) + "\n";
  const std::string elsets = actuator_elsets(b);
  auto deck = [&](const HexBlock& g, const std::string& type) {
    return g.nodes() + g.elements("*ELEMENT, TYPE=" + type + ", ELSET=BODY") + elsets + surface +
           g.nset("FIXED", [](const Vec& s) { return s.y() == 0.0; }) + g.nset("TIP", [](const Vec& s) { return s.y() == 1.0; });
  };
  const std::string quadratic = write("c3d20.inp", deck(b, "C3D20H")), linear = write("c3d8.inp", deck(b.corners_only(), "C3D8H"));
  std::vector<std::string> w20, w8;
  const double a20 = actuator_angle(quadratic, {}, &w20), a8 = actuator_angle(linear, {"mesh.promote_to_tet10=true"}, &w8);
  std::printf("hexahedral actuator at 5 kPa: C3D20 %.9f deg, C3D8 promoted %.9f deg\n", a20, a8);
  EXPECT_GT(a20, 0.05) << "the actuator curls towards its fabric";
  EXPECT_NEAR(a8, a20, 1e-6 * a20);
  EXPECT_EQ(count_containing(w20, "C3D20 into"), 1);
  EXPECT_EQ(count_containing(w8, "C3D8 into"), 1);
  EXPECT_EQ(count_containing(w8, "mesh.promote_to_tet10 = true (recommended)"), 1);
}

// The C3D20 actuator as Abaqus/CAE writes it: part Actuator (its nodes moved by -shift, the
// element sets), one instance translated back by shift, FIXED and TIP as assembly sets with
// INSTANCE=, the cavity walls as an assembly surface on INTERNAL element sets per face number,
// loaded by *DSLOAD, and *BOUNDARY on the assembly set. The flat deck loads the same hexahedron
// faces by *DLOAD. Neither names a CAVITY surface, so both scenes take the pressure faces as the
// cavity, and the angle frame from the mesh. The instance's elements split as the flat deck's: the
// same tetrahedra, ids, labels, sets, fixed dofs, tip nodes, cavity faces and frame, the same angle.
TEST_F(SolidDecks, AHexahedralActuatorAsACaeDeckSplitsAndBendsAsTheFlatDeck) {
  const Vec shift(0.0, 12.3, -4.7);  // not exact in binary: the placement shows as round-off only
  HexBlock flat(3, 6, 3, true, 31, actuator_mm);
  HexBlock part(3, 6, 3, true, 31, [&](const Vec& s) { return Vec(actuator_mm(s) - shift); });
  flat.remove_cells(actuator_cavity);
  part.remove_cells(actuator_cavity);
  const std::vector<std::pair<long, int>> walls = actuator_walls(flat);
  auto fixed = [](const Vec& s) { return s.y() == 0.0; };
  auto tip = [](const Vec& s) { return s.y() == 1.0; };

  std::string dload = "*DLOAD\n";
  for (const auto& [element, face] : walls)
    dload += std::to_string(element) + ", P" + std::to_string(face) + ", 0.005\n";
  const std::string flat_path = write("flat.inp", flat.nodes() + flat.elements("*ELEMENT, TYPE=C3D20H, ELSET=BODY") +
                                                      actuator_elsets(flat) + flat.nset("FIXED", fixed) +
                                                      flat.nset("TIP", tip) + dload);
  std::ostringstream cae;
  cae.precision(17);
  cae << "*Heading\n** Generated by: Abaqus/CAE 2021\n*Part, name=Actuator\n" << part.nodes()
      << part.elements("*Element, type=C3D20H, elset=BODY") << actuator_elsets(part)
      << "*Solid Section, elset=SILICONE, material=Ecoflex\n,\n*Solid Section, elset=FABRIC, material=Fabric\n,\n"
      << "*End Part\n"
      << "*Assembly, name=Assembly\n*Instance, name=Actuator-1, part=Actuator\n"
      << shift.x() << ", " << shift.y() << ", " << shift.z() << "\n*End Instance\n"
      << part.nset("Fixed, instance=Actuator-1", fixed) << part.nset("Tip, instance=Actuator-1", tip);
  for (int f = 1; f <= 6; ++f) {
    cae << "*Elset, elset=_Walls_S" << f << ", internal, instance=Actuator-1\n";
    for (const auto& [element, face] : walls)
      if (face == f) cae << element << "\n";
  }
  cae << "*Surface, type=ELEMENT, name=Walls\n";
  for (int f = 1; f <= 6; ++f) cae << "_Walls_S" << f << ", S" << f << "\n";
  // The materials and sections are the default scene's (a scene takes them from the deck, the flat deck
  // has none): Yeoh with D1 = 0 takes the default K0/mu0 = 100; no *DENSITY, the default 1070 kg/m^3.
  cae << "*End Assembly\n*Material, name=Ecoflex\n*Hyperelastic, yeoh\n 0.019, 0.0009, -4.75e-6\n"
         "*Material, name=Fabric\n*Elastic\n6500., 0.2\n"
         "*Step, name=Inflate, nlgeom=YES\n*Static\n0.1, 1., 1e-05, 0.1\n*Boundary\nFixed, ENCASTRE\n"
         "*Dsload\nWalls, P, 0.005\n*End Step\n";
  const std::string cae_path = write("cae.inp", cae.str());

  auto scene = [](const std::string& path) {
    return Scene::load("", {"mesh.source=\"inp\"", "mesh.file=\"" + path + "\"", "load.max_kPa=5.0"});
  };
  const auto f = build_model(scene(flat_path)), c = build_model(scene(cae_path));
  const Mesh &fm = f->model.mesh, &cm = c->model.mesh;
  ASSERT_EQ(cm.num_nodes(), fm.num_nodes());
  ASSERT_EQ(cm.num_elements(), fm.num_elements());
  EXPECT_EQ(cm.conn, fm.conn);
  EXPECT_EQ(cm.node_ids, fm.node_ids);
  EXPECT_EQ(cm.element_ids, fm.element_ids);  // one instance: the deck's ids, the split's new ones alike
  EXPECT_TRUE(cm.id_scopes.empty());
  double max_dx = 0.0;
  for (int n = 0; n < fm.num_nodes(); ++n)
    max_dx = std::max(max_dx, (cm.X[static_cast<std::size_t>(n)] - fm.X[static_cast<std::size_t>(n)]).norm());
  EXPECT_LT(max_dx, 1e-16);  // a few ulps of the ~0.04 m coordinates, the new mid-nodes too
  for (int e = 0; e < fm.num_elements(); ++e) ASSERT_EQ(cm.element_label(e), fm.element_label(e));
  EXPECT_NE(cm.element_label(fm.num_elements() - 1).find(" of C3D20 "), std::string::npos);
  for (const char* set : {"FABRIC", "SILICONE"}) EXPECT_EQ(cm.element_sets.at(set), fm.element_sets.at(set)) << set;
  for (const char* set : {"FIXED", "TIP"}) EXPECT_EQ(cm.node_sets.at(set), fm.node_sets.at(set)) << set;
  EXPECT_EQ(cm.element_sets.at("ACTUATOR-1.FABRIC"), fm.element_sets.at("FABRIC"));

  // The *DSLOAD faces of the assembly surface are the *DLOAD faces, grouped by face number.
  auto sorted_faces = [](std::vector<FaceRef> v) {
    std::sort(v.begin(), v.end(), [](const FaceRef& a, const FaceRef& b) {
      return std::pair(a.element, a.local_face) < std::pair(b.element, b.local_face);
    });
    return v;
  };
  EXPECT_EQ(f->model.pressure_faces.size(), 36u);
  EXPECT_EQ(sorted_faces(c->model.pressure_faces), sorted_faces(f->model.pressure_faces));
  EXPECT_EQ(c->model.fixed, f->model.fixed);
  EXPECT_EQ(c->model.angle.tip_nodes, f->model.angle.tip_nodes);
  EXPECT_LT((c->model.angle.fixed_normal_out - f->model.angle.fixed_normal_out).norm(), 1e-12);
  EXPECT_LT((c->model.angle.bend_direction - f->model.angle.bend_direction).norm(), 1e-12);
  for (const auto* bm : {f.get(), c.get()}) {
    EXPECT_EQ(count_containing(bm->warnings, "faces of its pressure load (36 *DLOAD/*DSLOAD P faces) are the cavity"), 1);
    EXPECT_EQ(count_containing(bm->warnings, "C3D20 into"), 1);
  }
  EXPECT_EQ(count_containing(c->warnings, "part 'Actuator' (instance 'Actuator-1'): split into tetrahedra"), 1);

  std::vector<std::string> wf, wc;
  const double a_flat = actuator_angle(flat_path, {}, &wf), a_cae = actuator_angle(cae_path, {}, &wc);
  EXPECT_GT(a_flat, 0.05);
  // The same mesh, faces and materials; the runs differ by the coordinates' round-off and the
  // order in which the cavity faces are summed (the split amplifies nothing): 1e-10 relative
  // leaves a wide margin, a missing face or a wrong fixed or tip node changes far more.
  EXPECT_NEAR(a_cae, a_flat, 1e-10 * a_flat);
  EXPECT_EQ(count_containing(wc, "instances"), 0);
}

// A scene's error about a split element names the deck's element.
TEST_F(SolidDecks, SceneErrorsNameTheDeckElement) {
  const HexBlock b(2, 1, 1, false, 3, [](const Vec& s) { return Vec(10.0 * s.x(), 5.0 * s.y(), 5.0 * s.z()); });
  const std::string path =
      write("inner.inp", b.nodes() + b.elements("*ELEMENT, TYPE=C3D8, ELSET=SILICONE") + "*ELSET, ELSET=FABRIC\n" +
                             "*SURFACE, NAME=CAVITY\n1, S4\n" +  // S4 of element 1 (x+) is element 2's S6: inside
                             b.nset("FIXED", [](const Vec& s) { return s.x() == 0.0; }) +
                             b.nset("TIP", [](const Vec& s) { return s.x() == 1.0; }));
  try {
    build_model(Scene::load("", {"mesh.source=\"inp\"", "mesh.file=\"" + path + "\""}));
    ADD_FAILURE() << "an inner face was accepted as the cavity";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("'CAVITY' has a face inside the solid"), std::string::npos) << what;
    EXPECT_NE(what.find(" of C3D8 1, region 'silicone'), shared by two tetrahedra"), std::string::npos) << what;
  }
}

// ------------------------------------------------------------------------------------------------
// Quadrilateral surface elements (how Gmsh writes the named surfaces of a hexahedral mesh)
// ------------------------------------------------------------------------------------------------

/// Corners (0-based) of the hexahedron faces S1..S6, in the Abaqus order (solid_split.h).
constexpr int kHexFace[6][4] = {{0, 1, 2, 3}, {4, 7, 6, 5}, {0, 4, 5, 1}, {1, 5, 6, 2}, {2, 6, 7, 3}, {3, 7, 4, 0}};
/// Corner pairs of the C3D20 mid-edge nodes 9..20.
constexpr int kHexEdge[12][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6}, {6, 7}, {7, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};

/// Face `face` (1-based) of a hexahedron with nodes `n` (C3D8 or C3D20 order) as the data line of
/// a quadrilateral element: its corners from the face's corner `start`, around the face in the
/// Abaqus order or, `reversed`, the other way; for a C3D20 then the mid-edge nodes of its sides,
/// in the same order (a CPS8: corners, then the middles of sides 1-2, 2-3, 3-4, 4-1).
std::string quad_line(long id, const std::vector<long>& n, int face, int start, bool reversed) {
  std::array<int, 4> c{};
  for (int k = 0; k < 4; ++k) c[static_cast<std::size_t>(k)] = kHexFace[face - 1][(start + (reversed ? 4 - k : k)) % 4];
  std::string out = std::to_string(id);
  for (int a : c) out += ", " + std::to_string(n[static_cast<std::size_t>(a)]);
  if (n.size() == 20)
    for (int k = 0; k < 4; ++k) {
      const int a = c[static_cast<std::size_t>(k)], b = c[static_cast<std::size_t>((k + 1) % 4)];
      int e = 0;
      while (!((kHexEdge[e][0] == a && kHexEdge[e][1] == b) || (kHexEdge[e][0] == b && kHexEdge[e][1] == a))) ++e;
      out += ", " + std::to_string(n[static_cast<std::size_t>(8 + e)]);
    }
  return out + "\n";
}

/// Faces (element id, face number) of a block as an *ELEMENT block of quadrilaterals with ids
/// from `first_id`, each face from another corner and every fourth the other way round (all 8
/// node orders of a quadrilateral in turn).
std::string quad_block(const HexBlock& b, const std::string& header, const std::vector<std::pair<long, int>>& faces,
                       long first_id) {
  std::string out = header + "\n";
  int k = 0;
  for (const auto& [element, face] : faces) {
    const int e = static_cast<int>(element - 1), i = e % b.nx_, j = (e / b.nx_) % b.ny_, l = e / (b.nx_ * b.ny_);
    out += quad_line(first_id++, b.cell(i, j, l), face, k % 4, (k / 4) % 2 == 1);
    ++k;
  }
  return out;
}

/// The same faces as an element-face *SURFACE.
std::string face_surface(const std::string& name, const std::vector<std::pair<long, int>>& faces) {
  std::string out = "*SURFACE, NAME=" + name + ", TYPE=ELEMENT\n";
  for (const auto& [element, face] : faces) out += std::to_string(element) + ", S" + std::to_string(face) + "\n";
  return out;
}

/// Nodes of the faces of a tetrahedral mesh, sorted, each once.
std::vector<int> nodes_of(const Mesh& m, const std::vector<FaceRef>& faces) {
  std::vector<int> nodes;
  for (const FaceRef& f : faces)
    for (int a = 0; a < nodes_per_face(m.type); ++a) nodes.push_back(m.element(f.element)[face_local_nodes(m.type, f.local_face)[a]]);
  std::sort(nodes.begin(), nodes.end());
  nodes.erase(std::unique(nodes.begin(), nodes.end()), nodes.end());
  return nodes;
}

// Every face of a hexahedron (C3D8 and C3D20, node ids shuffled so the cut diagonals vary) written
// as a quadrilateral element in each of its 8 node orders (4 first corners, 2 windings) is the
// surface its *SURFACE face gives: the same two tetrahedron faces, in the same order. So are the
// quadrilateral faces of a wedge, in an ELSET that holds its triangles too (other element types).
TEST_F(SolidDecks, AQuadrilateralElementInAnyNodeOrderIsTheFaceItCovers) {
  const Eigen::Matrix3d A = shear();
  for (bool quadratic : {false, true})
    for (unsigned seed = 1; seed <= 4; ++seed) {
      const HexBlock b(1, 1, 1, quadratic, seed, [&](const Vec& s) { return Vec(A * s); });
      std::string deck = b.nodes() + b.elements(quadratic ? "*ELEMENT, TYPE=C3D20, ELSET=BODY" : "*ELEMENT, TYPE=C3D8, ELSET=BODY");
      long id = 100;
      for (int face = 1; face <= 6; ++face) {
        const std::string f = std::to_string(face);
        deck += face_surface("S" + f, {{1, face}});
        for (int order = 0; order < 8; ++order)
          deck += "*ELEMENT, TYPE=" + std::string(quadratic ? "S8R" : "S4R") + ", ELSET=Q" + f + "_" +
                  std::to_string(order) + "\n" + quad_line(++id, b.cell(0, 0, 0), face, order % 4, order >= 4);
      }
      const InpDeck d = read(deck);
      for (int face = 1; face <= 6; ++face) {
        const std::string f = std::to_string(face);
        const std::vector<FaceRef>& want = d.mesh.surfaces.at("S" + f);
        ASSERT_EQ(want.size(), 2u);
        for (int order = 0; order < 8; ++order) {
          const std::string q = "Q" + f + "_" + std::to_string(order);
          EXPECT_EQ(d.mesh.surfaces.at(q), want) << q << ", seed " << seed << (quadratic ? ", C3D20" : ", C3D8");
          EXPECT_EQ(d.mesh.node_sets.at(q), nodes_of(d.mesh, want)) << q;
        }
      }
      EXPECT_EQ(count_containing(d.warnings, "lie inside the solid"), 0);
    }
  // The wedge 1-2-3 / 5-6-7 of the unit cube: quadrilaterals S3, S4, S5 (M3D4) and triangles S1,
  // S2 (M3D3) in one ELSET, as the *SURFACE of those faces.
  const InpDeck w = read(kCube + "*ELEMENT, TYPE=C3D6\n1, 1, 2, 3, 5, 6, 7\n*ELEMENT, TYPE=M3D4, ELSET=All\n"
                                 "11, 1, 5, 6, 2\n12, 3, 7, 6, 2\n13, 7, 5, 1, 3\n*ELEMENT, TYPE=M3D3, ELSET=All\n"
                                 "14, 1, 2, 3\n15, 5, 7, 6\n*SURFACE, NAME=Faces\n1, S3\n1, S4\n1, S5\n1, S1\n1, S2\n");
  EXPECT_EQ(w.mesh.surfaces.at("ALL").size(), 8u);
  EXPECT_EQ(w.mesh.surfaces.at("ALL"), w.mesh.surfaces.at("FACES"));
  EXPECT_EQ(w.mesh.node_sets.at("ALL"), (std::vector<int>{0, 1, 2, 4, 5, 6}));
  EXPECT_EQ(count_containing(w.warnings, "TYPE=M3D4, ELSET=ALL read as faces of the tetrahedra (a quadrilateral as the "
                                         "two of its split): surface and node set ALL"), 1);
}

// Gmsh writes the physical surfaces of a hexahedral mesh as quadrilateral elements (CPS4; CPS8 for
// a second-order mesh; shells S4R, S8R alike). The hexahedral actuator whose cavity, clamped end
// and tip are given so, in every node order, is the model of the same deck with element-face
// *SURFACE blocks (and *NSET for the clamped end and the tip): the same surfaces, node sets (on
// C3D20 faces with the node the split put on their diagonal), pressure faces, fixed dofs and tip
// nodes, and the same angle; as C3D20, and as C3D8 promoted to Tet10.
TEST_F(SolidDecks, AHexahedralDeckWithQuadrilateralSurfacesIsItsDeckWithElementFaceSurfaces) {
  for (bool quadratic : {true, false}) {
    HexBlock b20(3, 6, 3, true, 31, actuator_mm);
    b20.remove_cells(actuator_cavity);
    const HexBlock b = quadratic ? b20 : b20.corners_only();
    std::vector<std::pair<long, int>> fixed, tip;  // the end faces y = 0 (S3) and y = 36 mm (S5)
    for (int k = 0; k < 3; ++k)
      for (int i = 0; i < 3; ++i) {
        fixed.emplace_back(b.element(i, 0, k), 3);
        tip.emplace_back(b.element(i, 5, k), 5);
      }
    const std::vector<std::pair<long, int>> walls = actuator_walls(b);
    const std::string mesh = b.nodes() + b.elements(quadratic ? "*ELEMENT, TYPE=C3D20H, ELSET=BODY" : "*ELEMENT, TYPE=C3D8H, ELSET=BODY") +
                             actuator_elsets(b);
    const std::string faces_path =
        write("faces.inp", mesh + face_surface("CAVITY", walls) + face_surface("FIXED", fixed) + face_surface("TIP", tip) +
                               b.nset("FIXED", [](const Vec& s) { return s.y() == 0.0; }) +
                               b.nset("TIP", [](const Vec& s) { return s.y() == 1.0; }));
    const std::string quad = quadratic ? "CPS8" : "CPS4", shell = quadratic ? "S8R" : "S4R";
    const std::string quads_path =
        write("quads.inp", mesh + quad_block(b, "*ELEMENT, TYPE=" + quad + ", ELSET=Cavity", walls, 1001) +
                               quad_block(b, "*Element, type=" + shell + ", elset=Fixed", fixed, 2001) +
                               quad_block(b, "*ELEMENT, TYPE=" + quad + ", ELSET=Tip", tip, 3001));
    SCOPED_TRACE(quadratic ? "C3D20" : "C3D8");

    const InpDeck F = read_inp(faces_path, 1e-3), Q = read_inp(quads_path, 1e-3);
    ASSERT_EQ(Q.mesh.conn, F.mesh.conn);  // the quadrilaterals are no elements
    ASSERT_EQ(Q.mesh.X, F.mesh.X);
    for (const char* name : {"CAVITY", "FIXED", "TIP"}) EXPECT_EQ(Q.mesh.surfaces.at(name), F.mesh.surfaces.at(name)) << name;
    for (const char* name : {"FIXED", "TIP"}) EXPECT_EQ(Q.mesh.node_sets.at(name), F.mesh.node_sets.at(name)) << name;
    EXPECT_EQ(Q.mesh.node_sets.at("CAVITY"), nodes_of(F.mesh, F.mesh.surfaces.at("CAVITY")));
    const std::vector<int>& fixed_nodes = Q.mesh.node_sets.at("FIXED");
    const auto diagonal_nodes = std::count_if(fixed_nodes.begin(), fixed_nodes.end(), [&](int n) { return n >= b.node_count(); });
    EXPECT_EQ(diagonal_nodes, quadratic ? 9 : 0);  // one per face of the clamped end
    EXPECT_EQ(count_containing(Q.warnings, "*ELEMENT, TYPE=" + quad + ", ELSET=CAVITY read as faces of the tetrahedra"), 1);
    EXPECT_EQ(count_containing(Q.warnings, "*ELEMENT, TYPE=" + shell + ", ELSET=FIXED read as faces"), 1);
    EXPECT_EQ(count_containing(Q.warnings, "inside the solid"), 0);
    EXPECT_EQ(count_containing(Q.warnings, "skipped"), 0);

    std::vector<std::string> extra = {"load.max_kPa=5.0"};
    if (!quadratic) extra.push_back("mesh.promote_to_tet10=true");
    auto scene = [&](const std::string& path) {
      std::vector<std::string> o = extra;
      o.insert(o.end(), {"mesh.source=\"inp\"", "mesh.file=\"" + path + "\""});
      return Scene::load("", o);
    };
    const auto fm = build_model(scene(faces_path)), qm = build_model(scene(quads_path));
    EXPECT_EQ(qm->model.pressure_faces, fm->model.pressure_faces);
    EXPECT_EQ(qm->model.pressure_faces.size(), 36u);
    EXPECT_EQ(qm->model.fixed, fm->model.fixed);
    EXPECT_EQ(qm->model.angle.tip_nodes, fm->model.angle.tip_nodes);
    const double a_faces = actuator_angle(faces_path, extra, nullptr), a_quads = actuator_angle(quads_path, extra, nullptr);
    std::printf("%s actuator at 5 kPa: *SURFACE faces %.12f deg, quadrilateral elements %.12f deg\n",
                quadratic ? "C3D20" : "C3D8 promoted", a_faces, a_quads);
    EXPECT_GT(a_faces, 0.05);
    EXPECT_NEAR(a_quads, a_faces, 1e-12 * a_faces);  // the same model: equal up to nothing but round-off
  }
}

// The fabric as a membrane on a hexahedral mesh: a sheet of M3D8 elements on the interface of the
// fabric layer and the silicone, 14 of its 18 quadrilaterals between two hexahedra (the other 4
// are the floor of the cavity). It is the surface its *SURFACE gives, with a note that it lies
// inside the solid; the membrane on its triangles bends the actuator as on the *SURFACE's, and the
// sheet named as the cavity is refused at the scene's line.
TEST_F(SolidDecks, AnEmbeddedQuadrilateralSheetCarriesTheMembraneAndIsNoCavity) {
  HexBlock b(3, 6, 3, true, 31, actuator_mm);
  b.remove_cells(actuator_cavity);
  std::vector<std::pair<long, int>> sheet;  // S2 (z+) of the fabric layer's cells
  for (int j = 0; j < 6; ++j)
    for (int i = 0; i < 3; ++i) sheet.emplace_back(b.element(i, j, 0), 2);
  const std::string mesh = b.nodes() + b.elements("*ELEMENT, TYPE=C3D20H, ELSET=BODY") + actuator_elsets(b) +
                           face_surface("CAVITY", actuator_walls(b)) +
                           b.nset("FIXED", [](const Vec& s) { return s.y() == 0.0; }) +
                           b.nset("TIP", [](const Vec& s) { return s.y() == 1.0; });
  const std::string faces_path = write("faces.inp", mesh + face_surface("SHEET", sheet));
  const std::string quads_path = write("quads.inp", mesh + quad_block(b, "*ELEMENT, TYPE=M3D8, ELSET=SHEET", sheet, 5001) +
                                                        "*MEMBRANE SECTION, ELSET=SHEET, MATERIAL=FABRIC\n0.4\n");
  const InpDeck F = read_inp(faces_path, 1e-3), Q = read_inp(quads_path, 1e-3);
  EXPECT_EQ(Q.mesh.surfaces.at("SHEET"), F.mesh.surfaces.at("SHEET"));
  EXPECT_EQ(Q.mesh.surfaces.at("SHEET").size(), 36u);
  EXPECT_EQ(count_containing(Q.warnings, "quads.inp:" + std::to_string(std::count(mesh.begin(), mesh.end(), '\n') + 2) +
                                             ": 14 of the 18 quadrilaterals of ELSET=SHEET lie inside the solid"),
            1);
  EXPECT_EQ(count_containing(Q.warnings, "*MEMBRANE SECTION, ELSET=SHEET: its elements are read as a surface"), 1);

  const std::vector<std::string> membrane = {"mesh.fabric_model=\"membrane\"", "mesh.fabric_surface=\"SHEET\""};
  std::vector<std::string> wf, wq;
  const double a_faces = actuator_angle(faces_path, membrane, &wf), a_quads = actuator_angle(quads_path, membrane, &wq);
  const double a_solid = actuator_angle(faces_path, {}, nullptr);
  std::printf("actuator at 5 kPa: fabric membrane on the *SURFACE %.12f deg, on M3D8 %.12f deg; without %.12f deg\n",
              a_faces, a_quads, a_solid);
  EXPECT_GT(a_faces, 0.05);
  EXPECT_NEAR(a_quads, a_faces, 1e-12 * a_faces);
  EXPECT_GT(std::abs(a_faces - a_solid), 1e-3 * a_solid) << "the membrane carries load";

  const std::string scene_path = write("scene.toml", "[mesh]\nsource = \"inp\"\nfile = \"quads.inp\"\n"
                                                     "cavity_surface = \"SHEET\"\n");
  try {
    build_model(Scene::load(scene_path));
    ADD_FAILURE() << "an embedded sheet was accepted as the cavity";
  } catch (const InputError& e) {
    const std::string what = e.what();
    for (const char* part : {"scene.toml:4: key 'mesh.cavity_surface': 'SHEET' has a face inside the solid (face ",
                             " of C3D20 ", "shared by two tetrahedra", "name the surface of the chamber walls"})
      EXPECT_NE(what.find(part), std::string::npos) << "missing '" << part << "' in: " << what;
  }
}

// A quadrilateral that is no face: its corners out of order around the face, off the elements, or
// in a part (named with the part and the instance).
TEST_F(SolidDecks, QuadrilateralElementsOnNoFaceAreRefused) {
  const std::string cube = kCube + "9, 2, 0, 0\n*ELEMENT, TYPE=C3D8\n1, 1, 2, 3, 4, 5, 6, 7, 8\n";  // lines 1-12
  const std::string hint =
      "its first four nodes, in order around it (either way), must be the corners of a face of a hexahedron, wedge or "
      "pyramid (export the surface from the same mesh)";
  expect_error(cube + "*ELEMENT, TYPE=CPS4, ELSET=Bottom\n10, 1, 3, 2, 4\n", 14,
               {"surface element 10 (ELSET=BOTTOM) matches no quadrilateral face of the solid elements", hint});
  expect_error(cube + "*ELEMENT, TYPE=S4R, ELSET=S\n10, 4, 3, 2, 1\n11, 2, 9, 3, 6\n", 15,
               {"surface element 11 (ELSET=S) matches no quadrilateral face", hint});
  std::string part = "*Part, name=P\n" + kCube + "*Element, type=C3D8\n1, 1, 2, 3, 4, 5, 6, 7, 8\n";  // lines 1-12
  part += "*Element, type=CPS4, elset=S\n10, 1, 2, 3, 5\n*End Part\n*Assembly, name=A\n*Instance, name=P-1, part=P\n"
          "*End Instance\n*End Assembly\n";
  expect_error(part, 14,
               {"part 'P' (instance 'P-1'): surface element 10 (ELSET=S) matches no quadrilateral face",
                "export the surface from the same mesh; in an assembly, from the same instance"});
}

}  // namespace
}  // namespace pneufem
