// scenes/inp/text.h, the text layer of the deck reader, field by field: numbers as Fortran list input
// writes them (and nothing else), fields split at commas with Abaqus's trailing-comma continuation,
// keyword names and parameters normalised. The *INCLUDE handling of LineSource is tested on decks
// (test_deck.cpp).
#include "scenes/inp/text.h"

#include <string>
#include <vector>

#include <gtest/gtest.h>

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
