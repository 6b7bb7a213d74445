#pragma once
// Helpers shared by the deck reader's and writer's tests (tests/scenes/inp/test_reader.cpp and its
// siblings, and the scene's deck tests in tests/scenes/): the test decks of tests/data/inp, ids and
// notes of a read deck, and the InpFiles fixture, which writes decks to a temporary directory per
// test, reads them and asserts an error's file, line and hints.
#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <vector>

#include "core/errors.h"
#include "scenes/inp/deck.h"

namespace pneufem::test {

namespace fs = std::filesystem;

inline std::string data_path(const std::string& name) { return std::string(PNEUFEM_TEST_DATA_DIR) + "/inp/" + name; }

/// External ids of a sorted index list.
inline std::vector<long> ids_of(const std::vector<int>& indices, const std::vector<long>& ids) {
  std::vector<long> out;
  for (int i : indices) out.push_back(ids[static_cast<std::size_t>(i)]);
  return out;
}

/// External node ids of element e.
inline std::vector<long> element_node_ids(const Mesh& m, int e) {
  std::vector<long> out;
  for (int k = 0; k < m.npe(); ++k) out.push_back(m.node_ids[static_cast<std::size_t>(m.element(e)[k])]);
  return out;
}

inline std::string upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

inline std::string region_of(const Mesh& m, int e) { return m.region_names[m.region[static_cast<std::size_t>(e)]]; }

inline int count_containing(const std::vector<std::string>& lines, const std::string& needle) {
  return static_cast<int>(std::count_if(lines.begin(), lines.end(),
                                        [&](const std::string& l) { return l.find(needle) != std::string::npos; }));
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
  /// Reads `text` as bad.inp (lengths times error_length_to_m_) and returns the InputError message
  /// ("" if none was thrown).
  std::string error_of(const std::string& text, const std::string& name = "bad.inp") const {
    try {
      read_inp(write(name, text), error_length_to_m_);
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
  double error_length_to_m_ = 1e-3;  ///< the length unit error_of() reads a bad deck in
};

/// Every mutilation of the deck `lines` (each line dropped, halved, extended by ", junk" and
/// replaced by junk, for every junk), as the deck's text, to `attempt`.
template <class Attempt>
void for_each_mutilation(const std::vector<std::string>& lines, const std::vector<std::string>& junk, Attempt&& attempt) {
  auto join = [](const std::vector<std::string>& ls) {
    std::string s;
    for (const auto& l : ls) s += l + "\n";
    return s;
  };
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
}

/// Nodes 1-4 of a unit tetrahedron: lines 1-5 of a deck that goes on with its elements.
inline const std::string kNodes = "*NODE\n1, 0, 0, 0\n2, 1, 0, 0\n3, 0, 1, 0\n4, 0, 0, 1\n";

}  // namespace pneufem::test
