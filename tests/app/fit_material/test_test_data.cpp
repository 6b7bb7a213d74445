// app/fit_material/test_data.h: the reader of test-data CSV files - units from the header, a machine's
// export with its metadata block, the test mode from a prefix or the file's name, and bad input, each
// error naming the file, the line and what to do.
#include "app/fit_material/test_data.h"

#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "fit/inelastic.h"
#include "tests/app/fit_material/fit_material_helpers.h"
#include "tests/support/input_error.h"

namespace pneufem {
namespace {

using fit::TestMode;
using test::error_of;
using namespace test::fit_material;

// --- reader ---------------------------------------------------------------------------------

TEST(TestData, UnitsComeFromTheHeader) {
  const fit::TestCurve kpa = read(write_temp("kpa.csv", "strain,stress_kPa\n0,0\n0.5,20\n1.0,35\n"));
  ASSERT_EQ(kpa.points.size(), 3u);
  EXPECT_DOUBLE_EQ(kpa.points[2].stretch, 2.0);
  EXPECT_DOUBLE_EQ(kpa.points[2].P_Pa, 35e3);
  EXPECT_EQ(kpa.points[2].line, 4);
  const fit::TestCurve mpa = read(write_temp("mpa.csv", "Stretch, Stress (MPa)\n1.5,0.02\n"));
  EXPECT_DOUBLE_EQ(mpa.points[0].stretch, 1.5);
  EXPECT_DOUBLE_EQ(mpa.points[0].P_Pa, 0.02e6);
  const fit::TestCurve pct = read(write_temp("pct.csv", "time_s,strain_percent,stress_psi\n0,50,1\n"));
  EXPECT_DOUBLE_EQ(pct.points[0].stretch, 1.5);
  EXPECT_NEAR(pct.points[0].P_Pa, 6894.757, 1e-3);
  // decimal commas with ';' (a spreadsheet in a decimal-comma locale)
  const fit::TestCurve comma = read(write_temp("comma.csv", "Dehnung;strain;stress_N/mm^2\nx;0,25;0,5\n"));
  EXPECT_DOUBLE_EQ(comma.points[0].stretch, 1.25);
  EXPECT_DOUBLE_EQ(comma.points[0].P_Pa, 0.5e6);
}

// The testing machine's export as it is: 17 metadata lines, ';', true and engineering columns.
TEST(TestData, ReadsTheMachineExportWithItsMetadataBlock) {
  std::vector<std::string> notes;
  const fit::TestCurve c = read_test_csv(kEcoflex, TestMode::uniaxial, notes);
  ASSERT_EQ(c.points.size(), 720u);  // 721 rows, the first (negative stress) left out
  EXPECT_EQ(c.points[0].line, 20);
  EXPECT_DOUBLE_EQ(c.points[0].stretch, 1.06795);
  EXPECT_DOUBLE_EQ(c.points[0].P_Pa, 0.00224e6);
  std::string all;
  for (const std::string& n : notes) all += n + "\n";
  EXPECT_NE(all.find("16 line(s) before the header (line 18) skipped"), std::string::npos) << all;
  EXPECT_NE(all.find("'True Strain', 'True Stress (MPa)' skipped"), std::string::npos) << all;
  EXPECT_NE(all.find("ecoflex_00-50.csv:19: 1 point(s) with zero or negative stress"), std::string::npos) << all;
}

TEST(TestData, TheTestModeComesFromThePrefixOrTheFileName) {
  EXPECT_EQ(parse_test_spec("planar:a.csv").mode, TestMode::planar);
  EXPECT_EQ(parse_test_spec("planar:a.csv").path, "a.csv");
  EXPECT_EQ(parse_test_spec("equibiaxial:x/b.csv").mode, TestMode::biaxial);
  EXPECT_EQ(parse_test_spec("data/silicone_pure_shear.csv").mode, TestMode::planar);
  EXPECT_EQ(parse_test_spec("run3_Equibiaxial.csv").mode, TestMode::biaxial);
  const std::string e = error_of([] { parse_test_spec("data/silicone.csv"); });
  EXPECT_NE(e.find("which test is it? Write uniaxial:data/silicone.csv"), std::string::npos) << e;
}

// --- reader: bad input, each naming the file and line and what to do -------------------------------

TEST(TestDataErrors, NonMonotonicStrain) {
  const std::string p = write_temp("cycle.csv", "strain,stress_kPa\n0.1,5\n0.5,20\n0.3,8\n");
  const std::string e = error_of([&] { read(p); });
  EXPECT_NE(e.find("cycle.csv:4: the strain falls from 0.5 (line 3) to 0.3"), std::string::npos) << e;
  EXPECT_NE(e.find("Keep the first loading up to line 3"), std::string::npos) << e;
}

TEST(TestDataErrors, NegativeStrain) {
  const std::string p = write_temp("compression.csv", "strain,stress_kPa\n-0.2,-5\n0,0\n0.5,20\n");
  const std::string e = error_of([&] { read(p); });
  EXPECT_NE(e.find("compression.csv:2: nominal strain -0.2 is negative"), std::string::npos) << e;
  EXPECT_NE(e.find("tension tests only"), std::string::npos) << e;
  const std::string s = write_temp("stretch0.csv", "stretch,stress_kPa\n0,0\n");
  EXPECT_NE(error_of([&] { read(s); }).find("stretch0.csv:2: stretch 0 <= 0"), std::string::npos);
}

TEST(TestDataErrors, MixedMissingAndUnknownUnits) {
  const std::string mixed = write_temp("mixed.csv", "strain,stress_kPa,stress_MPa\n0.5,20,0.02\n");
  std::string e = error_of([&] { read(mixed); });
  EXPECT_NE(e.find("mixed.csv:1: columns 'stress_kPa' and 'stress_MPa' both give the stress in different units "
                   "(mixed units); keep one of them"),
            std::string::npos)
      << e;
  const std::string two_strains = write_temp("two.csv", "strain,stretch,stress_MPa\n0.5,1.5,0.02\n");
  EXPECT_NE(error_of([&] { read(two_strains); }).find("both give the strain in different units"), std::string::npos);
  const std::string none = write_temp("nounit.csv", "# my test\nstrain,stress\n0.5,20\n");
  e = error_of([&] { read(none); });
  EXPECT_NE(e.find("nounit.csv:2: column 'stress' has no unit; name it stress_Pa, stress_kPa"), std::string::npos) << e;
  const std::string bar = write_temp("bar.csv", "strain,stress_bar\n0.5,20\n");
  EXPECT_NE(error_of([&] { read(bar); }).find("bar.csv:1: column 'stress_bar': unknown stress unit 'bar'"),
            std::string::npos);
  const std::string cells = write_temp("cells.csv", "strain,stress_kPa\n0.5,20 kPa\n");
  e = error_of([&] { read(cells); });
  EXPECT_NE(e.find("cells.csv:2: '20 kPa' in column 'stress_kPa' is not a number (units belong in the header"),
            std::string::npos)
      << e;
}

TEST(TestDataErrors, NoHeader) {
  const std::string p = write_temp("bare.csv", "0.5,20\n1.0,35\n");
  const std::string e = error_of([&] { read(p); });
  EXPECT_NE(e.find("bare.csv:1: data before any header; the first line must name the columns"), std::string::npos) << e;
  const std::string q = write_temp("words.csv", "a,b\nc,d\n");
  EXPECT_NE(error_of([&] { read(q); }).find("words.csv: no header naming the columns with their units, e.g. 'strain,stress_kPa'"), std::string::npos);
}

}  // namespace
}  // namespace pneufem
