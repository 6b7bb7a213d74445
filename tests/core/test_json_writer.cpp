// The JSON writer (core/json_writer.h): numbers at the shortest precision that reads back to the
// same double, non-finite numbers as null, strings escaped, objects in insertion order.
#include "core/json_writer.h"

#include <cmath>
#include <cstdlib>
#include <limits>
#include <string>

#include <gtest/gtest.h>

namespace {

using namespace pneufem;

TEST(JsonWriter, NumbersReadBackExactlyAtTheShortestPrecision) {
  EXPECT_EQ(json::num(0.0), "0");
  EXPECT_EQ(json::num(1.5), "1.5");
  EXPECT_EQ(json::num(0.1), "0.1");
  EXPECT_EQ(json::num(-2e-7), "-2e-07");
  for (double v : {1.0 / 3.0, 2.0 / 3.0, std::sqrt(2.0), 6.02214076e23, 1e-300, 123456.789012345678,
                   std::numeric_limits<double>::max(), std::numeric_limits<double>::denorm_min()}) {
    const std::string s = json::num(v);
    EXPECT_EQ(std::strtod(s.c_str(), nullptr), v) << s;
  }
}

TEST(JsonWriter, NonFiniteNumbersAreNull) {
  EXPECT_EQ(json::num(std::nan("")), "null");
  EXPECT_EQ(json::num(std::numeric_limits<double>::infinity()), "null");
  EXPECT_EQ(json::array({1.0, std::nan(""), 2.5}), "[1, null, 2.5]");
}

TEST(JsonWriter, StringsAreEscaped) {
  EXPECT_EQ(json::quote("plain"), "\"plain\"");
  EXPECT_EQ(json::quote("a\"b\\c"), "\"a\\\"b\\\\c\"");
  EXPECT_EQ(json::quote("line\nnext\ttab\r"), "\"line\\nnext\\ttab\\r\"");
  EXPECT_EQ(json::quote(std::string("\x01", 1)), "\"\\u0001\"");
}

TEST(JsonWriter, ObjectsKeepTheirOrderAndIndent) {
  json::Object inner;
  inner.add("x", 1.0);
  json::Object o;
  o.add_str("name", "run").add("value", 0.25).add("inner", inner.str(2));
  EXPECT_EQ(o.str(), "{\n  \"name\": \"run\",\n  \"value\": 0.25,\n  \"inner\": {\n    \"x\": 1\n  }\n}");
}

}  // namespace
