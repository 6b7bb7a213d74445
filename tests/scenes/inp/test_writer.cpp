// The deck writer (scenes/inp/writer.cpp): round trips through write_inp_mesh and read_inp keep every
// node, element, region and set, coordinates to round-off and CalculiX's line limits; a name a deck
// cannot hold is refused.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <numbers>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "tests/scenes/inp/deck_files.h"

namespace pneufem {
namespace {

using namespace pneufem::test;

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

}  // namespace
}  // namespace pneufem
