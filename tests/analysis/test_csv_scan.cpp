// analysis/csv_scan.h: the scanning helpers of the CSV readers - lines, fields, strict numbers,
// header cells, and the file:line:column message.
#include "analysis/csv_scan.h"

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/errors.h"

namespace pneufem::csv {
namespace {

// A byte-order mark is skipped, CRLF and LF both end a line, a last line without "\n" counts, and
// an empty line is a line.
TEST(CsvScan, LinesAfterABomWithEitherTerminator) {
  LineCursor c("\xEF\xBB\xBFtime_s,angle_deg\r\n1,2\n\n3,4");
  Line l;
  std::vector<std::string> text;
  std::vector<int> number;
  while (c.next(l)) {
    text.emplace_back(l.text);
    number.push_back(l.number);
  }
  EXPECT_EQ(text, (std::vector<std::string>{"time_s,angle_deg", "1,2", "", "3,4"}));
  EXPECT_EQ(number, (std::vector<int>{1, 2, 3, 4}));
  LineCursor empty("");
  EXPECT_FALSE(empty.next(l));
}

TEST(CsvScan, SplitKeepsEmptyAndUntrimmedFields) {
  std::vector<std::string_view> f;
  split(" a, b ,,c,", f);
  ASSERT_EQ(f.size(), 5u);
  EXPECT_EQ(f[0], " a");
  EXPECT_EQ(f[1], " b ");
  EXPECT_EQ(f[2], "");
  EXPECT_EQ(f[3], "c");
  EXPECT_EQ(f[4], "");
  split("", f);
  EXPECT_EQ(f.size(), 1u);
  EXPECT_EQ(trim(" \t x y\t "), "x y");
  EXPECT_EQ(trim(" \t "), "");
}

TEST(CsvScan, HeaderNamesAreLowerCaseWithoutQuotes) {
  EXPECT_EQ(header_name("  \" Angle_Deg \" "), "angle_deg");
  EXPECT_EQ(header_name("Time_s"), "time_s");
  EXPECT_EQ(header_name("\""), "\"");  // a lone quote is not a pair
}

TEST(CsvScan, ParseDoubleIsStrict) {
  double v = 0.0;
  EXPECT_EQ(parse_double(" 2.5e-1 ", v), Number::ok);
  EXPECT_EQ(v, 0.25);
  EXPECT_EQ(parse_double("+3", v), Number::ok);
  EXPECT_EQ(v, 3.0);
  EXPECT_EQ(parse_double("-0.5", v), Number::ok);
  EXPECT_EQ(v, -0.5);
  EXPECT_EQ(parse_double("  ", v), Number::empty);
  EXPECT_EQ(parse_double("1.5 kPa", v), Number::not_a_number);
  EXPECT_EQ(parse_double("1,5", v), Number::not_a_number);
  EXPECT_EQ(parse_double("abc", v), Number::not_a_number);
  EXPECT_EQ(parse_double("nan", v), Number::not_finite);
  EXPECT_EQ(parse_double("inf", v), Number::not_finite);
  EXPECT_EQ(parse_double("1e999", v), Number::not_finite);
}

TEST(CsvScan, ParseIntTakesIntegralDecimals) {
  long n = 0;
  EXPECT_EQ(parse_int("7", n), Number::ok);
  EXPECT_EQ(n, 7);
  EXPECT_EQ(parse_int(" +12 ", n), Number::ok);
  EXPECT_EQ(n, 12);
  EXPECT_EQ(parse_int("3.0", n), Number::ok);  // MATLAB writes these
  EXPECT_EQ(n, 3);
  EXPECT_EQ(parse_int("-2", n), Number::ok);
  EXPECT_EQ(n, -2);
  EXPECT_EQ(parse_int("3.5", n), Number::not_a_number);
  EXPECT_EQ(parse_int("1e20", n), Number::not_a_number);  // integral, but beyond a long's exact range here
  EXPECT_EQ(parse_int("", n), Number::empty);
  EXPECT_EQ(parse_int("nan", n), Number::not_finite);
  EXPECT_EQ(parse_int("x1", n), Number::not_a_number);
}

TEST(CsvScan, NumberTextReadsBackExactly) {
  for (double v : {0.1, 1.0 / 3.0, 45.0, -2.5e-7, 1e300}) {
    double back = 0.0;
    ASSERT_EQ(parse_double(number_text(v), back), Number::ok) << number_text(v);
    EXPECT_EQ(back, v);
  }
  EXPECT_EQ(number_text(0.1), "0.1");
  EXPECT_EQ(number_text(45.0), "45");
}

// A quoted field is cut to 40 characters and its control bytes are written out.
TEST(CsvScan, QuotedFieldsArePrintableAndShort) {
  EXPECT_EQ(csv::quoted("ab"), "'ab'");
  EXPECT_EQ(csv::quoted(std::string("a\0b", 3)), "'a\\x00b'");
  const std::string q = csv::quoted(std::string(100, 'x'));
  EXPECT_EQ(q, "'" + std::string(37, 'x') + "...'");
}

TEST(CsvScan, FailNamesFileLineAndColumn) {
  try {
    fail("rec.csv", 12, 3, "angle 'x' is not a number", "give degrees");
    FAIL() << "fail() returned";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "rec.csv:12:3: angle 'x' is not a number; give degrees");
  }
  try {
    (void)read_file("/nonexistent/dir/rec.csv");
    FAIL() << "read_file() returned";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind("/nonexistent/dir/rec.csv: cannot open the file (", 0), 0u) << e.what();
  }
}

}  // namespace
}  // namespace pneufem::csv
