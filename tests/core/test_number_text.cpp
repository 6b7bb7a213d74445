// core/number_text.h: numbers as messages quote them.
#include "core/number_text.h"

#include <cmath>
#include <string>

#include <gtest/gtest.h>

namespace pneufem {
namespace {

TEST(NumberText, ShortNumIsSixSignificantDigits) {
  EXPECT_EQ(short_num(0.25), "0.25");
  EXPECT_EQ(short_num(45.0), "45");
  EXPECT_EQ(short_num(1e6), "1e+06");
  EXPECT_EQ(short_num(1.0 / 3.0), "0.333333");
  EXPECT_EQ(short_num(std::nan("")), "nan");
}

}  // namespace
}  // namespace pneufem
