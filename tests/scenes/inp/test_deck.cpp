// Abaqus/CalculiX deck reader and writer (scenes/inp/deck.h): hand-written decks, round trips through
// write_inp_mesh, and one test per class of user error asserting file, line and hint.
#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include <algorithm>
#include <array>
#include <cctype>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include "core/errors.h"
#include "damage/viscoelastic.h"
#include "engine/assembly.h"
#include "engine/quasi_static.h"
#include "scenes/build_model.h"
#include "scenes/inp/deck.h"

namespace pneufem {
namespace {

namespace fs = std::filesystem;

std::string data_path(const std::string& name) { return std::string(PNEUFEM_TEST_DATA_DIR) + "/inp/" + name; }

/// External ids of a sorted index list.
std::vector<long> ids_of(const std::vector<int>& indices, const std::vector<long>& ids) {
  std::vector<long> out;
  for (int i : indices) out.push_back(ids[static_cast<std::size_t>(i)]);
  return out;
}

/// External node ids of element e.
std::vector<long> element_node_ids(const Mesh& m, int e) {
  std::vector<long> out;
  for (int k = 0; k < m.npe(); ++k) out.push_back(m.node_ids[static_cast<std::size_t>(m.element(e)[k])]);
  return out;
}

std::string upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

std::string region_of(const Mesh& m, int e) { return m.region_names[m.region[static_cast<std::size_t>(e)]]; }

int count_containing(const std::vector<std::string>& lines, const std::string& needle) {
  return static_cast<int>(std::count_if(lines.begin(), lines.end(),
                                        [&](const std::string& l) { return l.find(needle) != std::string::npos; }));
}

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

/// A fresh directory per test, removed afterwards.
class InpFiles : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    dir_ = fs::path(::testing::TempDir()) / ("pneufem_inp_" + std::string(info->test_suite_name()) + "_" +
                                             info->name() + "_" + std::to_string(std::random_device{}()));
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }
  std::string write(const std::string& name, const std::string& text) const {
    const fs::path p = dir_ / name;
    fs::create_directories(p.parent_path());
    std::ofstream(p, std::ios::binary) << text;
    return p.string();
  }
  /// Reads `text` as bad.inp and returns the InputError message ("" if none was thrown).
  std::string error_of(const std::string& text, const std::string& name = "bad.inp") const {
    try {
      read_inp(write(name, text), 1e-3);
    } catch (const InputError& e) {
      return e.what();
    }
    return "";
  }
  /// The message must name the file and line and contain every hint.
  void expect_error(const std::string& text, int line, const std::vector<std::string>& hints) const {
    const std::string msg = error_of(text);
    ASSERT_FALSE(msg.empty()) << "no InputError for:\n" << text;
    EXPECT_NE(msg.find("bad.inp:" + std::to_string(line) + ": "), std::string::npos) << msg;
    for (const std::string& h : hints) EXPECT_NE(msg.find(h), std::string::npos) << "missing '" << h << "' in: " << msg;
  }
  fs::path dir_;
};

// -------------------------------------------------------------------------------------------
// Reading hand-written decks
// -------------------------------------------------------------------------------------------

TEST(InpRead, Tet4DeckInCentimetres) {
  const InpDeck d = read_inp(data_path("tet4_two.inp"), 0.01);
  const Mesh& m = d.mesh;
  EXPECT_EQ(m.type, ElementType::Tet4);
  ASSERT_EQ(m.num_nodes(), 5);
  ASSERT_EQ(m.num_elements(), 2);
  EXPECT_EQ(m.node_ids, (std::vector<long>{10, 20, 30, 40, 50}));
  EXPECT_EQ(m.element_ids, (std::vector<long>{100, 200}));
  EXPECT_DOUBLE_EQ(m.X[1].x(), 0.02);  // 2 cm
  EXPECT_DOUBLE_EQ(m.X[4].z(), 0.02);
  EXPECT_EQ(m.X[0], Eigen::Vector3d::Zero());
  EXPECT_EQ(element_node_ids(m, 0), (std::vector<long>{10, 20, 30, 40}));
  EXPECT_EQ(element_node_ids(m, 1), (std::vector<long>{20, 30, 40, 50}));
  EXPECT_EQ(region_of(m, 0), "default");  // no ELSET=
  EXPECT_EQ(region_of(m, 1), "default");

  EXPECT_EQ(m.element_sets.at("E_ALL"), (std::vector<int>{0, 1}));
  EXPECT_EQ(ids_of(m.node_sets.at("BOTTOM"), m.node_ids), (std::vector<long>{10, 20, 30}));
  EXPECT_EQ(ids_of(m.node_sets.at("SYM"), m.node_ids), (std::vector<long>{10, 20, 30, 40}));
  EXPECT_EQ(m.surfaces.at("PRESSED"), (std::vector<FaceRef>{{0, 0}, {1, 0}}));

  ASSERT_EQ(d.pressure_faces.size(), 2u);
  EXPECT_EQ(d.pressure_faces[0].face, (FaceRef{0, 1}));
  EXPECT_EQ(d.pressure_faces[1].face, (FaceRef{1, 1}));
  EXPECT_EQ(d.pressure_faces[1].magnitude, 0.005);

  // PINNED on BOTTOM (nodes 0-2), XSYMM on node 40, dof 1 of node 50.
  const std::vector<std::pair<int, int>> fixed = {{0, 0}, {0, 1}, {0, 2}, {1, 0}, {1, 1}, {1, 2},
                                                  {2, 0}, {2, 1}, {2, 2}, {3, 0}, {4, 0}};
  EXPECT_EQ(d.fixed_dofs, fixed);
  EXPECT_EQ(count_containing(d.warnings, "*HEADING skipped"), 1);
}

TEST(InpRead, Tet10DeckWithEveryFeature) {
  const InpDeck d = read_inp(data_path("tet10_two.inp"), 1e-3);
  const Mesh& m = d.mesh;
  EXPECT_EQ(m.type, ElementType::Tet10);
  ASSERT_EQ(m.num_nodes(), 14);
  ASSERT_EQ(m.num_elements(), 2);
  // Node index = order of appearance through both nested includes; ids are not contiguous.
  EXPECT_EQ(m.node_ids, (std::vector<long>{1, 2, 3, 4, 5, 19, 18, 17, 11, 12, 13, 14, 15, 16}));
  EXPECT_EQ(m.element_ids, (std::vector<long>{7, 9}));
  // Coordinates in mm scaled to m: "1.E1", "1.0D1", "+10", tab-separated fields, trailing comma.
  EXPECT_DOUBLE_EQ(m.X[1].x(), 0.01);
  EXPECT_DOUBLE_EQ(m.X[2].y(), 0.01);
  EXPECT_DOUBLE_EQ(m.X[3].z(), 0.01);
  EXPECT_DOUBLE_EQ(m.X[4].x(), 0.01);
  EXPECT_DOUBLE_EQ(m.X[8].y(), 1e-4);  // node 11 at y = 0.1 mm
  EXPECT_DOUBLE_EQ(m.X[5].z(), 0.01);  // node 19
  // Connectivity order preserved across continuation lines (split after 8 and after 4 nodes).
  EXPECT_EQ(element_node_ids(m, 0), (std::vector<long>{1, 2, 3, 4, 11, 12, 13, 14, 15, 16}));
  EXPECT_EQ(element_node_ids(m, 1), (std::vector<long>{2, 3, 4, 5, 12, 16, 15, 17, 18, 19}));
  EXPECT_EQ(region_of(m, 0), "body");
  EXPECT_EQ(region_of(m, 1), "cap");

  // Set names upper-cased; GENERATE, lists over two lines, sets of sets.
  for (const auto& [name, v] : m.node_sets) EXPECT_EQ(name, upper(name));
  for (const auto& [name, v] : m.element_sets) EXPECT_EQ(name, upper(name));
  EXPECT_EQ(ids_of(m.node_sets.at("NALL"), m.node_ids).size(), 14u);  // *NODE, NSET= spans the include
  EXPECT_EQ(ids_of(m.node_sets.at("CORNERS"), m.node_ids), (std::vector<long>{1, 2, 3, 4, 5}));
  std::vector<long> mids = ids_of(m.node_sets.at("MIDS"), m.node_ids);
  std::sort(mids.begin(), mids.end());
  EXPECT_EQ(mids, (std::vector<long>{11, 13, 15, 17, 19}));
  EXPECT_EQ(m.node_sets.at("FIX"), (std::vector<int>{0, 1, 2, 8, 9, 10}));
  EXPECT_EQ(m.node_sets.at("FIXPLUS"), (std::vector<int>{0, 1, 2, 8, 9, 10, 11}));
  EXPECT_EQ(m.element_sets.at("BODY"), (std::vector<int>{0}));
  EXPECT_EQ(m.element_sets.at("CAP"), (std::vector<int>{1}));
  EXPECT_EQ(m.element_sets.at("ALL"), (std::vector<int>{0, 1}));
  EXPECT_EQ(m.element_sets.at("GEN"), (std::vector<int>{0, 1}));

  EXPECT_EQ(m.surfaces.at("CAVITY"), (std::vector<FaceRef>{{0, 2}, {1, 1}}));
  EXPECT_EQ(m.surfaces.count("TIPNODES"), 0u);  // TYPE=NODE: skipped with a warning

  // *DLOAD on an elset in step 1, a repeat with another magnitude and a new face in step 2.
  ASSERT_EQ(d.pressure_faces.size(), 3u);
  EXPECT_EQ(d.pressure_faces[0].face, (FaceRef{0, 0}));
  EXPECT_EQ(d.pressure_faces[0].magnitude, 0.01);  // first magnitude kept
  EXPECT_EQ(d.pressure_faces[1].face, (FaceRef{1, 0}));
  EXPECT_EQ(d.pressure_faces[2].face, (FaceRef{1, 3}));
  EXPECT_EQ(d.pressure_faces[2].magnitude, 0.01);

  // fix,1,3 / 19,ENCASTRE / 5,2,2,0.0 / 4,4,6 (rotations: ignored).
  std::vector<std::pair<int, int>> fixed;
  for (int n : {0, 1, 2, 8, 9, 10, 5})
    for (int k = 0; k < 3; ++k) fixed.emplace_back(n, k);
  fixed.emplace_back(4, 1);
  EXPECT_EQ(d.fixed_dofs, fixed);

  EXPECT_EQ(count_containing(d.warnings, "C3D10H is read as C3D10"), 1);
  EXPECT_EQ(count_containing(d.warnings, "TYPE=NODE"), 1);
  EXPECT_EQ(count_containing(d.warnings, "GRAV skipped"), 1);
  EXPECT_EQ(count_containing(d.warnings, "keeping the first magnitude"), 1);
  EXPECT_EQ(count_containing(d.warnings, "dofs above 3"), 1);
  EXPECT_EQ(count_containing(d.warnings, "*STEP skipped"), 1);  // two *STEP, warned once
  EXPECT_EQ(count_containing(d.warnings, "tet10_two.inp:41: *STEP"), 1);
  EXPECT_EQ(count_containing(d.warnings, "volume"), 0);
  EXPECT_EQ(count_containing(d.warnings, "belong to no element"), 0);
}

TEST_F(InpFiles, WindowsLineEndingsByteOrderMarkAndDataLineQuirks) {
  const std::string deck =
      "\xEF\xBB\xBF*node\r\n1, 0, 0, 0\r\n2,1,,0\r\n3 , 0 , 1 , 0 ,\r\n4,0,0,1\r\n"
      "9, 5, 5, 5\r\n\r\n   ** indented comment\r\n*element,type=c3d4,elset=Solid\r\n"
      "1,1,2,3,4,\r\n*Boundary\r\n1, 1\r\n2, 2,\r\n";
  const InpDeck d = read_inp(write("crlf.inp", deck), 1.0);
  ASSERT_EQ(d.mesh.num_nodes(), 5);
  EXPECT_EQ(d.mesh.X[1], Eigen::Vector3d(1, 0, 0));  // blank field = 0 (Abaqus)
  EXPECT_EQ(d.mesh.X[2], Eigen::Vector3d(0, 1, 0));
  EXPECT_EQ(element_node_ids(d.mesh, 0), (std::vector<long>{1, 2, 3, 4}));
  EXPECT_EQ(region_of(d.mesh, 0), "solid");
  EXPECT_EQ(d.mesh.element_sets.at("SOLID"), (std::vector<int>{0}));
  EXPECT_EQ(d.fixed_dofs, (std::vector<std::pair<int, int>>{{0, 0}, {1, 1}}));
  EXPECT_EQ(count_containing(d.warnings, "1 node(s) belong to no element"), 1);  // node 9
}

TEST_F(InpFiles, GenerateSkipsUndefinedIdsWithAWarning) {
  const InpDeck d = read_inp(write("gen.inp",
                                   "*NODE\n1,0,0,0\n2,1,0,0\n3,0,1,0\n5,0,0,1\n*ELEMENT,TYPE=C3D4\n1,1,2,3,5\n"
                                   "*NSET,NSET=N,GENERATE\n1,5\n*NSET,NSET=HUGE,GENERATE\n2,900000000,3\n"),
                             1.0);
  EXPECT_EQ(ids_of(d.mesh.node_sets.at("N"), d.mesh.node_ids), (std::vector<long>{1, 2, 3, 5}));
  EXPECT_EQ(ids_of(d.mesh.node_sets.at("HUGE"), d.mesh.node_ids), (std::vector<long>{2, 5}));
  EXPECT_EQ(count_containing(d.warnings, "gen.inp:9: GENERATE 1, 5, 1 of N: 1 undefined node id(s) skipped"), 1);
}

// -------------------------------------------------------------------------------------------
// Round trips through write_inp_mesh
// -------------------------------------------------------------------------------------------

/// Everything write_inp_mesh stores must come back (names upper-cased); coordinates to 1e-15
/// relative to max(|x|, L), L = model size: tiny coordinates keep >= 14 digits (20-character field).
void expect_same_mesh(const Mesh& a, const Mesh& b, double L) {
  EXPECT_EQ(a.type, b.type);
  EXPECT_EQ(a.node_ids, b.node_ids);
  EXPECT_EQ(a.element_ids, b.element_ids);
  EXPECT_EQ(a.conn, b.conn);
  ASSERT_EQ(a.num_nodes(), b.num_nodes());
  double worst = 0.0;
  for (int i = 0; i < a.num_nodes(); ++i)
    for (int k = 0; k < 3; ++k) {
      const double x = a.X[static_cast<std::size_t>(i)][k], y = b.X[static_cast<std::size_t>(i)][k];
      worst = std::max(worst, std::abs(x - y) / std::max(std::abs(x), L));
    }
  EXPECT_LE(worst, 1e-15);
  ASSERT_EQ(a.num_elements(), b.num_elements());
  for (int e = 0; e < a.num_elements(); ++e) ASSERT_EQ(region_of(a, e), region_of(b, e)) << "element " << e;
  for (const auto& [name, v] : a.node_sets) EXPECT_EQ(b.node_sets.at(upper(name)), v) << name;
  for (const auto& [name, v] : a.element_sets) EXPECT_EQ(b.element_sets.at(upper(name)), v) << name;
  for (const auto& [name, v] : a.surfaces) EXPECT_EQ(b.surfaces.at(upper(name)), v) << name;
}

/// CalculiX limits: 132 characters and 16 entries per line; a real is read from 20 characters.
void expect_calculix_lines(const std::string& deck) {
  std::istringstream in(deck);
  std::string line, keyword;
  int n = 0;
  while (std::getline(in, line)) {
    ++n;
    ASSERT_LE(line.size(), 132u) << "line " << n;
    if (line.rfind("**", 0) == 0) continue;
    if (line[0] == '*') {
      keyword = line.substr(0, line.find(','));
      continue;
    }
    std::vector<std::string> fields;
    std::stringstream ss(line);
    for (std::string f; std::getline(ss, f, ',');) fields.push_back(f);
    ASSERT_LE(fields.size(), 16u) << "line " << n << ": " << line;
    if (keyword == "*NODE") {
      ASSERT_EQ(fields.size(), 4u) << line;
      for (std::size_t k = 1; k < 4; ++k) {
        const std::size_t first = fields[k].find_first_not_of(' ');
        ASSERT_LE(fields[k].size() - first, 20u) << "line " << n << ": " << line;
      }
    }
  }
}

Mesh round_trip(const Mesh& m, double length_to_m, const fs::path& dir, std::string* text = nullptr) {
  std::ostringstream os;
  write_inp_mesh(os, m, length_to_m);
  if (text) *text = os.str();
  const fs::path p = dir / "round_trip.inp";
  std::ofstream(p) << os.str();
  const InpDeck back = read_inp(p.string(), length_to_m);
  EXPECT_TRUE(back.warnings.empty()) << back.warnings.size() << " warnings, first: " << back.warnings.front();
  return back.mesh;
}

TEST_F(InpFiles, RoundTripOfTheTet10Deck) {
  const Mesh m = read_inp(data_path("tet10_two.inp"), 1e-3).mesh;
  std::string text;
  const Mesh back = round_trip(m, 1e-3, dir_, &text);
  expect_same_mesh(m, back, 0.01);
  // Reading a deck makes every region an element set, so even the set lists match exactly.
  EXPECT_EQ(back.node_sets, m.node_sets);
  EXPECT_EQ(back.element_sets, m.element_sets);
  EXPECT_EQ(back.surfaces, m.surfaces);
  EXPECT_EQ(back.region_names, m.region_names);
  expect_calculix_lines(text);
  EXPECT_NE(text.find("*ELEMENT, TYPE=C3D10, ELSET=CAP\n9, 2, 3, 4, 5, 12, 16, 15, 17,\n18, 19\n"), std::string::npos)
      << text;
}

TEST_F(InpFiles, RoundTripOfTheTet4Deck) {
  const Mesh m = read_inp(data_path("tet4_two.inp"), 0.01).mesh;
  std::string text;
  const Mesh back = round_trip(m, 0.01, dir_, &text);
  expect_same_mesh(m, back, 0.02);
  // The elements had no ELSET=: they are written as ELSET=DEFAULT, which comes back as a set.
  EXPECT_EQ(back.element_sets.size(), 2u);
  EXPECT_EQ(back.element_sets.at("DEFAULT"), (std::vector<int>{0, 1}));
  expect_calculix_lines(text);
}

/// Structured cube of n^3 cells, 6 Kuhn tetrahedra each, promoted to C3D10, with interleaved
/// regions, scattered ids and coordinates that need all 17 digits (some tiny and negative).
Mesh awkward_mesh(int n) {
  Mesh m;
  m.type = ElementType::Tet4;
  const double h = 0.0123456789 / n;
  auto node = [&](int i, int j, int k) { return (i * (n + 1) + j) * (n + 1) + k; };
  for (int i = 0; i <= n; ++i)
    for (int j = 0; j <= n; ++j)
      for (int k = 0; k <= n; ++k) {
        const double wobble = 1e-9 * std::sin(1.0 + node(i, j, k));  // tiny, irrational
        m.X.emplace_back(i * h + wobble - 1e-9 / 3.0, j * h / 3.0 - wobble, k * h * std::numbers::pi + wobble);
      }
  constexpr int kKuhn[6][4] = {{0, 1, 3, 7}, {0, 1, 5, 7}, {0, 2, 3, 7}, {0, 2, 6, 7}, {0, 4, 5, 7}, {0, 4, 6, 7}};
  for (int i = 0; i < n; ++i)
    for (int j = 0; j < n; ++j)
      for (int k = 0; k < n; ++k) {
        int c[8];
        for (int b = 0; b < 8; ++b) c[b] = node(i + (b >> 2 & 1), j + (b >> 1 & 1), k + (b & 1));
        for (const auto& t : kKuhn) {
          std::array<int, 4> tet = {c[t[0]], c[t[1]], c[t[2]], c[t[3]]};
          m.conn.insert(m.conn.end(), tet.begin(), tet.end());
          if (corner_volume(m, m.num_elements() - 1) < 0)
            std::swap(m.conn[m.conn.size() - 1], m.conn[m.conn.size() - 2]);
        }
      }
  for (int i = 0; i < m.num_nodes(); ++i) m.node_ids.push_back(1000 + 7L * i);
  for (int e = 0; e < m.num_elements(); ++e) m.element_ids.push_back(50 + 3L * e);
  const std::uint16_t roof = m.region_id(regions::kRoof), base = m.region_id(regions::kBase);
  m.region_id(regions::kFabric);  // a region without elements is not written
  for (int e = 0; e < m.num_elements(); ++e) m.region.push_back(e % 3 == 1 ? base : roof);
  for (int i = 0; i < m.num_nodes(); ++i)
    if (m.X[static_cast<std::size_t>(i)].x() < 0.5 * h) m.node_sets["fix"].push_back(i);
  for (int e = 0; e < m.num_elements(); e += 5) m.element_sets["every_fifth"].push_back(e);
  m.surfaces["outside"] = boundary_faces(m);
  m.node_sets["empty"];  // declared, no members: must survive too
  m.element_sets["empty_elements"];
  m.surfaces["empty_surface"];
  return promote_to_tet10(m);
}

TEST_F(InpFiles, RoundTripOfAGeneratedTet10MeshKeepsOrderAndPrecision) {
  const Mesh m = awkward_mesh(5);
  ASSERT_EQ(m.num_elements(), 750);
  std::string text;
  const Mesh back = round_trip(m, 1e-3, dir_, &text);
  expect_same_mesh(m, back, 0.0123456789 * std::numbers::pi);
  expect_calculix_lines(text);
  // Interleaved regions are written as runs, so element order and region per element survive.
  EXPECT_GT(std::count(text.begin(), text.end(), '*'), 500);
  EXPECT_EQ(back.region_names, (std::vector<std::string>{"roof", "base"}));
  EXPECT_EQ(back.element_sets.size(), 4u);  // EMPTY_ELEMENTS, EVERY_FIFTH, ROOF, BASE
  EXPECT_TRUE(back.node_sets.at("EMPTY").empty());
  EXPECT_TRUE(back.surfaces.at("EMPTY_SURFACE").empty());
  // Most coordinates come back bit for bit; all of them within the tolerance above.
  int exact = 0;
  for (int i = 0; i < m.num_nodes(); ++i)
    exact += m.X[static_cast<std::size_t>(i)] == back.X[static_cast<std::size_t>(i)];
  EXPECT_GT(exact, m.num_nodes() / 2);
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

// A deck oriented otherwise than the built-in actuator (here along x instead of y). Left at their
// defaults, the angle keys are taken from the mesh (the clamped face's outward normal, the side of the
// stiff layer), with a note each; set by the user, they are checked: a fixed normal in a wrong plane is
// refused with the normal to use, a bend direction pointing away from the fabric (it only flips the
// sign) is a warning.
TEST_F(InpFiles, TheAngleFrameComesFromTheMeshUnlessSetAndIsCheckedWhenSet) {
  Mesh mesh = build_mesh(Scene::load("", {"geometry.chambers=2", "mesh.h_mm=6.0", "mesh.half=false"}));
  for (Eigen::Vector3d& x : mesh.X) x = Eigen::Vector3d(x.y(), -x.x(), x.z());  // y -> x: along x now
  std::ostringstream os;
  write_inp_mesh(os, mesh, 1e-3);
  const std::string path = write("along_x.inp", os.str());
  auto scene = [&](std::vector<std::string> extra) {
    extra.insert(extra.begin(), {"mesh.source=\"inp\"", "mesh.file=\"" + path + "\""});
    return Scene::load("", extra);
  };
  const auto detected = build_model(scene({}));
  EXPECT_NEAR((detected->model.angle.fixed_normal_out - Eigen::Vector3d(-1.0, 0.0, 0.0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((detected->model.angle.bend_direction - Eigen::Vector3d(0.0, 0.0, -1.0)).norm(), 0.0, 1e-12);
  EXPECT_EQ(count_containing(detected->warnings, "angle.fixed_normal taken from the mesh: [-1.000, 0.000, 0.000]"), 1);
  // The default bend direction already points to the fabric: kept, no note.
  EXPECT_EQ(count_containing(detected->warnings, "angle.bend_direction"), 0);
  try {
    build_model(scene({"angle.fixed_normal=[0.0, -1.0, 0.0]"}));  // the built-in's normal, set on purpose
    ADD_FAILURE() << "a fixed normal in a wrong plane was accepted";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("angle.fixed_normal"), std::string::npos) << what;
    EXPECT_NE(what.find("outward normal is [-1.000, 0.000, 0.000]: set angle.fixed_normal = [-1.000, 0.000, 0.000]"),
              std::string::npos) << what;
  }
  const auto ok = build_model(scene({"angle.fixed_normal=[-1.0, 0.0, 0.0]"}));
  EXPECT_EQ(count_containing(ok->warnings, "angle."), 0);
  const auto flipped = build_model(scene({"angle.fixed_normal=[-1.0, 0.0, 0.0]", "angle.bend_direction=[0.0, 0.0, 1.0]"}));
  EXPECT_EQ(count_containing(flipped->warnings, "points away from the inextensible layer"), 1);
  EXPECT_EQ(count_containing(flipped->warnings, "set angle.bend_direction = [0.000, 0.000, -1.000]"), 1);
  // The built-in actuator with its own defaults: neither a note nor a warning.
  EXPECT_EQ(count_containing(build_model(Scene::load("", {"geometry.chambers=2", "mesh.h_mm=6.0"}))->warnings, "angle"), 0);
  // A rig angle hangs the deck in its own frame: phi = 0 along the actuator away from the clamp
  // (+x here), 90 deg towards the fabric (-z); it cannot be combined with a gravity vector.
  auto g_at = [&](const std::string& phi) { return build_model(scene({"gravity.rig_angle_deg=" + phi}))->model.gravity_m_s2; };
  EXPECT_NEAR((g_at("0.0") - Eigen::Vector3d(9.81, 0.0, 0.0)).norm(), 0.0, 1e-12);
  EXPECT_NEAR((g_at("90.0") - Eigen::Vector3d(0.0, 0.0, -9.81)).norm(), 0.0, 1e-12);
  EXPECT_EQ(build_model(scene({}))->model.gravity_m_s2, Eigen::Vector3d::Zero());  // -1: off
  for (const auto& [sets, hint] : std::vector<std::pair<std::vector<std::string>, std::string>>{
           {{"gravity.rig_angle_deg=200.0"}, "allowed: >= -360 and <= 180"},  // the scene's checked read (scenes/key_limits.cpp)
           {{"gravity.rig_angle_deg=10.0", "gravity.g_m_s2=[0.0, 0.0, -9.81]"}, "both give gravity"}}) {
    try {
      build_model(scene(sets));
      ADD_FAILURE() << hint;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("gravity.rig_angle_deg"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(hint), std::string::npos) << e.what();
    }
  }
}

// The same actuator as a deck in any orientation (a rotation about a skew axis: no coordinate axis
// along it) bends by the same angle with no angle keys at all: the frame is the mesh's. Both runs
// solve the same discrete equations in rotated coordinates to solver.rel_tol = 1e-8 of the force
// scale, so the angles agree far inside 1e-6 of the angle (round-off and the Newton tolerance only);
// the rotated deck with the built-in's frame forced on it would be refused (checked above).
TEST_F(InpFiles, ADeckInAnyOrientationBendsAsTheBuiltInWithoutAngleKeys) {
  Mesh mesh = build_mesh(Scene::load("", {"geometry.chambers=2", "mesh.h_mm=6.0", "mesh.half=false"}));
  auto deck_of = [&](const Eigen::Matrix3d& R, const std::string& name) {
    Mesh m = mesh;
    for (Eigen::Vector3d& x : m.X) x = R * x;
    std::ostringstream os;
    write_inp_mesh(os, m, 1e-3);
    return write(name, os.str());
  };
  auto angle_at_10kPa = [](const std::string& deck, std::vector<std::string>* warnings) {
    const auto bm = build_model(Scene::load("", {"mesh.source=\"inp\"", "mesh.file=\"" + deck + "\"", "load.max_kPa=10.0",
                                                 "load.trials=1", "output.vtu=\"none\""}));
    if (warnings) *warnings = bm->warnings;
    const Assembler A(bm->model);
    QuasiStaticRun run(A, bm->solver.quasi_static);
    double last = 0.0;
    run.run(bm->load, [&](const StateRecord& r, const Eigen::VectorXd&, const std::vector<double>&) { last = r.angle_deg; });
    return last;
  };
  const Eigen::Matrix3d R = Eigen::AngleAxisd(1.1, Eigen::Vector3d(0.3, -0.5, 0.8).normalized()).toRotationMatrix();
  std::vector<std::string> notes;
  const double upright = angle_at_10kPa(deck_of(Eigen::Matrix3d::Identity(), "upright.inp"), nullptr);
  const double tilted = angle_at_10kPa(deck_of(R, "tilted.inp"), &notes);
  EXPECT_GT(upright, 0.2);  // a real bend (0.39 deg for two chambers at 10 kPa), positive towards the fabric
  EXPECT_NEAR(tilted, upright, 1e-6 * upright);
  EXPECT_EQ(count_containing(notes, "angle.fixed_normal taken from the mesh"), 1);
  EXPECT_EQ(count_containing(notes, "angle.bend_direction taken from the mesh"), 1);
}

// A deck without the tip node set (and the scene leaving mesh.tip_set at its default): the free end
// face is found from the mesh (the boundary nodes farthest from the clamped face), with a note, and
// is exactly the built-in mesher's TIP set; a tip set named by the user must exist.
TEST_F(InpFiles, WithoutATipSetTheFreeEndFaceIsFoundFromTheMesh) {
  Mesh mesh = build_mesh(Scene::load("", {"geometry.chambers=2", "mesh.h_mm=6.0", "mesh.half=false"}));
  const std::vector<int> tip = mesh.node_sets.at("TIP");
  mesh.node_sets.erase("TIP");
  for (Eigen::Vector3d& x : mesh.X) x = Eigen::Vector3d(x.y(), -x.x(), x.z());  // along x: no help from the defaults
  std::ostringstream os;
  write_inp_mesh(os, mesh, 1e-3);
  const std::string path = write("no_tip.inp", os.str());
  const auto bm = build_model(Scene::load("", {"mesh.source=\"inp\"", "mesh.file=\"" + path + "\""}));
  EXPECT_EQ(bm->model.angle.tip_nodes, tip);
  EXPECT_EQ(count_containing(bm->warnings, "mesh.tip_set: the deck has no node set 'TIP'; the free end face was taken from the mesh ("
                                           + std::to_string(tip.size()) + " boundary nodes at "), 1);
  try {
    build_model(Scene::load("", {"mesh.source=\"inp\"", "mesh.file=\"" + path + "\"", "mesh.tip_set=\"END\""}));
    ADD_FAILURE() << "a missing tip set named by the user was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("node set 'END' not found in the mesh"), std::string::npos) << e.what();
  }
}

// A deck whose chambers are marked only by their pressure load (*DLOAD Pn, no CAVITY surface) and a
// scene leaving mesh.cavity_surface at its default: the loaded faces are the cavity, with a note.
TEST_F(InpFiles, WithoutACavitySurfaceTheDecksPressureFacesAreTheCavity) {
  Mesh mesh = build_mesh(Scene::load("", {"geometry.chambers=2", "mesh.h_mm=6.0"}));
  const std::vector<FaceRef> cavity = mesh.surfaces.at("CAVITY");
  mesh.surfaces.erase("CAVITY");
  std::ostringstream os;
  write_inp_mesh(os, mesh, 1e-3);
  os << "*STEP, NLGEOM\n*STATIC\n*DLOAD\n";
  for (const FaceRef& f : cavity) os << mesh.element_ids[f.element] << ", P" << f.local_face + 1 << ", 0.045\n";
  os << "*END STEP\n";
  const std::string path = write("dload_only.inp", os.str());
  const auto bm = build_model(Scene::load("", {"mesh.source=\"inp\"", "mesh.file=\"" + path + "\"",
                                               "mesh.symmetry_set=\"SYMMETRY\""}));
  EXPECT_EQ(bm->model.pressure_faces, cavity);
  EXPECT_EQ(count_containing(bm->warnings, "mesh.cavity_surface: the deck has no surface 'CAVITY'; the faces of its pressure load (" +
                                               std::to_string(cavity.size()) + " *DLOAD/*DSLOAD P faces) are the cavity"), 1);
}

TEST(InpWrite, RefusesNamesADeckCannotHold) {
  Mesh m = read_inp(data_path("tet4_two.inp"), 0.01).mesh;
  m.node_sets["two words"] = {0};
  std::ostringstream os;
  try {
    write_inp_mesh(os, m, 0.01);
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("'two words'"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("rename it"), std::string::npos) << e.what();
  }
}

// -------------------------------------------------------------------------------------------
// User errors: file, line and what to do
// -------------------------------------------------------------------------------------------

const std::string kNodes = "*NODE\n1, 0, 0, 0\n2, 1, 0, 0\n3, 0, 1, 0\n4, 0, 0, 1\n";  // lines 1-5

TEST_F(InpFiles, UnknownElementType) {
  expect_error(kNodes + "*ELEMENT, TYPE=C3D27, ELSET=B\n1, 1, 2, 3, 4, 1, 2, 3, 4\n", 6,
               {"C3D27", "not supported", "C3D8 and C3D20", "convert the mesh to one of them"});
}

TEST_F(InpFiles, MixedElementOrders) {
  expect_error(kNodes + "*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n*ELEMENT, TYPE=C3D10\n", 8,
               {"mixes element orders", "bad.inp:6", "one element order"});
}

TEST_F(InpFiles, MissingNode) {
  expect_error(kNodes + "*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n2, 1, 2, 3,\n 99\n", 8,
               {"element 2 refers to node 99", "define the node under *NODE"});
}

TEST_F(InpFiles, DuplicateNodeId) { expect_error(kNodes + "3, 5, 5, 5\n", 6, {"node 3 is defined twice", "unique"}); }

TEST_F(InpFiles, NonNumericField) {
  expect_error("*NODE\n1, 0, 0, 0\n2, 1.0, abc, 0\n", 3,
               {"coordinate y 'abc' is not a finite number", "fix the value"});
  expect_error(kNodes + "*ELEMENT, TYPE=C3D4\n1, 1, 2, x3, 4\n", 7, {"node 'x3' is not an integer", "'id, node1"});
  expect_error(kNodes + "*NODE\n5, nan, 0, 0\n", 7, {"not a finite number"});
}

TEST_F(InpFiles, TwoDimensionalNode) { expect_error("*NODE\n1, 0.0, 0.0\n", 2, {"3-D", "'id, x, y, z'"}); }

TEST_F(InpFiles, IncompleteElement) {
  expect_error(kNodes + "*ELEMENT, TYPE=C3D10\n1, 1, 2, 3, 4, 1, 2, 3, 4\n", 7,
               {"lists 8 nodes but a C3D10 has 10", "end a line with ','"});
  expect_error(kNodes + "*ELEMENT, TYPE=C3D4\n1, 1, 2,\n*NSET, NSET=A\n1\n", 7,
               {"lists 2 nodes but a C3D4 has 4", "list all its nodes"});
}

TEST_F(InpFiles, UnknownSetNameInSurface) {
  expect_error(kNodes + "*ELEMENT, TYPE=C3D4, ELSET=BODY\n1, 1, 2, 3, 4\n*SURFACE, NAME=S\nbody, S1\nnope, S2\n", 10,
               {"unknown element set 'nope' in *SURFACE S", "define it with *ELSET"});
}

TEST_F(InpFiles, NodeSetWhereAnElementSetIsDue) {
  expect_error(kNodes + "*NSET, NSET=N\n1\n*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n*ELSET, ELSET=E\nN\n", 11,
               {"is a node set, not an element set"});
}

TEST_F(InpFiles, BadSurfaceFaceAndDloadFace) {
  const std::string head = kNodes + "*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n";
  expect_error(head + "*SURFACE, NAME=S\n1, S5\n", 9, {"S5 names face 5 of element 1, a C3D4 with faces 1-4", "use S1..S4"});
  expect_error(head + "*SURFACE, NAME=S\n1, S7\n", 9, {"'S7' is not an element face", "S1..S6 (hexahedra)"});
  expect_error(head + "*DLOAD\n1, P6, 1.0\n", 9, {"faces 1-4", "P1..P4"});
  expect_error(head + "*DLOAD\n1, P2\n", 9, {"without a magnitude"});
}

TEST_F(InpFiles, NonzeroBoundaryValue) {
  expect_error(kNodes + "*NSET, NSET=FIX\n1, 2\n*BOUNDARY\nFIX, 1, 3\nFIX, 3, 3, 0.5\n", 10,
               {"value 0.5 is not zero", "only homogeneous conditions"});
  expect_error(kNodes + "*BOUNDARY\n1, XASYMM\n", 7, {"'XASYMM'", "ENCASTRE"});
}

TEST_F(InpFiles, MissingIncludeFile) {
  const std::string msg = error_of("** main deck\n*INCLUDE, INPUT=mesh/missing.inp\n", "main.inp");
  EXPECT_NE(msg.find("main.inp:2: cannot open include file"), std::string::npos) << msg;
  EXPECT_NE(msg.find("mesh/missing.inp"), std::string::npos) << msg;
  EXPECT_NE(msg.find("relative path is taken from the directory of the including file"), std::string::npos) << msg;
}

TEST_F(InpFiles, ErrorInAnIncludedFileNamesThatFileAndLine) {
  write("sub/nodes.inp", "** nodes\n1, 0, 0, 0\n1, 1, 1, 1\n");
  const std::string msg = error_of("*NODE\n*INCLUDE, INPUT=sub/nodes.inp\n", "main.inp");
  EXPECT_NE(msg.find("sub/nodes.inp:3: node 1 is defined twice"), std::string::npos) << msg;
}

// *INCLUDE is bounded (issue 30, item 4): a fan-out of files each including the next twice, 24
// deep (2^24 inclusions, which hung the reader), ends at the count of inclusions with the chain of
// files; a cycle is named as such before the depth limit.
TEST_F(InpFiles, IncludeFanOutEndsAtTheLimitWithTheChain) {
  constexpr int kDepth = 24;
  auto file = [](int i) {
    std::ostringstream name;
    name << 'f' << i << ".inp";
    return name.str();
  };
  for (int i = 0; i < kDepth; ++i)
    write(file(i), "*INCLUDE, INPUT=" + file(i + 1) + "\n*INCLUDE, INPUT=" + file(i + 1) + "\n");
  write(file(kDepth), "** the leaf\n");
  const auto t0 = std::chrono::steady_clock::now();
  std::string msg;
  try {
    read_inp((dir_ / "f0.inp").string(), 1e-3);
  } catch (const InputError& e) {
    msg = e.what();
  }
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  EXPECT_LT(seconds, 10.0);
  EXPECT_NE(msg.find("more than 10000 *INCLUDE lines followed in one deck"), std::string::npos) << msg;
  // The chain: the line of each *INCLUDE open, the files after the deck named from its directory.
  EXPECT_NE(msg.find((dir_ / "f0.inp").string() + ":1 -> f1.inp:1 -> f2.inp:1 -> "), std::string::npos) << msg;
  EXPECT_NE(msg.find("include each file once"), std::string::npos) << msg;
}

// The deck's text is bounded too (issue 30, item 4): an included file that takes the text over the
// 1 GiB limit is refused at its *INCLUDE, with the chain, before its bytes are read (the file is
// sparse: nothing is written to disk or memory; a reader that read it first would take seconds and
// a gigabyte, so the time bound shows it did not); a top-level deck over the limit alone is refused
// the same way.
TEST_F(InpFiles, DeckTextOverOneGibibyteIsRefusedBeforeItIsRead) {
  const fs::path big = dir_ / "sub" / "big.inp";
  fs::create_directories(big.parent_path());
  std::ofstream(big).put('*');
  fs::resize_file(big, (std::uintmax_t{1} << 30) + 1);
  const auto t0 = std::chrono::steady_clock::now();
  const std::string msg = error_of(kNodes + "*INCLUDE, INPUT=sub/big.inp\n", "main.inp");
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 2.0);
  EXPECT_NE(msg.find("main.inp:6: the deck's text reaches 1024.0 MiB with "), std::string::npos) << msg;
  EXPECT_NE(msg.find("over the limit of 1024.0 MiB (a file counts each time it is included)"), std::string::npos) << msg;
  EXPECT_NE(msg.find("include chain "), std::string::npos) << msg;
  std::string top;
  try {
    read_inp(big.string(), 1e-3);
  } catch (const InputError& e) {
    top = e.what();
  }
  EXPECT_NE(top.find(big.string() + ": the deck's text reaches 1024.0 MiB"), std::string::npos) << top;
  EXPECT_NE(top.find("split the model or coarsen the mesh"), std::string::npos) << top;
}

TEST_F(InpFiles, IncludeCycleIsNamedWithItsChain) {
  write("a.inp", "** a\n*INCLUDE, INPUT=sub/b.inp\n");
  write("sub/b.inp", "*INCLUDE, INPUT=../a.inp\n");
  const std::string msg = error_of(kNodes + "*INCLUDE, INPUT=a.inp\n", "main.inp");
  EXPECT_NE(msg.find("sub/b.inp:1: *INCLUDE of "), std::string::npos) << msg;
  EXPECT_NE(msg.find("closes a cycle"), std::string::npos) << msg;
  EXPECT_NE(msg.find("main.inp:6 -> "), std::string::npos) << msg;
  EXPECT_NE(msg.find("a.inp:2 -> "), std::string::npos) << msg;
  EXPECT_NE(msg.find("remove the *INCLUDE that closes the cycle"), std::string::npos) << msg;
}

// A C3D10 whose mid-node lies far off its edge's midpoint folds over itself (issue 30, item 4): the
// deck is refused with the element, the node and the distortion; a gently curved edge is read.
TEST_F(InpFiles, DistortedTet10IsRefusedWithTheElementAndItsDistortion) {
  auto deck = [](const std::string& node5) {
    return "*NODE\n1, 0, 0, 0\n2, 1, 0, 0\n3, 0, 1, 0\n4, 0, 0, 1\n5, " + node5 +
           "\n6, .5, .5, 0\n7, 0, .5, 0\n8, 0, 0, .5\n9, .5, 0, .5\n10, 0, .5, .5\n"
           "*ELEMENT, TYPE=C3D10, ELSET=BODY\n7, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10\n";
  };
  EXPECT_EQ(error_of(deck("0.5, -0.08, 0")), "");  // a curved edge, 0.08 of its length off: fine
  const std::string msg = error_of(deck("0.9, 0, 0"));  // 0.4 of the edge off, along it: folds at node 2
  EXPECT_NE(msg.find("bad.inp: element 7"), std::string::npos) << msg;
  EXPECT_NE(msg.find("is a C3D10 too distorted to compute: its Jacobian falls to -0.6 of its straight-sided "
                     "tetrahedron's at its node 2 (at least 0.1 is needed)"), std::string::npos) << msg;
  EXPECT_NE(msg.find("its mid-node 5 lying 0.4 edge lengths off the midpoint of edge 1-2; 1 element(s)"),
            std::string::npos) << msg;
  EXPECT_NE(msg.find("remesh"), std::string::npos) << msg;
}

TEST_F(InpFiles, EmptyFile) {
  expect_error("", 1, {"empty", "give a deck with *NODE and *ELEMENT"});
  expect_error("** only a comment\n\n", 2, {"empty"});
}

TEST_F(InpFiles, DeckWithoutElementsOrDataBeforeKeywords) {
  expect_error(kNodes, 5, {"no elements", "*ELEMENT, TYPE=C3D4"});
  expect_error("1, 0, 0, 0\n", 1, {"data line before any keyword"});
}

// MODULI= of *HYPERELASTIC / *VISCOELASTIC (Abaqus: whether the hyperelastic constants are the
// instantaneous or the long-term response of a viscoelastic material) is read with its *MATERIAL and
// reaches materials.<m>.viscoelastic.moduli: by the material's name, else the one value of the deck;
// a scene's own key wins (with a note); an unknown value is an error naming file and line.
TEST_F(InpFiles, ModuliOfAViscoelasticMaterialReachTheScene) {
  std::ifstream in(data_path("tet4_two.inp"));
  std::stringstream buffer;
  buffer << in.rdbuf();
  const std::string two = buffer.str();
  const std::string materials =
      "*MATERIAL, NAME=Silicone\n"
      "*HYPERELASTIC, YEOH, MODULI=LONG TERM\n"
      "0.019, 0.0009, -4.75e-6, 0.5, 0.0, 0.0\n"
      "*VISCOELASTIC, TIME=PRONY\n"
      "0.3, 0.0, 2.0\n"
      "*MATERIAL, NAME=Gel\n"
      "*HYPERELASTIC, NEO HOOKE\n"
      "0.01, 0.5\n"
      "*VISCOELASTIC, TIME=PRONY, moduli=instantaneous\n"
      "0.2, 0.0, 1.0\n";
  const InpDeck d = read_inp(write("m.inp", two + materials), 1e-2);
  const int first = static_cast<int>(std::count(two.begin(), two.end(), '\n')) + 2;  // *HYPERELASTIC's line
  ASSERT_EQ(d.moduli.size(), 2u);
  EXPECT_EQ(d.moduli[0].material, "SILICONE");
  EXPECT_EQ(d.moduli[0].value, "long_term");
  EXPECT_NE(d.moduli[0].where.find("m.inp:" + std::to_string(first)), std::string::npos) << d.moduli[0].where;
  EXPECT_EQ(d.moduli[1].material, "GEL");
  EXPECT_EQ(d.moduli[1].value, "instantaneous");
  EXPECT_EQ(count_containing(d.warnings, "*HYPERELASTIC"), 0);  // a scene's materials pass reads it (materials.h)
  // Abaqus writes "LONG TERM"; an underscore and any case are read alike.
  EXPECT_EQ(read_inp(write("u.inp", two + "*MATERIAL, NAME=A\n*HYPERELASTIC, MODULI=long_term\n0.01, 0, 0.5\n"), 1e-2).moduli.at(0).value,
            "long_term");
  expect_error(two + "*MATERIAL, NAME=A\n*HYPERELASTIC, YEOH, MODULI=RELAXED\n", first,
               {"*HYPERELASTIC, MODULI=RELAXED: unknown value", "use MODULI=INSTANTANEOUS", "or MODULI=LONG TERM"});
  expect_error(two + "*MATERIAL, NAME=A\n*VISCOELASTIC, MODULI=\n", first, {"*VISCOELASTIC, MODULI=: unknown value"});

  // Through a scene: the built-in actuator written as a deck, with the materials appended.
  const std::vector<std::string> base = {"geometry.chambers=2", "mesh.h_mm=6.0"};
  std::ostringstream os;
  write_inp_mesh(os, build_mesh(Scene::load("", base)), 1e-3);
  auto scene = [&](const std::string& deck_materials, std::vector<std::string> extra) {
    std::vector<std::string> o = base;
    o.insert(o.end(), {"mesh.source=\"inp\"", "mesh.file=\"" + write("a.inp", os.str() + deck_materials) + "\"",
                       "mesh.symmetry_set=\"SYMMETRY\""});
    o.insert(o.end(), extra.begin(), extra.end());
    return Scene::load("", o);
  };
  auto moduli = [](const BuiltModel& bm) {
    for (const Part& p : bm.model.parts)
      if (const auto* v = dynamic_cast<const Viscoelastic*>(p.material.get())) return std::string(to_string(v->moduli()));
    return std::string("(not viscoelastic)");
  };
  const std::string on = "materials.silicone.viscoelastic.enabled=true";
  auto bm = build_model(scene(materials, {on}));
  EXPECT_EQ(moduli(*bm), "long_term");  // *MATERIAL, NAME=Silicone is the scene's silicone
  EXPECT_EQ(count_containing(bm->warnings, "materials.silicone from the deck (*MATERIAL Silicone, "), 1);
  EXPECT_EQ(count_containing(bm->warnings, "viscoelastic.gamma, viscoelastic.tau_s, viscoelastic.moduli"), 2);  // and Gel
  bm = build_model(scene(materials, {on, "materials.silicone.viscoelastic.moduli=instantaneous"}));
  EXPECT_EQ(moduli(*bm), "instantaneous");  // the scene's own key wins, with a note
  EXPECT_EQ(count_containing(bm->warnings, "is kept over the deck's MODULI=LONG TERM of *MATERIAL SILICONE"), 1);
  bm = build_model(scene(materials, {}));  // the deck's *VISCOELASTIC switches it on (scenes/deck_materials.h)
  EXPECT_EQ(moduli(*bm), "long_term");
  bm = build_model(scene(materials, {"materials.silicone.viscoelastic.enabled=false"}));  // the scene's key wins
  EXPECT_EQ(moduli(*bm), "(not viscoelastic)");
  EXPECT_EQ(count_containing(bm->warnings, "MODULI="), 0);
  bm = build_model(scene("*MATERIAL, NAME=Ecoflex\n*HYPERELASTIC, YEOH, MODULI=LONG TERM\n0.019, 0, 0, 0.5\n", {on}));
  EXPECT_EQ(moduli(*bm), "long_term");  // no material of the scene's name: the deck's one value
  bm = build_model(scene("", {on}));
  EXPECT_EQ(moduli(*bm), "instantaneous");  // no MODULI= at all: the scene's default, as Abaqus's
  try {
    build_model(scene("*MATERIAL, NAME=A\n*HYPERELASTIC, MODULI=LONG TERM\n0.01, 0, 0.5\n*MATERIAL, NAME=B\n"
                      "*HYPERELASTIC, MODULI=INSTANTANEOUS\n0.01, 0, 0.5\n",
                      {on}));
    ADD_FAILURE() << "no error for MODULI= that differ";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("materials.silicone.viscoelastic.moduli"), std::string::npos) << what;
    EXPECT_NE(what.find("the deck's MODULI= differ (MODULI=LONG TERM of *MATERIAL A at "), std::string::npos) << what;
    EXPECT_NE(what.find("MODULI=INSTANTANEOUS of *MATERIAL B at "), std::string::npos) << what;
    EXPECT_NE(what.find("none belongs to a *MATERIAL named 'silicone'"), std::string::npos) << what;
  }
}

TEST(InpErrors, MissingDeck) {
  try {
    read_inp("/nonexistent/dir/deck.inp", 1e-3);
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/dir/deck.inp: cannot open"), std::string::npos) << e.what();
  }
}

/// Found by fuzz/count_outcomes.py on the fuzz corpus: deck text with a NUL byte (a UTF-16 deck, a
/// binary file) quoted into a message cut InputError::what() - a C string - short at the NUL, before
/// the advice ("node 1: coordinate z '"). Control bytes in messages and notes are now \xHH.
TEST_F(InpFiles, ControlBytesInTheDeckDoNotCutTheMessageShort) {
  const std::string nodes = "*NODE\n1, 0, 0, 0\n2, 1, 0, 0\n3, 0, 1, 0\n4, 0, 0, 1\n";
  std::string msg = error_of(std::string("*NODE\n1, 0, 0, z\0z\n", 19));
  EXPECT_NE(msg.find("bad.inp:2: "), std::string::npos) << msg;
  EXPECT_NE(msg.find("'z\\x00z'"), std::string::npos) << msg;
  EXPECT_NE(msg.find("; "), std::string::npos) << "no advice in: " << msg;
  msg = error_of(nodes + "*ELEMENT, TYPE=C3D\x1B[2J\n1, 1, 2, 3, 4\n");
  EXPECT_NE(msg.find("bad.inp:6: "), std::string::npos) << msg;
  EXPECT_NE(msg.find("C3D\\x1B[2J"), std::string::npos) << msg;
  for (const char c : msg) EXPECT_FALSE(static_cast<unsigned char>(c) < 0x20 && c != '\n') << msg;
  // A note quoting deck text (a skipped keyword) is printable too.
  const InpDeck deck = read_inp(write("note.inp", nodes + "*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n*FOO\r\x07\n"), 1e-3);
  bool found = false;
  for (const std::string& w : deck.warnings) {
    for (const char c : w) EXPECT_FALSE(static_cast<unsigned char>(c) < 0x20 && c != '\n') << w;
    found = found || w.find("\\x07") != std::string::npos;
  }
  EXPECT_TRUE(found) << "the note on *FOO\\r\\x07 is missing";
}

/// Every mutilation of a valid deck either reads or throws InputError: no crash, no other error.
TEST_F(InpFiles, GarbageNeverCrashes) {
  std::ifstream in(data_path("tet4_two.inp"));
  std::vector<std::string> lines;
  for (std::string l; std::getline(in, l);) lines.push_back(l);
  ASSERT_GT(lines.size(), 20u);
  auto join = [](const std::vector<std::string>& ls) {
    std::string s;
    for (const auto& l : ls) s += l + "\n";
    return s;
  };
  const std::vector<std::string> junk = {
      "", ",", ",,,,", "x", "*", "**", "-1", "99999999999999999999", "1e999", "*ELEMENT, TYPE=", "\xff\xfe", "S9", "P"};
  int accepted = 0, rejected = 0;
  auto attempt = [&](const std::string& text) {
    try {
      read_inp(write("g.inp", text), 1.0);
      ++accepted;
    } catch (const InputError&) {
      ++rejected;
    }
  };
  std::mt19937 rng(42);
  for (std::size_t i = 0; i < lines.size(); ++i) {
    std::vector<std::string> ls = lines;
    ls.erase(ls.begin() + static_cast<std::ptrdiff_t>(i));
    attempt(join(ls));
    ls = lines;
    ls[i] = ls[i].substr(0, ls[i].size() / 2);
    attempt(join(ls));
    for (const std::string& j : junk) {
      ls = lines;
      ls[i] += ", " + j;
      attempt(join(ls));
      ls[i] = j;
      attempt(join(ls));
    }
  }
  std::string bytes(4000, '\0');
  for (char& c : bytes) c = static_cast<char>(rng() & 0xff);
  attempt(bytes);
  EXPECT_GT(accepted, 0);
  EXPECT_GT(rejected, 0);
}

}  // namespace
}  // namespace pneufem
