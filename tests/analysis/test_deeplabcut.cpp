// DeepLabCut reader (analysis/deeplabcut.h): synthetic tracks of a known angle sequence, written
// in DeepLabCut's CSV layout, must give that angle (signed, unwrapped past 180 deg, zeroed at
// rest) and drop exactly the low-likelihood frames; malformed files name file, line and column.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <map>
#include <numbers>
#include <set>
#include <string>
#include <vector>

#include "analysis/deeplabcut.h"
#include "core/errors.h"
#include "tests/analysis/synthetic.h"

namespace pneufem {
namespace {

constexpr double kPi = std::numbers::pi;

// Brief: angles within 0.1 deg. The coordinates are written with 6 decimals (DeepLabCut writes
// more), i.e. 5e-7 px on lines 80-120 px long: an angle error of ~1e-8 rad, so any error
// above 0.1 deg is a wrong convention (sign, y axis, unwrapping, zero), not rounding.
constexpr double kAngleTol_deg = 0.1;

struct Xy {
  double x = 0.0, y = 0.0;
};

Xy rotate(Xy p, double deg) {
  const double a = deg * kPi / 180.0;
  return {std::cos(a) * p.x - std::sin(a) * p.y, std::sin(a) * p.x + std::cos(a) * p.y};
}

/// Known bending angle of frame k (deg, counter-clockwise on the screen): rest, a curl past
/// 180 deg, a hold, and a return through zero to -30 deg.
double true_angle(int k) {
  if (k < 20) return 0.0;
  if (k < 80) return (k - 20) * 200.0 / 60.0;
  if (k < 100) return 200.0;
  return 200.0 - (k - 100) * 5.0;
}

struct SyntheticDlc {
  int frames = 150;
  double camera_roll_deg = 7.0;  ///< the rig is not aligned with the image axes
  bool tip_along_face = false;   ///< tip points across the end face instead of along the axis
  bool individuals_row = false;  ///< multi-animal layout with one individual
  std::map<int, std::string> low_part;  ///< frame -> body part written with likelihood 0.2
};

/// DeepLabCut CSV of an actuator hanging down from a clamp at the top of the image, bending in
/// the image plane. Body parts: clamp_top, clamp_mid, clamp_low (fixed end, top to bottom),
/// tip_a, tip_b, tip_c (tip segment), marker (unused by the mapping).
std::string dlc_csv(const SyntheticDlc& spec) {
  const std::vector<std::string> parts = {"clamp_top", "clamp_mid", "clamp_low", "tip_a", "tip_b", "tip_c", "marker"};
  std::string out = "scorer";
  for (std::size_t i = 0; i < parts.size() * 3; ++i) out += ",DLC_resnet50_pneunetNov1shuffle1_100000";
  out += "\n";
  if (spec.individuals_row) {
    out += "individuals";
    for (std::size_t i = 0; i < parts.size() * 3; ++i) out += ",actuator1";
    out += "\n";
  }
  out += "bodyparts";
  for (const std::string& p : parts) out += "," + p + "," + p + "," + p;
  out += "\ncoords";
  for (std::size_t i = 0; i < parts.size(); ++i) out += ",x,y,likelihood";
  out += "\n";
  char buf[64];
  for (int k = 0; k < spec.frames; ++k) {
    const double th = true_angle(k);
    // Model coordinates (X right, Y up); the actuator hangs along -Y from the clamp at the origin.
    const Xy pivot{-150.0 * (1.0 - std::cos(th * kPi / 180.0)), -400.0 + 150.0 * std::sin(th * kPi / 180.0)};
    std::vector<Xy> pts = {{0.0, 0.0}, {0.0, -60.0}, {0.0, -120.0}};
    const std::vector<Xy> tip_local = spec.tip_along_face ? std::vector<Xy>{{-30.0, 0.0}, {0.0, 0.0}, {30.0, 0.0}}
                                                          : std::vector<Xy>{{0.0, 0.0}, {0.0, -40.0}, {0.0, -90.0}};
    for (const Xy& q : tip_local) {
      const Xy r = rotate(q, th);
      pts.push_back({pivot.x + r.x, pivot.y + r.y});
    }
    pts.push_back({250.0 + k, -50.0});
    out += std::to_string(k);
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const Xy c = rotate(pts[i], spec.camera_roll_deg);
      const auto low = spec.low_part.find(k);
      const double lik = low != spec.low_part.end() && low->second == parts[i] ? 0.2 : 0.97;
      std::snprintf(buf, sizeof buf, ",%.6f,%.6f,%.4f", 640.0 + c.x, 100.0 - c.y, lik);  // image y down
      out += buf;
    }
    out += "\n";
  }
  return out;
}

DlcMapping mapping() {
  DlcMapping m;
  m.fixed_parts = {"clamp_top", "clamp_mid", "clamp_low"};
  m.tip_parts = {"tip_a", "tip_b", "tip_c"};
  m.trial = 4;
  m.t0_s = 0.5;
  return m;
}

/// Checks angles of every kept frame against true_angle(frame) * sign and that exactly `dropped`
/// frames are missing.
void expect_angles(const Recording& rec, const std::set<int>& dropped, int frames, double sign, double fps,
                   double t0) {
  ASSERT_EQ(rec.trials.size(), 1u);
  const Series& a = rec.trials[0].angle_deg;
  ASSERT_EQ(a.t_s.size(), static_cast<std::size_t>(frames) - dropped.size());
  std::size_t i = 0;
  for (int k = 0; k < frames; ++k) {
    if (dropped.count(k)) continue;
    EXPECT_NEAR(a.t_s[i], t0 + k / fps, 1e-12) << "frame " << k;
    EXPECT_NEAR(a.value[i], sign * true_angle(k), kAngleTol_deg) << "frame " << k;
    ++i;
  }
  EXPECT_TRUE(rec.trials[0].pressure_kPa.t_s.empty());
}

TEST(DeepLabCut, AnglesSignedUnwrappedAndLowLikelihoodDropped) {
  SyntheticDlc spec;
  spec.low_part = {{5, "tip_b"}, {33, "tip_c"}, {34, "tip_a"}, {60, "clamp_mid"}, {90, "tip_a"}, {120, "tip_c"},
                   {70, "marker"}};  // frame 70: only the unused body part is poor -> kept
  const std::string path = testing::temp_path("dlc.csv");
  testing::write_text(path, dlc_csv(spec));
  const DlcMapping map = mapping();
  const Recording rec = read_deeplabcut_csv(path, map);
  EXPECT_EQ(rec.source, path);
  EXPECT_EQ(rec.trials[0].trial, 4);
  expect_angles(rec, {5, 33, 34, 60, 90, 120}, spec.frames, +1.0, map.fps, map.t0_s);
  ASSERT_EQ(rec.warnings.size(), 1u);
  EXPECT_NE(rec.warnings[0].find("dropped 6 of 150 frames: 6 with a mapped body part below likelihood 0.9 (first at "
                                 "line 9)"),
            std::string::npos)
      << rec.warnings[0];
}

TEST(DeepLabCut, ClockwiseSenseFlipsTheSign) {
  SyntheticDlc spec;
  const std::string path = testing::temp_path("dlc_cw.csv");
  testing::write_text(path, dlc_csv(spec));
  DlcMapping map = mapping();
  map.positive = AngleSense::clockwise;
  const Recording rec = read_deeplabcut_csv(path, map);
  expect_angles(rec, {}, spec.frames, -1.0, map.fps, map.t0_s);
  EXPECT_TRUE(rec.warnings.empty());
}

// Points across the end face instead of along the axis: the raw angle at rest is 90 deg, the
// zero reference (median of the first frames) removes it. An explicit zero_raw_deg = 90 gives
// the same; zero_raw_deg = 0 with axis points keeps the raw angle (0 at rest for a straight rest
// shape).
TEST(DeepLabCut, ZeroReferenceMakesTheFeatureChoiceIrrelevant) {
  SyntheticDlc spec;
  spec.tip_along_face = true;
  spec.individuals_row = true;
  const std::string path = testing::temp_path("dlc_face.csv");
  testing::write_text(path, dlc_csv(spec));
  DlcMapping map = mapping();
  expect_angles(read_deeplabcut_csv(path, map), {}, spec.frames, 1.0, map.fps, map.t0_s);
  map.zero_raw_deg = 90.0;
  expect_angles(read_deeplabcut_csv(path, map), {}, spec.frames, 1.0, map.fps, map.t0_s);
  map.zero_raw_deg = -270.0;  // the same direction: the first frame's branch nearest the zero is taken
  expect_angles(read_deeplabcut_csv(path, map), {}, spec.frames, 1.0, map.fps, map.t0_s);

  spec.tip_along_face = false;
  spec.individuals_row = false;
  testing::write_text(path, dlc_csv(spec));
  map.zero_raw_deg = 0.0;
  map.fps = 60.0;
  expect_angles(read_deeplabcut_csv(path, map), {}, spec.frames, 1.0, map.fps, map.t0_s);
}

// A small file as DeepLabCut writes it (CRLF, two-point lists, a frame with NaN coordinates).
TEST(DeepLabCut, ReadsTheSmallDataFile) {
  DlcMapping map;
  map.fixed_parts = {"base1", "base2"};
  map.tip_parts = {"tip1", "tip2"};
  map.zero_frames = 1;
  const Recording rec = read_deeplabcut_csv(std::string(PNEUFEM_TEST_DATA_DIR) + "/measurements/dlc_small.csv", map);
  ASSERT_EQ(rec.trials.size(), 1u);
  const Series& a = rec.trials[0].angle_deg;
  // Frames 0..4: tip direction (0,1)->(1,1)->(1,0) in image pixels: 0, 45, 90 deg counter-clockwise
  // as seen on the screen (image y down); frame 3 has NaN coordinates; frame 4 back at 45 deg.
  ASSERT_EQ(a.value.size(), 4u);
  EXPECT_NEAR(a.value[0], 0.0, kAngleTol_deg);
  EXPECT_NEAR(a.value[1], 45.0, kAngleTol_deg);
  EXPECT_NEAR(a.value[2], 90.0, kAngleTol_deg);
  EXPECT_NEAR(a.value[3], 45.0, kAngleTol_deg);
  EXPECT_NEAR(a.t_s[3], 4.0 / 30.0, 1e-12);
  ASSERT_EQ(rec.warnings.size(), 1u);
  EXPECT_NE(rec.warnings[0].find("1 with empty or NaN coordinates"), std::string::npos) << rec.warnings[0];
}

// ---- malformed input: every message names file, line and column --------------------------------

/// Parses `text` and returns the InputError message ("" when nothing was thrown).
std::string error_of(const std::string& text, const DlcMapping& map = mapping()) {
  try {
    parse_deeplabcut_csv(text, "tracks.csv", map);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

std::string header() {
  return "scorer,s,s,s,s,s,s,s,s,s,s,s,s,s,s,s,s,s,s\n"
         "bodyparts,clamp_top,clamp_top,clamp_top,clamp_mid,clamp_mid,clamp_mid,clamp_low,clamp_low,clamp_low,"
         "tip_a,tip_a,tip_a,tip_b,tip_b,tip_b,tip_c,tip_c,tip_c\n"
         "coords,x,y,likelihood,x,y,likelihood,x,y,likelihood,x,y,likelihood,x,y,likelihood,x,y,likelihood\n";
}

const std::string kRow = ",0,0,1,0,60,1,0,120,1,0,400,1,0,440,1,0,490,1\n";

TEST(DeepLabCutErrors, MessagesNameFileLineAndColumn) {
  struct Case {
    std::string text, expected;
  };
  const std::vector<Case> cases = {
      {"", "tracks.csv:1:1: the file is empty; "},
      {"bodyparts,a\n", "tracks.csv:1:1: expected the header row 'scorer', found 'bodyparts'; "},
      {"scorer,s,s,s\ncoords,x,y,likelihood\n", "tracks.csv:2:1: expected the header row 'bodyparts'"},
      {"scorer,s,s,s\nbodyparts,a,a\n", "tracks.csv:2:4: the header row has 3 fields, the scorer row 4; "},
      {"scorer,s,s,s\nbodyparts,a,a,a\ncoords,x,y,z\n", "tracks.csv:3:4: coordinate 'z' is not x, y or likelihood; "},
      {"scorer,s,s,s\nbodyparts,a,a,a\ncoords,x,y,likelihood\n0,1,2,1\n",
       "tracks.csv:2:1: fixed_parts names body part 'clamp_top', which is not in the file (it has: a); "},
      {header(), "tracks.csv:4:1: no frame rows after the header rows; "},
      {header() + "0" + kRow + "1,0,0,1\n", "tracks.csv:5:5: the row has 4 fields, the header rows 19; "},
      {header() + "0" + kRow + "frame1" + kRow, "tracks.csv:5:1: frame index 'frame1' is not an integer; "},
      {header() + "3" + kRow + "3" + kRow, "tracks.csv:5:1: frame 3 does not follow frame 3 (line 4); "},
      {header() + "0,0,0,1,0,60,1,0,120,1,0,400,1,0,4x0,1,0,490,1\n",
       "tracks.csv:4:15: tip_b y = '4x0' is not a number; "},
      {header() + "0,0,0,1,0,60,1,0,120,1,0,400,0.1,0,440,1,0,490,1\n",
       "tracks.csv:4:1: none of the 1 frames has all of the mapped body parts tracked above likelihood 0.9; "},
  };
  for (const Case& c : cases) {
    const std::string msg = error_of(c.text);
    EXPECT_EQ(msg.rfind(c.expected, 0), 0u) << "expected: " << c.expected << "\n     got: " << msg;
    EXPECT_NE(msg.find("; "), std::string::npos) << "no advice in: " << msg;
  }
}

// Found by fuzz/count_outcomes.py on the fuzz corpus: a first cell with a NUL byte (a UTF-16 file)
// cut the message short at the NUL, before the advice; control bytes are now written as \xHH.
TEST(DeepLabCutErrors, AUtf16FileGivesTheWholeMessageOnOneLine) {
  std::string utf16 = "\xFF\xFE";
  for (const char c : std::string("scorer,DLC\nbodyparts,base1\n")) utf16 += std::string{c, '\0'};
  const std::string msg = error_of(utf16);
  EXPECT_EQ(msg.rfind("tracks.csv:1:1: expected the header row 'scorer', found '\xFF\xFEs\\x00c\\x00o\\x00", 0), 0u) << msg;
  EXPECT_NE(msg.find("r\\x00'; give DeepLabCut's CSV as written by analyze_videos"), std::string::npos) << msg;
  for (const char c : msg) EXPECT_FALSE(static_cast<unsigned char>(c) < 0x20) << msg;
}

TEST(DeepLabCutErrors, InvalidMappingNamesTheField) {
  const std::string text = header() + "0" + kRow;
  DlcMapping m = mapping();
  m.fixed_parts = {"clamp_top"};
  EXPECT_NE(error_of(text, m).find("DeepLabCut mapping: fixed_parts lists 1 body part(s)"), std::string::npos);
  m = mapping();
  m.tip_parts = {"tip_a", "clamp_top"};
  EXPECT_NE(error_of(text, m).find("'clamp_top' is in both fixed_parts and tip_parts"), std::string::npos);
  m = mapping();
  m.likelihood_cut = 1.5;
  EXPECT_NE(error_of(text, m).find("likelihood_cut"), std::string::npos);
  m = mapping();
  m.fps = 0.0;
  EXPECT_NE(error_of(text, m).find("fps"), std::string::npos);
  EXPECT_THROW(read_deeplabcut_csv(testing::temp_path("missing.csv"), mapping()), InputError);
}

}  // namespace
}  // namespace pneufem
