// The helpers every file of diagnose shares (app/diagnose/detail.h): the square and the number
// formatting its sentences are made of. The rest of detail.h declares the functions of the other
// files of app/diagnose, tested in their own test files (test_calibrate.cpp, test_evidence.cpp, ...).
#include <string>

#include <gtest/gtest.h>

#include "app/diagnose/detail.h"

namespace pneufem::diagnose_detail {
namespace {

TEST(DiagnoseDetail, SquareIsTheProductWithItself) {
  EXPECT_EQ(sq(0.0), 0.0);
  EXPECT_EQ(sq(-3.0), 9.0);
  EXPECT_EQ(sq(0.1), 0.1 * 0.1);
}

TEST(DiagnoseDetail, FmtPrintsOneNumberWithThePrintfFormat) {
  EXPECT_EQ(fmt("%.4f", 0.01234567), "0.0123");
  EXPECT_EQ(fmt("%+.2f", 0.4), "+0.40");
  EXPECT_EQ(fmt("%.0f", 99.6), "100");
  EXPECT_EQ(fmt("%.4g", 1.0 / 3.0), "0.3333");
  // A number wider than any sentence prints: the buffer (96 characters) holds it whole.
  EXPECT_EQ(fmt("%.17g", 1e300).size(), std::string("1.0000000000000001e+300").size());
}

}  // namespace
}  // namespace pneufem::diagnose_detail
