// scenes/inp/text.h, the text layer of the deck reader, field by field: numbers as Fortran list input
// writes them (and nothing else), fields split at commas with Abaqus's trailing-comma continuation,
// keyword names and parameters normalised; then, through the reader, the *INCLUDE handling of
// LineSource (missing, nested, bounded in count and bytes, cycles), a missing deck, and deck bytes
// quoted printable into messages.
#include "scenes/inp/text.h"

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/errors.h"
#include "tests/scenes/inp/deck_files.h"

namespace {

using namespace pneufem::inp;

TEST(InpText, RealsAreWholeFieldsInFortranForms) {
  EXPECT_EQ(parse_double("1."), 1.0);
  EXPECT_EQ(parse_double(".5"), 0.5);
  EXPECT_EQ(parse_double("+2"), 2.0);
  EXPECT_EQ(parse_double("-1e-3"), -1e-3);
  EXPECT_EQ(parse_double("1.0D-3"), 1e-3);  // the double-precision exponent
  EXPECT_EQ(parse_double("2.5d2"), 250.0);
  EXPECT_EQ(parse_double("1.E1"), 10.0);
  for (const char* bad : {"", "+", "1.0x", "1,0", " 1", "1 ", "inf", "nan", "1e999", "--1", "0x10"})
    EXPECT_FALSE(parse_double(bad).has_value()) << '"' << bad << '"';
  // At most 64 characters: a longer field is refused, not cut.
  EXPECT_TRUE(parse_double(std::string(64, '1')).has_value());
  EXPECT_FALSE(parse_double(std::string(65, '1')).has_value());
}

TEST(InpText, IntegersAreWholeFields) {
  EXPECT_EQ(parse_long("12"), 12);
  EXPECT_EQ(parse_long("+12"), 12);
  EXPECT_EQ(parse_long("-3"), -3);
  for (const char* bad : {"", "+", "1.0", "1e3", "12a", " 1", "99999999999999999999"})
    EXPECT_FALSE(parse_long(bad).has_value()) << '"' << bad << '"';
}

TEST(InpText, FieldsAreTrimmedAndATrailingCommaIsAContinuation) {
  std::vector<std::string_view> f;
  bool trailing = false;
  split_fields(" 1,\t2.5 ,, 3 ", f, trailing);
  EXPECT_EQ(f, (std::vector<std::string_view>{"1", "2.5", "", "3"}));
  EXPECT_FALSE(trailing);
  split_fields("4, 5,  ", f, trailing);
  EXPECT_EQ(f, (std::vector<std::string_view>{"4", "5"}));  // no empty last field
  EXPECT_TRUE(trailing);
  split_fields("", f, trailing);
  EXPECT_EQ(f, (std::vector<std::string_view>{""}));
  EXPECT_FALSE(trailing);
}

TEST(InpText, KeywordNamesAndParametersAreNormalised) {
  EXPECT_EQ(keyword_name("*Solid  \t Section"), "SOLID SECTION");
  EXPECT_EQ(keyword_name("* node"), "NODE");
  const Keyword kw = parse_keyword("*Element, type=C3D10 , ELSET = \"Body A\", generate,");
  EXPECT_EQ(kw.name, "ELEMENT");
  EXPECT_EQ(kw.get("TYPE"), "C3D10");  // keys upper case, values as written
  EXPECT_EQ(kw.get("ELSET"), "Body A");  // unquoted
  EXPECT_TRUE(kw.has("GENERATE"));
  EXPECT_EQ(kw.get("GENERATE"), "");
  EXPECT_FALSE(kw.has("NSET"));
  EXPECT_EQ(kw.params.size(), 3u);
}

}  // namespace

namespace pneufem {
namespace {

using namespace pneufem::test;

// -------------------------------------------------------------------------------------------
// Through the reader: *INCLUDE (the LineSource of text.h), a missing deck and the bytes quoted
// into its messages
// -------------------------------------------------------------------------------------------

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

}  // namespace
}  // namespace pneufem
