// Decks as Abaqus/CAE writes them (scenes/inp/deck.h, scenes/inp/assembly.h): *PART / *ASSEMBLY /
// *INSTANCE with placement, assembly-level sets with INSTANCE=, qualified names, INTERNAL element
// sets behind element-based *SURFACEs, *DSLOAD; several instances with their own numbering; the
// built-in actuator written as a CAE deck bends as its flat deck does; user errors name file,
// line and what to do.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "core/errors.h"
#include "engine/assembly.h"
#include "engine/quasi_static.h"
#include "scenes/build_model.h"
#include "scenes/inp/assembly.h"
#include "scenes/inp/deck.h"
#include "tests/scenes/inp/deck_files.h"

namespace pneufem {
namespace {

namespace fs = std::filesystem;

using test::count_containing;
using test::data_path;

/// 1-based number of the first line of `text` that contains `needle` (0 if none); a needle
/// starting with '\n' names the line after that newline ("\n6\n": the line "6").
int line_of(const std::string& text, const std::string& needle) {
  const std::size_t at = text.find(needle);
  if (at == std::string::npos) return 0;
  const int lead = !needle.empty() && needle.front() == '\n' ? 1 : 0;
  return 1 + lead + static_cast<int>(std::count(text.begin(), text.begin() + static_cast<std::ptrdiff_t>(at), '\n'));
}

/// InpFiles (a fresh directory per test), with an error's line named by the text it holds.
class InpAssemblyFiles : public test::InpFiles {
 protected:
  /// The message must name bad.inp and the line holding `line_text`, and contain every hint.
  void expect_error(const std::string& text, const std::string& line_text, const std::vector<std::string>& hints) const {
    const int line = line_of(text, line_text);
    ASSERT_GT(line, 0) << "no line '" << line_text << "' in the deck";
    const std::string msg = error_of(text);
    ASSERT_FALSE(msg.empty()) << "no InputError for:\n" << text;
    EXPECT_NE(msg.find("bad.inp:" + std::to_string(line) + ": "), std::string::npos) << msg;
    for (const std::string& h : hints) EXPECT_NE(msg.find(h), std::string::npos) << "missing '" << h << "' in: " << msg;
  }
};

// -------------------------------------------------------------------------------------------
// The hand-written CAE deck (tests/data/inp/cae_block.inp): two tetrahedra in part Block, one
// instance translated by (5, 0, 0) and turned 90 degrees about the z axis through (5, 0, 0).
// -------------------------------------------------------------------------------------------

TEST(InpAssembly, CaeDeckPartInstanceSetsSurfacesAndDsload) {
  // In metres (length_to_m = 1) the placement is exact: part point (x, y, z) -> (5 - y, x, z).
  const InpDeck d = read_inp(data_path("cae_block.inp"), 1.0);
  const Mesh& m = d.mesh;
  EXPECT_EQ(m.type, ElementType::Tet4);  // C3D4H
  ASSERT_EQ(m.num_nodes(), 5);
  ASSERT_EQ(m.num_elements(), 2);
  const std::vector<Eigen::Vector3d> part = {{0, 0, 0}, {10, 0, 0}, {0, 10, 0}, {0, 0, 10}, {10, 10, 10}};
  for (int n = 0; n < 5; ++n) {
    const Eigen::Vector3d& p = part[static_cast<std::size_t>(n)];
    EXPECT_EQ(m.X[static_cast<std::size_t>(n)], Eigen::Vector3d(5.0 - p.y(), p.x(), p.z())) << "node " << n + 1;
  }
  EXPECT_EQ(m.X[4], Eigen::Vector3d(-5.0, 10.0, 10.0));  // node 5 by hand
  // One instance: the deck's own ids, no qualified labels.
  EXPECT_EQ(m.node_ids, (std::vector<long>{1, 2, 3, 4, 5}));
  EXPECT_EQ(m.element_ids, (std::vector<long>{1, 2}));
  EXPECT_TRUE(m.id_scopes.empty());
  EXPECT_EQ(m.element_label(1), "element 2 (region 'default')");
  EXPECT_EQ(m.node_name(4), "5");
  EXPECT_EQ(d.solid_instances, (std::vector<std::string>{"Block-1"}));

  // Part sets under the qualified and the bare name; assembly sets (INSTANCE=, qualified ids,
  // GENERATE) under their own; INTERNAL sets not at all.
  EXPECT_EQ(m.node_sets.at("BLOCK-1.BASE"), (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(m.node_sets.at("BASE"), (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(m.element_sets.at("BLOCK-1.BASE"), (std::vector<int>{0}));
  EXPECT_EQ(m.element_sets.at("BASE"), (std::vector<int>{0}));
  EXPECT_EQ(m.node_sets.at("ALL"), (std::vector<int>{0, 1, 2, 3, 4}));
  EXPECT_EQ(m.element_sets.at("BLOCK-1.ALL"), (std::vector<int>{0, 1}));
  EXPECT_EQ(m.node_sets.at("FIXED"), (std::vector<int>{0, 2}));
  EXPECT_EQ(m.node_sets.at("TIP"), (std::vector<int>{3, 4}));
  EXPECT_EQ(m.element_sets.at("BOTH"), (std::vector<int>{0, 1}));
  std::vector<std::string> names;
  for (const auto& [name, v] : m.element_sets) names.push_back(name);
  EXPECT_EQ(names, (std::vector<std::string>{"ALL", "BASE", "BLOCK-1.ALL", "BLOCK-1.BASE", "BOTH"}));
  EXPECT_EQ(m.node_sets.size(), 6u);  // ALL, BASE, BLOCK-1.ALL, BLOCK-1.BASE, FIXED, TIP

  // Element-based surfaces: "_Cavity_S3, S3" = face S3 of element 2 (index 1, local face 2).
  EXPECT_EQ(m.surfaces.at("CAVITY"), (std::vector<FaceRef>{{1, 2}, {0, 0}}));
  EXPECT_EQ(m.surfaces.at("BLOCK-1.INNER"), (std::vector<FaceRef>{{1, 1}}));
  EXPECT_EQ(m.surfaces.at("INNER"), (std::vector<FaceRef>{{1, 1}}));
  EXPECT_EQ(m.surfaces.at("OUTER"), (std::vector<FaceRef>{{1, 1}}));  // a surface made of another
  EXPECT_EQ(m.surfaces.size(), 4u);

  // *DSLOAD Cavity, P and Inner, P (bare: the one instance's) are the pressure faces.
  ASSERT_EQ(d.pressure_faces.size(), 3u);
  EXPECT_EQ(d.pressure_faces[0].face, (FaceRef{1, 2}));
  EXPECT_EQ(d.pressure_faces[1].face, (FaceRef{0, 0}));
  EXPECT_EQ(d.pressure_faces[2].face, (FaceRef{1, 1}));
  EXPECT_EQ(d.pressure_faces[2].magnitude, 0.05);
  const std::vector<std::pair<int, int>> fixed = {{0, 0}, {0, 1}, {0, 2}, {2, 0}, {2, 1}, {2, 2}};
  EXPECT_EQ(d.fixed_dofs, fixed);

  // What CAE writes besides is skipped with a note, not refused.
  EXPECT_EQ(count_containing(d.warnings, "C3D4H is read as C3D4"), 1);
  for (const char* kw : {"*PREPRINT skipped", "*AMPLITUDE skipped", "*STEP skipped", "*STATIC skipped",
                         "*RESTART skipped", "*OUTPUT skipped", "*END STEP skipped"})
    EXPECT_EQ(count_containing(d.warnings, kw), 1) << kw;
  // The material and section lines are a scene's (scenes/inp/materials.h): no note that they are skipped.
  for (const char* kw : {"*SOLID SECTION skipped", "*MATERIAL skipped", "*HYPERELASTIC skipped", "*DENSITY skipped"})
    EXPECT_EQ(count_containing(d.warnings, kw), 0) << kw;
  EXPECT_EQ(count_containing(d.warnings, "volume"), 0);
  EXPECT_EQ(count_containing(d.warnings, "belong to no element"), 0);
  EXPECT_EQ(count_containing(d.warnings, "instances"), 0);
}

TEST(InpAssembly, PlacementIsInTheDecksLengthUnit) {
  // In mm the translation and the axis points are scaled like the nodes: the same placement to
  // a few ulps of the 1e-2 m coordinates.
  const Mesh mm = read_inp(data_path("cae_block.inp"), 1e-3).mesh;
  const Mesh m = read_inp(data_path("cae_block.inp"), 1.0).mesh;
  for (int n = 0; n < 5; ++n)
    for (int k = 0; k < 3; ++k)
      EXPECT_NEAR(mm.X[static_cast<std::size_t>(n)][k], 1e-3 * m.X[static_cast<std::size_t>(n)][k], 1e-17)
          << "node " << n + 1 << " axis " << k;
}

TEST(InpAssembly, QuarterTurnsAreExactAndTheGeneralRotationIsRightHanded) {
  const Eigen::Vector3d z(0, 0, 1), x(1, 0, 0);
  Eigen::Matrix3d Rz90;
  Rz90 << 0, -1, 0, 1, 0, 0, 0, 0, 1;
  EXPECT_EQ(inp::rotation_deg(z, 90.0), Rz90);
  EXPECT_EQ(inp::rotation_deg(z, -270.0), Rz90);
  EXPECT_EQ(inp::rotation_deg(z, 450.0), Rz90);
  EXPECT_EQ(inp::rotation_deg(z, 180.0) * x, Eigen::Vector3d(-1, 0, 0));
  // 30 degrees about x: y -> (0, cos, sin); to round-off of cos and sin (1e-16).
  const Eigen::Vector3d y30 = inp::rotation_deg(x, 30.0) * Eigen::Vector3d(0, 1, 0);
  EXPECT_NEAR(y30.y(), std::sqrt(3.0) / 2.0, 1e-15);
  EXPECT_NEAR(y30.z(), 0.5, 1e-15);
  EXPECT_EQ(y30.x(), 0.0);
}

// -------------------------------------------------------------------------------------------
// Two instances of one part
// -------------------------------------------------------------------------------------------

const std::string kPart =
    "*Part, name=Block\n*Node\n1, 0, 0, 0\n2, 10, 0, 0\n3, 0, 10, 0\n4, 0, 0, 10\n5, 10, 10, 10\n"
    "*Element, type=C3D4H\n1, 1, 2, 3, 4\n2, 2, 3, 4, 5\n*Nset, nset=Base\n1, 2, 3\n"
    "*Elset, elset=All, generate\n1, 2, 1\n*Elset, elset=_Inner_S2, internal\n2,\n"
    "*Surface, type=ELEMENT, name=Inner\n_Inner_S2, S2\n*End Part\n";

/// kPart twice: A-1 translated by (100, 0, 0) mm, A-2 turned 30 degrees about the x axis.
const std::string kTwo = kPart +
                         "*Assembly, name=Assembly\n"
                         "*Instance, name=A-1, part=Block\n100, 0, 0\n*End Instance\n"
                         "*Instance, name=A-2, part=Block\n0, 0, 0\n0, 0, 0, 1, 0, 0, 30\n*End Instance\n"
                         "*Nset, nset=Tip\nA-1.5, A-2.5\n"
                         "*End Assembly\n"
                         "*Step\n*Static\n*Dsload\nA-2.Inner, P, 0.01\n*End Step\n";

TEST_F(InpAssemblyFiles, TwoInstancesAreNumberedApartAndNamedByInstance) {
  const InpDeck d = read_inp(write("two.inp", kTwo), 1e-3);
  const Mesh& m = d.mesh;
  ASSERT_EQ(m.num_nodes(), 10);
  ASSERT_EQ(m.num_elements(), 4);
  // A-2 after A-1; its ids offset by A-1's largest, so the mesh's ids are distinct.
  EXPECT_EQ(m.node_ids, (std::vector<long>{1, 2, 3, 4, 5, 6, 7, 8, 9, 10}));
  EXPECT_EQ(m.element_ids, (std::vector<long>{1, 2, 3, 4}));
  ASSERT_EQ(m.id_scopes.size(), 3u);  // the assembly level, A-1, A-2
  EXPECT_EQ(m.id_scopes[2].name, "A-2");
  EXPECT_EQ(m.node_name(7), "A-2.3");
  EXPECT_EQ(m.node_name(1), "A-1.2");
  EXPECT_EQ(m.element_label(3), "element A-2.2 (region 'default')");
  EXPECT_EQ(m.element_name(0), "A-1.1");
  // Each instance placed on its own: A-1 node 2 at (110, 0, 0) mm, A-2 node 5 turned about x.
  EXPECT_NEAR(m.X[1].x(), 0.110, 1e-17);
  const double c = std::cos(std::numbers::pi / 6.0), s = std::sin(std::numbers::pi / 6.0);
  const Eigen::Vector3d a2n5 = 1e-3 * Eigen::Vector3d(10.0, 10.0 * c - 10.0 * s, 10.0 * s + 10.0 * c);
  EXPECT_NEAR((m.X[9] - a2n5).norm(), 0.0, 1e-17);  // a few ulps of 1e-2 m
  EXPECT_EQ(m.X[5], Eigen::Vector3d::Zero());       // A-2 node 1 on the axis

  // Part names qualified per instance; a bare name two instances define is not stored.
  EXPECT_EQ(m.node_sets.at("A-1.BASE"), (std::vector<int>{0, 1, 2}));
  EXPECT_EQ(m.node_sets.at("A-2.BASE"), (std::vector<int>{5, 6, 7}));
  EXPECT_EQ(m.element_sets.at("A-2.ALL"), (std::vector<int>{2, 3}));
  EXPECT_EQ(m.node_sets.count("BASE"), 0u);
  EXPECT_EQ(inp::qualified_choices(m.node_sets, "BASE"), (std::vector<std::string>{"A-1.BASE", "A-2.BASE"}));
  EXPECT_EQ(m.node_sets.at("TIP"), (std::vector<int>{4, 9}));
  EXPECT_EQ(m.surfaces.at("A-2.INNER"), (std::vector<FaceRef>{{3, 1}}));
  EXPECT_EQ(m.surfaces.count("INNER"), 0u);
  EXPECT_EQ(m.element_sets.count("A-1._INNER_S2"), 0u);
  ASSERT_EQ(d.pressure_faces.size(), 1u);
  EXPECT_EQ(d.pressure_faces[0].face, (FaceRef{3, 1}));

  // Solid instances share no node: said, with the fix.
  EXPECT_EQ(d.solid_instances, (std::vector<std::string>{"A-1", "A-2"}));
  EXPECT_EQ(count_containing(d.warnings, "instances (A-1 and A-2) that share no node"), 1);
  EXPECT_EQ(count_containing(d.warnings, "merge the instances in Abaqus (Merge/Cut Instances)"), 1);

  // The distinct ids make a valid flat deck: it reads back to the same mesh.
  std::ostringstream os;
  write_inp_mesh(os, m, 1e-3);
  const Mesh back = read_inp(write("flat.inp", os.str()), 1e-3).mesh;
  EXPECT_EQ(back.node_ids, m.node_ids);
  EXPECT_EQ(back.conn, m.conn);
  EXPECT_EQ(back.node_sets.at("A-2.BASE"), m.node_sets.at("A-2.BASE"));
}

TEST_F(InpAssemblyFiles, MessagesNameEntitiesByInstance) {
  // A repeated load with another magnitude names the face's element as the assembly knows it.
  const InpDeck d = read_inp(write("two.inp", kTwo + "*Dsload\nA-2.Inner, P, 0.02\n"), 1e-3);
  EXPECT_EQ(count_containing(d.warnings, "element A-2.2 face S2 loaded again with 0.02"), 1);
  expect_error(kTwo + "*Dload\nA-2.7, P1, 0.01\n", "A-2.7, P1", {"element A-2.7 in *DLOAD is not defined"});
  // A bare id at the assembly level is an assembly-level node: the message says how to name A-1's.
  expect_error(kTwo + "*Boundary\n3, 1, 3\n", "\n3, 1, 3\n",
               {"node 3 in *BOUNDARY is not defined", "write <instance>.3 (e.g. A-1.3)"});
  // An error in the part's lines names the instance being read.
  std::string bad = kTwo;
  bad.replace(bad.find("2, 2, 3, 4, 5"), 13, "2, 2, 3, 4, 9");
  expect_error(bad, "2, 2, 3, 4, 9", {"part 'Block' (instance 'A-1'): element 2 refers to node 9"});
  // build_model refuses two solid instances, with the fix.
  const std::string scene = write("two.toml", "[mesh]\nsource = \"inp\"\nfile = \"two.inp\"\n");
  try {
    build_model(Scene::load(scene));
    ADD_FAILURE() << "a deck of two unconnected instances was accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("mesh.file"), std::string::npos) << what;
    EXPECT_NE(what.find("2 instances (A-1 and A-2) that share no node"), std::string::npos) << what;
    EXPECT_NE(what.find("merge the instances in Abaqus (Merge/Cut Instances) so the mesh is conforming"),
              std::string::npos) << what;
  }
}

TEST_F(InpAssemblyFiles, AmbiguousBareNamesAreRejectedWithTheChoices) {
  expect_error(kTwo + "*Boundary\nBase, ENCASTRE\n", "Base, ENCASTRE",
               {"node set 'Base' in *BOUNDARY is ambiguous: instances A-1 and A-2 each define one",
                "name one with its instance: A-1.Base or A-2.Base"});
  expect_error(kTwo + "*Dsload\nInner, P, 0.01\n", "\nInner, P, 0.01",
               {"surface 'Inner' in *DSLOAD is ambiguous", "A-1.Inner or A-2.Inner"});
  // Qualified, or defined at the assembly level (which a bare name means first), it is fine.
  const InpDeck d =
      read_inp(write("ok.inp", kTwo + "*Boundary\nA-2.Base, ENCASTRE\n"), 1e-3);
  EXPECT_EQ(d.fixed_dofs.front(), (std::pair<int, int>{5, 0}));
  std::string with_own = kTwo;
  with_own.insert(with_own.find("*End Assembly"), "*Nset, nset=Base, instance=A-2\n4\n");
  EXPECT_EQ(read_inp(write("own.inp", with_own), 1e-3).mesh.node_sets.at("BASE"), (std::vector<int>{8}));

  // The scene's keys resolve the same names: a part with only a reference point (no elements, so
  // one solid instance) that also has a set Base makes mesh.fixed_set = "Base" ambiguous.
  const std::string deck = kPart + "*Part, name=Marker\n*Node\n1, 0, 0, 20\n*Nset, nset=Base\n1\n*End Part\n"
                           "*Assembly, name=Assembly\n*Instance, name=Block-1, part=Block\n*End Instance\n"
                           "*Instance, name=Marker-1, part=Marker\n*End Instance\n*End Assembly\n";
  write("rp.inp", deck);
  const std::string scene = write("rp.toml",
                                  "[mesh]\nsource = \"inp\"\nfile = \"rp.inp\"\nfixed_set = \"Base\"\n"
                                  "[[parts]]\nelset = \"All\"\nmaterial = \"silicone\"\n");
  try {
    build_model(Scene::load(scene));
    ADD_FAILURE() << "an ambiguous fixed_set was accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("mesh.fixed_set"), std::string::npos) << what;
    EXPECT_NE(what.find("node set 'Base' is defined by 2 instances of the deck; name one with its instance: "
                        "BLOCK-1.BASE or MARKER-1.BASE"),
              std::string::npos) << what;
  }
}

// -------------------------------------------------------------------------------------------
// The built-in actuator as a CAE deck bends as its flat deck does
// -------------------------------------------------------------------------------------------

/// `mesh` as Abaqus/CAE lays a model out: part Actuator (nodes moved by -shift_mm, elements as
/// C3D10H per region, the element sets and SYMMETRY), one instance translated back by shift_mm,
/// FIXED and TIP as assembly sets with INSTANCE=, the cavity as an assembly surface on INTERNAL
/// element sets per face number, loaded by *DSLOAD; materials and a step as CAE writes them.
std::string cae_deck(const Mesh& mesh, const Eigen::Vector3d& shift_mm) {
  std::ostringstream os;
  os.precision(17);
  auto ids = [&](const std::vector<int>& indices, const std::vector<long>& of) {
    for (std::size_t i = 0; i < indices.size(); ++i)
      os << of[static_cast<std::size_t>(indices[i])] << ((i + 1) % 16 == 0 || i + 1 == indices.size() ? "\n" : ", ");
  };
  os << "*Heading\n** Job name: Actuator Model name: Model-1\n** Generated by: Abaqus/CAE 2021\n"
        "*Preprint, echo=NO, model=NO, history=NO, contact=NO\n**\n** PARTS\n**\n*Part, name=Actuator\n*Node\n";
  for (int n = 0; n < mesh.num_nodes(); ++n) {
    const Eigen::Vector3d x = mesh.X[static_cast<std::size_t>(n)] / 1e-3 - shift_mm;
    os << mesh.node_ids[static_cast<std::size_t>(n)] << ", " << x.x() << ", " << x.y() << ", " << x.z() << "\n";
  }
  for (int e = 0; e < mesh.num_elements(); ++e) {
    if (e == 0 || mesh.region[static_cast<std::size_t>(e)] != mesh.region[static_cast<std::size_t>(e) - 1])
      os << "*Element, type=C3D10H, elset=" << mesh.region_names[mesh.region[static_cast<std::size_t>(e)]] << "\n";
    os << mesh.element_ids[static_cast<std::size_t>(e)];
    for (int k = 0; k < mesh.npe(); ++k)
      os << (k == 8 ? ",\n" : ", ") << mesh.node_ids[static_cast<std::size_t>(mesh.element(e)[k])];
    os << "\n";
  }
  os << "*Nset, nset=Symmetry\n";
  ids(mesh.node_sets.at("SYMMETRY"), mesh.node_ids);
  for (const auto& [name, elements] : mesh.element_sets) {
    os << "*Elset, elset=" << name << "\n";
    ids(elements, mesh.element_ids);
  }
  os << "** Section: Silicone\n*Solid Section, elset=SILICONE, material=Ecoflex\n,\n*End Part\n"
        "**\n** ASSEMBLY\n**\n*Assembly, name=Assembly\n**\n*Instance, name=Actuator-1, part=Actuator\n"
     << shift_mm.x() << ", " << shift_mm.y() << ", " << shift_mm.z() << "\n*End Instance\n**\n";
  os << "*Nset, nset=Fixed, instance=Actuator-1\n";
  ids(mesh.node_sets.at("FIXED"), mesh.node_ids);
  os << "*Nset, nset=Tip, instance=Actuator-1\n";
  ids(mesh.node_sets.at("TIP"), mesh.node_ids);
  std::vector<int> by_face[4];
  for (const FaceRef& f : mesh.surfaces.at("CAVITY")) by_face[f.local_face].push_back(f.element);
  for (int f = 0; f < 4; ++f) {
    std::sort(by_face[f].begin(), by_face[f].end());
    os << "*Elset, elset=_Cavity_S" << f + 1 << ", internal, instance=Actuator-1\n";
    ids(by_face[f], mesh.element_ids);
  }
  os << "*Surface, type=ELEMENT, name=Cavity\n";
  for (int f = 0; f < 4; ++f) os << "_Cavity_S" << f + 1 << ", S" << f + 1 << "\n";
  os << "*End Assembly\n**\n** MATERIALS\n**\n*Material, name=Ecoflex\n*Hyperelastic, yeoh\n 0.019, 0.0009, -4.75e-6\n"
        "*Step, name=Inflate, nlgeom=YES\n*Static\n0.1, 1., 1e-05, 0.1\n*Boundary\nFixed, ENCASTRE\n"
        "*Dsload\nCavity, P, 0.005\n*Output, field, variable=PRESELECT\n*End Step\n";
  return os.str();
}

TEST_F(InpAssemblyFiles, TheBuiltInActuatorAsACaeDeckBendsAsItsFlatDeck) {
  const Mesh mesh = build_mesh(Scene::load("", {"geometry.chambers=2", "mesh.h_mm=6.0"}));
  std::ostringstream flat;
  write_inp_mesh(flat, mesh, 1e-3);
  write("flat.inp", flat.str());
  // x stays 0 on the symmetry plane; y and z move by amounts that are not exact in binary.
  write("cae.inp", cae_deck(mesh, Eigen::Vector3d(0.0, 12.3, -4.7)));

  const std::string flat_scene = write("flat.toml",
                                       "[mesh]\nsource = \"inp\"\nfile = \"flat.inp\"\nsymmetry_set = \"SYMMETRY\"\n"
                                       "[load]\nmax_kPa = 5.0\n");
  // The CAE scene names sets in both forms: bare part names (Symmetry, fabric), qualified ones
  // (Actuator-1.SILICONE, and Actuator-1.FABRIC as a region: a tag of scale 1, which changes
  // nothing but must be found), assembly sets (Fixed, Tip), and the *DSLOAD faces as the cavity.
  const std::string cae_scene = write("cae.toml",
                                      "[mesh]\nsource = \"inp\"\nfile = \"cae.inp\"\nsymmetry_set = \"Symmetry\"\n"
                                      "fixed_set = \"Fixed\"\ntip_set = \"Tip\"\ncavity_surface = \"DLOAD\"\n"
                                      "regions = { \"Actuator-1.FABRIC\" = \"layer\" }\n"
                                      "[regions.layer]\nstiffness_scale = 1.0\n"
                                      "[load]\nmax_kPa = 5.0\n"
                                      "[[parts]]\nelset = \"Actuator-1.SILICONE\"\nmaterial = \"silicone\"\n"
                                      "[[parts]]\nelset = \"fabric\"\nmaterial = \"fabric\"\n");
  // The instance puts every node back where the flat deck has it, to the round-off of
  // x - shift + shift (the angle alone would not see a rigid misplacement).
  const Mesh flat_mesh = build_mesh(Scene::load(flat_scene)), cae_mesh = build_mesh(Scene::load(cae_scene));
  ASSERT_EQ(cae_mesh.num_nodes(), flat_mesh.num_nodes());
  EXPECT_EQ(cae_mesh.conn, flat_mesh.conn);
  EXPECT_EQ(cae_mesh.node_ids, flat_mesh.node_ids);
  double max_dx = 0.0;
  for (int n = 0; n < flat_mesh.num_nodes(); ++n)
    max_dx = std::max(max_dx, (cae_mesh.X[static_cast<std::size_t>(n)] - flat_mesh.X[static_cast<std::size_t>(n)]).norm());
  EXPECT_LT(max_dx, 1e-16);  // a few ulps of the ~0.1 m coordinates

  {
    const auto bm = build_model(Scene::load(cae_scene));
    const int layer = bm->model.mesh.find_region("layer");
    ASSERT_GE(layer, 0);
    EXPECT_EQ(std::count(bm->model.mesh.region.begin(), bm->model.mesh.region.end(), layer),
              static_cast<long>(mesh.element_sets.at("FABRIC").size()));
    EXPECT_EQ(bm->model.parts[0].name, "Actuator-1.SILICONE");
  }

  auto angle = [](const std::string& scene, std::vector<std::string>* warnings) {
    auto bm = build_model(Scene::load(scene));
    if (warnings) *warnings = bm->warnings;
    const Assembler asmb(bm->model);
    QuasiStaticRun run(asmb, bm->solver.quasi_static);
    double last = 0.0;
    run.run(bm->load, [&](const StateRecord& r, const Eigen::VectorXd&, const std::vector<double>&) { last = r.angle_deg; });
    return std::pair(last, bm->model.pressure_faces.size());
  };
  std::vector<std::string> warnings;
  const auto [angle_flat, faces_flat] = angle(flat_scene, nullptr);
  const auto [angle_cae, faces_cae] = angle(cae_scene, &warnings);
  EXPECT_EQ(faces_cae, faces_flat);
  EXPECT_EQ(faces_cae, mesh.surfaces.at("CAVITY").size());
  EXPECT_GT(angle_flat, 0.05);
  // Same nodes, elements, faces and materials in the same order, so both runs take the same load
  // increments and Newton iterations; they differ only by the coordinates' round-off (above) and
  // the order in which the cavity faces are summed (grouped by face number here), i.e. by
  // round-off amplified by the conditioning of the equilibria: observed ~3e-15 relative. 1e-10
  // leaves that margin; a missing or extra cavity face, or a wrong fixed or tip node, changes the
  // angle by far more.
  EXPECT_NEAR(angle_cae, angle_flat, 1e-10 * angle_flat);
  EXPECT_EQ(count_containing(warnings, "C3D10H is read as C3D10"), 1);
  EXPECT_EQ(count_containing(warnings, "instances"), 0);
}

// -------------------------------------------------------------------------------------------
// What a CAE deck may hold beyond the reader: said, with what to do
// -------------------------------------------------------------------------------------------

const std::string kAsm = "*Assembly, name=Assembly\n*Instance, name=B-1, part=Block\n";

TEST_F(InpAssemblyFiles, StructureErrors) {
  expect_error(kPart + "*Assembly, name=Assembly\n*Instance, name=X-1, part=Nope\n*End Instance\n*End Assembly\n",
               "part=Nope", {"refers to part 'Nope', which is not defined above", "define *Part, name=Nope"});
  expect_error(kPart + "*Instance, name=B-1, part=Block\n*End Instance\n", "*Instance",
               {"*Instance outside *Assembly", "put the instances between *Assembly"});
  expect_error("*Heading\n" + kPart.substr(0, kPart.find("*End Part")), "*Part, name=Block",
               {"*Part 'Block' has no *End Part", "close the part with *End Part"});
  expect_error(kPart.substr(0, kPart.find("*End Part")) + kAsm, "*Assembly",
               {"*ASSEMBLY inside *Part 'Block'", "close the part with *End Part first"});
  expect_error(kPart + kAsm + "*End Assembly\n", "*End Assembly",
               {"*End Assembly inside *Instance 'B-1'", "close the instance with *End Instance first"});
  expect_error(kPart + kAsm + "*End Instance\n", "*Assembly", {"*Assembly has no *End Assembly", "*End Assembly"});
  expect_error(kPart + kAsm, "*Instance", {"*Instance 'B-1' has no *End Instance", "close it with *End Instance"});
  expect_error(kPart + "*End Instance\n", "*End Instance", {"*End Instance without *Instance", "remove it"});
  expect_error(kPart + kAsm + "*End Instance\n*Instance, name=b-1, part=Block\n*End Instance\n*End Assembly\n",
               "name=b-1", {"instance 'b-1' is defined twice", "rename one"});
  expect_error(kPart + "*Assembly\n*Instance, name=B.1, part=Block\n*End Instance\n*End Assembly\n", "B.1",
               {"contains a '.'", "rename the instance"});
  expect_error(kPart + "*Assembly\n*Instance, instance=B-1, library=old\n*End Instance\n*End Assembly\n",
               "library=old", {"imported from a previous analysis", "instance it with PART="});
  expect_error(kPart, "*Part", {"part 'Block' is defined but never instanced", "*Instance, name=Block-1, part=Block"});
  EXPECT_NE(error_of(kPart + kPart).find("bad.inp:" + std::to_string(line_of(kPart, "*End Part") + 1) +
                                         ": part 'Block' is defined twice"),
            std::string::npos)
      << error_of(kPart + kPart);
}

TEST_F(InpAssemblyFiles, PlacementErrors) {
  const std::string end = "*End Instance\n*End Assembly\n";
  expect_error(kPart + kAsm + "1, 2\n" + end, "\n1, 2\n", {"translation line of *Instance 'B-1' has 2 values", "'dx, dy, dz'"});
  expect_error(kPart + kAsm + "0, 0, 0\n0, 0, 0, 0, 0, 1\n" + end, "0, 0, 0, 0, 0, 1",
               {"rotation line of *Instance 'B-1' has 6 values", "'xa, ya, za, xb, yb, zb, angle_deg'"});
  expect_error(kPart + kAsm + "0, 0, 0\n1, 1, 1, 1, 1, 1, 45\n" + end, "1, 1, 1, 1, 1, 1, 45",
               {"rotation axis has two equal points", "two distinct points"});
  expect_error(kPart + kAsm + "0, 0, 0\n0, 0, 0, 0, 0, 1, 45\n1, 1, 1\n" + end, "\n1, 1, 1\n",
               {"has a third data line", "7 numbers"});
  expect_error(kPart + kAsm + "0, x, 0\n" + end, "0, x, 0", {"'x' is not a finite number"});
}

TEST_F(InpAssemblyFiles, SetAndLoadErrors) {
  const std::string two = kPart + kAsm + "*End Instance\n";
  expect_error(two + "*Nset, nset=F, instance=Nope\n1\n*End Assembly\n", "instance=Nope",
               {"INSTANCE=Nope: no such instance above", "use one of B-1"});
  expect_error(two + "*Nset, nset=F, instance=B-1\n6\n*End Assembly\n", "\n6\n",
               {"node B-1.6 in set F is not defined", "remove it from the set"});
  expect_error(two + "*End Assembly\n*Dsload\nNope, P, 0.01\n", "Nope, P",
               {"unknown surface 'Nope' in *DSLOAD", "define it with *SURFACE, TYPE=ELEMENT",
                "<instance>.<surface>"});
  expect_error(two + "*End Assembly\n*Dsload\nB-1.Inner, P\n", "B-1.Inner, P", {"*DSLOAD P without a magnitude"});
  expect_error(two + "*End Assembly\n*Boundary\nNope, 1, 3\n", "Nope, 1, 3",
               {"unknown node set 'Nope' in *BOUNDARY", "an instance's set is <instance>.<set> here"});
  // Other distributed loads and ties are skipped with a note; a tie's note says to merge.
  const InpDeck d = read_inp(write("tie.inp", two + "*Surface, type=ELEMENT, name=Top\nB-1._Inner_S2, S2\n"
                                                   "*Tie, name=Glue, adjust=yes\nTop, B-1.Inner\n*End Assembly\n"
                                                   "*Dsload\nTop, TRVEC, 0.1, 1, 0, 0\nTop, P, 0.01\n"),
                             1e-3);
  EXPECT_EQ(count_containing(d.warnings, "*TIE Glue ignored"), 1);
  EXPECT_EQ(count_containing(d.warnings, "merge the instances in Abaqus (Merge/Cut Instances) so the mesh is conforming"), 1);
  EXPECT_EQ(count_containing(d.warnings, "*DSLOAD load type TRVEC skipped"), 1);
  ASSERT_EQ(d.pressure_faces.size(), 1u);
  EXPECT_EQ(d.pressure_faces[0].face, (FaceRef{1, 1}));
  // An internal part set is reachable while reading (qualified), never stored.
  EXPECT_EQ(d.mesh.element_sets.count("B-1._INNER_S2"), 0u);
}

/// Every mutilation of the CAE deck (a line dropped, halved, extended or replaced by junk, which
/// unbalances *PART / *INSTANCE / *ASSEMBLY blocks and placement lines) reads or throws
/// InputError: no crash, no other exception.
TEST_F(InpAssemblyFiles, MutilatedCaeDecksNeverCrash) {
  std::ifstream in(data_path("cae_block.inp"));
  std::vector<std::string> lines;
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  ASSERT_GT(lines.size(), 50u);
  const std::vector<std::string> junk = {"", ",", "x", "*", "*End Part", "*End Instance", "*Instance, name=Z, part=Block",
                                         "*End Assembly", "Block-1.", ".1", "Block-1.99", "1e999", "0, 0, 0, 0, 0, 0, 90"};
  int accepted = 0, rejected = 0;
  auto attempt = [&](const std::string& text) {
    try {
      read_inp(write("g.inp", text), 1.0);
      ++accepted;
    } catch (const InputError&) {
      ++rejected;
    }
  };
  test::for_each_mutilation(lines, junk, attempt);
  EXPECT_GT(accepted, 0);
  EXPECT_GT(rejected, 0);
}

TEST_F(InpAssemblyFiles, HybridAndModifiedTetrahedraAreReadAsPlainOnes) {
  for (const char* type : {"C3D10H", "C3D10HS", "C3D10M", "C3D10MH", "C3D10I"}) {
    const std::string deck = "*Node\n1,0,0,0\n2,1,0,0\n3,0,1,0\n4,0,0,1\n5,.5,0,0\n6,.5,.5,0\n7,0,.5,0\n8,0,0,.5\n"
                             "9,.5,0,.5\n10,0,.5,.5\n*Element, type=" + std::string(type) + "\n1,1,2,3,4,5,6,7,8,9,10\n";
    const InpDeck d = read_inp(write("t.inp", deck), 1.0);
    EXPECT_EQ(d.mesh.type, ElementType::Tet10) << type;
    EXPECT_EQ(count_containing(d.warnings, std::string(type) + " is read as C3D10"), 1) << type;
  }
}

}  // namespace
}  // namespace pneufem
