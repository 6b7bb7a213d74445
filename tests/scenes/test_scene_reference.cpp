// scenes/scene_reference.h: the generated scene reference (docs/scene_reference.md). The docs test
// scene_reference_is_current compares the committed file with the generator's output; this tests the
// generator itself: the unit a key's name carries, one section per table of the default scene in its
// order, every key a row, every range of key_limits a row, and well-formed Markdown tables.
#include "scenes/scene_reference.h"

#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "scenes/key_limits.h"
#include "scenes/scene.h"

namespace pneufem {
namespace {

TEST(SceneReference, UnitOfKeyFromItsSuffix) {
  EXPECT_EQ(unit_of_key("h_mm"), "mm");
  EXPECT_EQ(unit_of_key("density_kg_m3"), "kg/m³");
  EXPECT_EQ(unit_of_key("acceleration_m_s2"), "m/s²");
  EXPECT_EQ(unit_of_key("max_kPa"), "kPa");
  EXPECT_EQ(unit_of_key("C10_MPa"), "MPa");
  EXPECT_EQ(unit_of_key("rig_angle_deg"), "deg");
  EXPECT_EQ(unit_of_key("hold_s"), "s");
  EXPECT_EQ(unit_of_key("rate_1_s"), "1/s");  // the longer suffix first: not "s"
  EXPECT_EQ(unit_of_key("method"), "");
  EXPECT_EQ(unit_of_key("_mm"), "");  // a suffix alone is not a key with a unit
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> out;
  std::istringstream in(text);
  for (std::string l; std::getline(in, l);) out.push_back(l);
  return out;
}

std::string trim(const std::string& s) {
  const std::size_t a = s.find_first_not_of(" \t");
  return a == std::string::npos ? "" : s.substr(a, s.find_last_not_of(" \t") + 1 - a);
}

TEST(SceneReference, ASectionPerTableAndARowPerKeyOfTheDefaultScene) {
  const std::string md = scene_reference_markdown();
  std::vector<std::string> tables, headings;
  std::vector<std::string> keys;
  for (const std::string& line : lines_of(Scene::default_text())) {
    const std::string t = trim(line);
    if (t.empty() || t[0] == '#') continue;
    if (t[0] == '[') {
      tables.push_back(t.substr(0, t.find_last_of(']', t.find('#')) + 1));  // "[x]" or "[[x]]", no comment
    } else if (t.find('=') != std::string::npos) {
      keys.push_back(trim(t.substr(0, t.find('='))));
    }
  }
  for (const std::string& line : lines_of(md))
    if (line.rfind("## `", 0) == 0) headings.push_back(line.substr(4, line.size() - 5));
  EXPECT_GT(tables.size(), 10u);
  EXPECT_EQ(headings, tables);  // the same tables, in the file's order
  for (const std::string& k : keys) EXPECT_NE(md.find("| `" + k + "` | `"), std::string::npos) << k;
  EXPECT_NE(md.find("| `h_mm` | `"), std::string::npos);
  EXPECT_NE(md.find("| mm | "), std::string::npos);  // the unit column filled from the key's name
}

TEST(SceneReference, EveryKeyLimitIsARowOfTheAllowedRanges) {
  const std::string md = scene_reference_markdown();
  const std::size_t ranges = md.find("## Allowed ranges");
  ASSERT_NE(ranges, std::string::npos);
  for (const KeyLimit& l : key_limits()) EXPECT_NE(md.find("| `" + l.pattern + "` | ", ranges), std::string::npos) << l.pattern;
}

TEST(SceneReference, TablesAreWellFormed) {
  // Every row has the cells of its table's header: a '|' in a comment must have been escaped.
  int cells = -1, rows = 0;
  for (const std::string& line : lines_of(scene_reference_markdown())) {
    if (line.rfind("|", 0) != 0) {
      cells = -1;
      continue;
    }
    int n = 0;
    for (std::size_t i = 0; i < line.size(); ++i) n += line[i] == '|' && (i == 0 || line[i - 1] != '\\');
    if (cells < 0)
      cells = n;
    else
      EXPECT_EQ(n, cells) << line;
    ++rows;
  }
  EXPECT_GT(rows, 100);
}

}  // namespace
}  // namespace pneufem
