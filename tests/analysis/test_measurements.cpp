// Canonical measurement CSV (analysis/measurements.h): a hand-made file with every tolerated
// quirk, a bit-exact round trip of the paper's ten-trial recording, a 10^6-row read (rate
// printed, not asserted), and one case per class of malformed input asserting file:line:column.
#include <gtest/gtest.h>

#include <cmath>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "analysis/csv_scan.h"
#include "analysis/measurements.h"
#include "core/errors.h"
#include "tests/analysis/synthetic.h"

namespace pneufem {
namespace {

using testing::StaircaseSpec;

bool contains(const std::vector<std::string>& v, const std::string& needle) {
  for (const std::string& s : v)
    if (s.find(needle) != std::string::npos) return true;
  return false;
}

TEST(MeasurementsCsv, ReadsTheSmallDataFileWithItsQuirks) {
  const std::string path = std::string(PNEUFEM_TEST_DATA_DIR) + "/measurements/canonical_small.csv";
  const Recording rec = read_measurements_csv(path);
  EXPECT_EQ(rec.source, path);
  ASSERT_EQ(rec.trials.size(), 2u);
  const TrialRecording& t1 = rec.trials[0];
  const TrialRecording& t2 = rec.trials[1];
  EXPECT_EQ(t1.trial, 1);  // sorted by trial number although trial 2 comes first in the file
  EXPECT_EQ(t2.trial, 2);
  EXPECT_EQ(t1.pressure_kPa.t_s, (std::vector<double>{0.0, 0.0025, 0.005, 0.0375}));
  EXPECT_EQ(t1.pressure_kPa.value, (std::vector<double>{0.02, 0.01, 0.025, 0.15}));  // repeated stamp: last wins
  EXPECT_EQ(t1.angle_deg.t_s, (std::vector<double>{0.0, 0.0333333}));
  EXPECT_EQ(t1.angle_deg.value, (std::vector<double>{0.1, 0.12}));
  EXPECT_EQ(t2.pressure_kPa.value, (std::vector<double>{0.03, 0.04}));
  EXPECT_EQ(t2.angle_deg.value, (std::vector<double>{0.5}));
  ASSERT_EQ(rec.warnings.size(), 1u);
  EXPECT_TRUE(contains(rec.warnings, path + ": trial 1: 1 repeated pressure time stamp(s) (first at line 7); kept "
                                            "the last sample of each"))
      << rec.warnings[0];
}

TEST(MeasurementsCsv, StreamsMayBeInterleavedAnyWayAndRowsMayCarryOneStream) {
  const std::string text =
      "trial,time_s,pressure_kPa,angle_deg\n"
      "1,0,1,\n1,0.1,2,\n1,0.2,3,\n"  // all pressure rows first ...
      "1,0,,10\n1,0.15,,11\n"         // ... then the angle rows of the same trial
      "+2,0.0,5,20\n2.0,0.1,,\n";     // "+2" and "2.0" are trial 2; a row with neither stream is skipped
  const Recording rec = parse_measurements_csv(text, "mem.csv");
  ASSERT_EQ(rec.trials.size(), 2u);
  EXPECT_EQ(rec.trials[0].pressure_kPa.t_s, (std::vector<double>{0.0, 0.1, 0.2}));
  EXPECT_EQ(rec.trials[0].angle_deg.t_s, (std::vector<double>{0.0, 0.15}));
  EXPECT_EQ(rec.trials[1].trial, 2);
  EXPECT_EQ(rec.trials[1].pressure_kPa.value, (std::vector<double>{5.0}));
  EXPECT_TRUE(contains(rec.warnings, "mem.csv: 1 row(s) with neither pressure_kPa nor angle_deg were skipped (first "
                                     "at line 8)"));
}

/// The paper's recording: ten trials of 0..45 kPa, 160 s each, 400 Hz pressure and 30 fps angle.
Recording paper_recording() {
  StaircaseSpec spec;
  spec.outlier_frames = {100, 2000};
  Recording rec;
  for (int trial = 1; trial <= 10; ++trial)
    rec.trials.push_back(testing::make_staircase_trial(spec, trial, 50u + static_cast<unsigned>(trial)));
  return rec;
}

void expect_same(const Recording& a, const Recording& b) {
  ASSERT_EQ(a.trials.size(), b.trials.size());
  for (std::size_t i = 0; i < a.trials.size(); ++i) {
    EXPECT_EQ(a.trials[i].trial, b.trials[i].trial);
    // Bit-for-bit: the writer uses the shortest text that reads back to the same double.
    EXPECT_EQ(a.trials[i].pressure_kPa.t_s, b.trials[i].pressure_kPa.t_s) << "trial " << a.trials[i].trial;
    EXPECT_EQ(a.trials[i].pressure_kPa.value, b.trials[i].pressure_kPa.value) << "trial " << a.trials[i].trial;
    EXPECT_EQ(a.trials[i].angle_deg.t_s, b.trials[i].angle_deg.t_s) << "trial " << a.trials[i].trial;
    EXPECT_EQ(a.trials[i].angle_deg.value, b.trials[i].angle_deg.value) << "trial " << a.trials[i].trial;
  }
}

TEST(MeasurementsCsv, RoundTripOfThePaperRecordingIsExact) {
  const Recording rec = paper_recording();
  const std::string path = testing::temp_path("roundtrip.csv");
  write_measurements_csv(path, rec);
  EXPECT_FALSE(std::filesystem::exists(path + ".tmp"));
  const Recording back = read_measurements_csv(path);
  EXPECT_TRUE(back.warnings.empty()) << back.warnings.front();
  expect_same(rec, back);
  std::filesystem::remove(path);
}

// ~10^6 rows: 10 trials x 250 s at 400 Hz plus the 30 fps angle stream (rows shared where the
// time stamps coincide, every 0.1 s). The rate is printed for the record; no timing assertion
// (machines differ), but the content is checked.
TEST(MeasurementsCsv, MillionRowFileReadRate) {
  StaircaseSpec spec;
  spec.hold_s = 25.0;  // 10 levels x 25 s = 250 s = 100 000 pressure samples per trial
  Recording rec;
  for (int trial = 1; trial <= 10; ++trial)
    rec.trials.push_back(testing::make_staircase_trial(spec, trial, 900u + static_cast<unsigned>(trial)));
  const std::string path = testing::temp_path("million.csv");
  write_measurements_csv(path, rec);
  const std::size_t rows = 10 * (100000 + 7500 - 2500);
  const auto bytes = std::filesystem::file_size(path);

  const auto t0 = std::chrono::steady_clock::now();
  const Recording back = read_measurements_csv(path);
  const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("[ read     ] %zu rows, %.1f MB in %.3f s: %.2f million rows/s, %.0f MB/s\n", rows, bytes / 1e6, s,
              rows / s / 1e6, bytes / 1e6 / s);
  std::filesystem::remove(path);

  ASSERT_EQ(back.trials.size(), 10u);
  std::size_t p = 0, a = 0;
  for (const TrialRecording& tr : back.trials) {
    p += tr.pressure_kPa.t_s.size();
    a += tr.angle_deg.t_s.size();
  }
  EXPECT_EQ(p, 1000000u);
  EXPECT_EQ(a, 75000u);
  expect_same(rec, back);
}

// ---- malformed input: every message is "<file>:<line>:<column>: <what>; <what to do>" -----------

std::string error_of(const std::string& text) {
  try {
    parse_measurements_csv(text, "data.csv");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(MeasurementsCsvErrors, MessagesNameFileLineAndColumn) {
  const std::string h = "trial,time_s,pressure_kPa,angle_deg\n";
  struct Case {
    std::string text, expected;
  };
  const std::vector<Case> cases = {
      {"", "data.csv:1:1: the file is empty; "},
      {"\xEF\xBB\xBF\r\n\n", "data.csv:1:1: the file is empty; "},
      {"\n" + h + "1,0,1,2\n", "data.csv:1:1: the first line is blank; "},
      {"trial,time_s,pressure_kPa\n1,0,1\n",
       "data.csv:1:1: missing column 'angle_deg' (the header is 'trial,time_s,pressure_kPa'); add the column"},
      {"trial,time_s,pressure,angle_deg\n1,0,1,2\n",
       "data.csv:1:1: missing column 'pressure_kPa' (the header is 'trial,time_s,pressure,angle_deg'); the header has "
       "'pressure': rename it to pressure_kPa"},
      {"trial;time_s;pressure_kPa;angle_deg\n1;0;1;2.5.1\n", "data.csv:2:4: angle_deg = '2.5.1' is not a number; "},
      {"trial,time_s,pressure_kPa,angle_deg,Time_s\n", "data.csv:1:5: column 'time_s' appears twice (also field 2); "},
      {h, "data.csv:2:1: no data rows after the header; "},
      {h + "1,0,abc,\n", "data.csv:2:3: pressure_kPa = 'abc' is not a number; "},
      {h + "1,0,1,2\n1,0.1,3;4,\n", "data.csv:3:3: pressure_kPa = '3;4' is not a number; "},
      {h + "1,0,nan,\n", "data.csv:2:3: pressure_kPa = 'nan' is not a finite number; "},
      {h + "1,0,,-inf\n", "data.csv:2:4: angle_deg = '-inf' is not a finite number; "},
      {h + "1,0,1e999,\n", "data.csv:2:3: pressure_kPa = '1e999' is not a finite number; "},
      {h + "1,NaN,1,\n", "data.csv:2:2: time_s = 'NaN' is not a finite number; "},
      {h + "1.5,0,1,\n", "data.csv:2:1: trial = '1.5' is not an integer; "},
      {h + "one,0,1,\n", "data.csv:2:1: trial = 'one' is not an integer; "},
      {h + "99999999999,0,1,\n", "data.csv:2:1: trial = '99999999999' is out of range; "},
      {h + ",0,1,\n", "data.csv:2:1: trial is empty; "},
      {h + "1,,1,\n", "data.csv:2:2: time_s is empty; "},
      {h + "1,0,1\n", "data.csv:2:4: angle_deg is missing: the row has 3 fields, the header 4; "},
      {h + "1,0,1,2,3\n", "data.csv:2:5: the row has 5 fields, the header only 4; "},
      {h + "1,0,1,\n1,0.5,1,\n1,0.25,1,\n",
       "data.csv:4:2: time_s = '0.25' goes back in time: the previous pressure sample of trial 1 is at time_s = 0.5 "
       "(line 3); "},
      {h + "1,0,,1\n1,0.5,,1\n1,0,2,\n1,0.25,,1\n",  // the pressure stream may restart; the angle may not
       "data.csv:5:2: time_s = '0.25' goes back in time: the previous angle sample of trial 1 is at time_s = 0.5 "
       "(line 3); "},
      {"Time_s,Trial,note,Angle_deg,Pressure_kPa\n0,1,x,,1 kPa\n",
       "data.csv:2:5: Pressure_kPa = '1 kPa' is not a number; "},
  };
  for (const Case& c : cases) {
    const std::string msg = error_of(c.text);
    EXPECT_EQ(msg.rfind(c.expected, 0), 0u) << "expected: " << c.expected << "\n     got: " << msg;
    EXPECT_NE(msg.find("; "), std::string::npos) << "no advice in: " << msg;
  }
}

// Found by fuzz/fuzz_measurements: a file whose every data row has neither a pressure nor an angle
// (each row skipped with a warning) was read as a recording of no trials, without an error; the
// reader now names the first such row (the fuzzer's input is fuzz/corpus/measurements/no_samples_*).
TEST(MeasurementsCsvErrors, RowsWithoutAnySampleAreAnErrorNotAnEmptyRecording) {
  const std::string h = "trial,time_s,pressure_kPa,angle_deg\n";
  EXPECT_EQ(error_of(h + "1,0,,\n\n1,0.1,,\n").rfind(
                "data.csv:2:1: no samples: none of the 2 data row(s) has a pressure_kPa or angle_deg value; ", 0),
            0u);
  EXPECT_EQ(error_of("Time_s,Trial,Angle_deg,note,PRESSUZE_KPA\n0,2,,0.04,x\n")
                .rfind("data.csv:2:1: no samples: none of the 1 data row(s) has an angle_deg value; ", 0),
            0u);
  // One row with a sample is enough; the others are skipped with the warning, as before.
  EXPECT_EQ(parse_measurements_csv(h + "1,0,,\n1,0.1,,2\n", "data.csv").trials.size(), 1u);
}

// Found by fuzz/count_outcomes.py on the fuzz corpus: a header with a NUL byte (every ASCII character
// of a UTF-16 file, as spreadsheets save "Unicode text") was quoted raw into the message, and
// InputError::what() - a C string - ended at the NUL: "missing column 'trial' (the header is '",
// with no advice. Control bytes are now written as \xHH and the quoted header is bounded.
TEST(MeasurementsCsvErrors, AUtf16OrBinaryHeaderGivesTheWholeMessageOnOneLine) {
  std::string utf16 = "\xFF\xFE";  // UTF-16LE byte-order mark, then each character and a NUL
  for (const char c : std::string("trial,time_s,pressure_kPa,angle_deg\n1,0,1,2\n")) utf16 += std::string{c, '\0'};
  const std::string msg = error_of(utf16);
  EXPECT_EQ(msg.rfind("data.csv:1:1: missing column 'trial' (the header is '\xFF\xFEt\\x00r\\x00i\\x00", 0), 0u) << msg;
  EXPECT_NE(msg.find("'); add the column; the header must name trial,time_s,pressure_kPa,angle_deg"), std::string::npos)
      << msg;
  EXPECT_LT(msg.size(), 600u) << msg;
  for (const char c : msg) EXPECT_FALSE(static_cast<unsigned char>(c) < 0x20) << msg;
  // A column name with a control byte, named in a cell's message, is printable too.
  EXPECT_EQ(error_of("trial,time_s,pressure_kPa,angle_deg,note\x1B[2J\n1,0,1,2\n")
                .rfind("data.csv:2:5: note\\x1B[2J is missing: the row has 4 fields, the header 5; ", 0),
            0u);
}

// Recordings made by other tools name their columns with units in brackets or in other units: the
// reader converts those it knows exactly (and says so), so nobody has to edit the file.
TEST(MeasurementsCsv, ColumnsInOtherUnitsAreConvertedAndReported) {
  const Recording r = parse_measurements_csv(
      "Trial,Time (ms),Pressure [psi],Angle (rad)\n1,0,0,0\n1,250,1,\n1,500,,0.5\n", "rig.csv");
  ASSERT_EQ(r.trials.size(), 1u);
  const TrialRecording& t = r.trials[0];
  ASSERT_EQ(t.pressure_kPa.t_s.size(), 2u);
  ASSERT_EQ(t.angle_deg.t_s.size(), 2u);
  EXPECT_EQ(t.pressure_kPa.t_s[1], 0.25);                   // 250 ms (exact in binary)
  EXPECT_EQ(t.pressure_kPa.value[1], 6.894757293168361);   // 1 psi in kPa (NIST)
  EXPECT_EQ(t.angle_deg.t_s[1], 0.5);
  EXPECT_NEAR(t.angle_deg.value[1], 28.64788975654116, 1e-13);  // 0.5 rad, to round-off
  ASSERT_EQ(r.warnings.size(), 3u);
  EXPECT_EQ(r.warnings[0], "rig.csv: column 'Time (ms)' read as time_s (values times 0.001)");
  EXPECT_NE(r.warnings[1].find("'Pressure [psi]' read as pressure_kPa"), std::string::npos) << r.warnings[1];
  EXPECT_NE(r.warnings[2].find("'Angle (rad)' read as angle_deg"), std::string::npos) << r.warnings[2];
  // Units spelled in brackets, canonical unit: no conversion, no note, the same numbers.
  const Recording c = parse_measurements_csv("trial, time [s] ,pressure (kPa),angle_deg\n1,0.1,2.5,\n1,0.2,,1\n", "c.csv");
  EXPECT_TRUE(c.warnings.empty());
  EXPECT_EQ(c.trials[0].pressure_kPa.value[0], 2.5);
  for (const char* bad : {"trial,time_s,pressure_kPa,pressure_psi,angle_deg\n1,0,1,1,\n",
                          "trial,time_s,pressure_atm,angle_deg\n1,0,1,\n"}) {
    const std::string msg = error_of(bad);
    EXPECT_TRUE(msg.find("appears twice") != std::string::npos || msg.find("pressure_psi; angle_deg") != std::string::npos)
        << msg;
  }
}

// Loggers that write one file per session without a trial column: a trial starts where the time
// restarts (and a single run is trial 1), said in a note.
TEST(MeasurementsCsv, WithoutATrialColumnTrialsStartWhereTheTimeRestarts) {
  const Recording r = parse_measurements_csv(
      "time_s,pressure_kPa,angle_deg\n0,0,0\n0.5,5,1\n1.0,5,1.1\n0,0,0.2\n0.5,5,1.3\n", "log.csv");
  ASSERT_EQ(r.trials.size(), 2u);
  EXPECT_EQ(r.trials[0].trial, 1);
  EXPECT_EQ(r.trials[1].trial, 2);
  EXPECT_EQ(r.trials[0].angle_deg.value, (std::vector<double>{0, 1, 1.1}));
  EXPECT_EQ(r.trials[1].angle_deg.value, (std::vector<double>{0.2, 1.3}));
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_EQ(r.warnings[0], "log.csv: no trial column: the trials are numbered 1, 2, ... where time_s restarts");
}

// Video of a commanded protocol (the seed paper's angles): no pressure column at all. The angles are
// read, the pressure series stay empty and the recording says so; a column that names a pressure
// without a known unit is still the error above (that column was meant, not left out).
TEST(MeasurementsCsv, AnglesAloneAreReadWithoutPressure) {
  const Recording r = parse_measurements_csv("trial,time_s,angle_deg\n1,0,0.1\n1,0.5,2\n2,0,0.3\n", "video.csv");
  EXPECT_FALSE(r.pressure_recorded);
  ASSERT_EQ(r.trials.size(), 2u);
  EXPECT_EQ(r.trials[0].angle_deg.value, (std::vector<double>{0.1, 2}));
  EXPECT_EQ(r.trials[1].angle_deg.t_s, (std::vector<double>{0}));
  EXPECT_TRUE(r.trials[0].pressure_kPa.t_s.empty());
  ASSERT_EQ(r.warnings.size(), 1u);  // the note, not one "no pressure samples" per trial
  EXPECT_NE(r.warnings[0].find("video.csv: no pressure column"), std::string::npos) << r.warnings[0];
  EXPECT_TRUE(parse_measurements_csv("trial,time_s,pressure_kPa,angle_deg\n1,0,0,0\n", "x.csv").pressure_recorded);
  EXPECT_NE(error_of("trial,time_s,Pressure (inH2O),angle_deg\n1,0,1,2\n").find("missing column 'pressure_kPa'"),
            std::string::npos);
}

// A continuous log of three staircases (no trial column, one clock): each trial 0-10-20 kPa in 4 s
// holds from the start of its 0 kPa hold, then an exponential vent (time constant 0.2 s) and the
// next trial's 0 kPa hold. The log is split where each vent has settled (within 2 % of the peak of
// the rest level: 0.2 s * ln(20/0.4) = 0.78 s after the release), not at a 0.5 s dip to 0 during a
// hold (shorter than the 1 s a rest must last) nor at a valve spike; sample times are 1/400 s, so
// the split times are known to that resolution.
TEST(MeasurementsCsv, AContinuousLogIsSplitIntoTrialsWhereThePressureIsReleased) {
  std::string text = "time_s,pressure_kPa,angle_deg\n";
  const double trial_s = 12.0 + 4.0;  // three 4 s holds, then 4 s of venting before the next 0 kPa hold
  auto pressure = [&](double t) {
    const double local = std::fmod(t, trial_s);
    if (t > 5.0 && t < 5.5) return 0.0;   // a dip during trial 1's 10 kPa hold
    if (std::abs(t - 21.0) < 0.001) return 80.0;  // a spike in trial 2's 10 kPa hold
    if (local < 12.0) return 10.0 * std::floor(local / 4.0);
    return 20.0 * std::exp(-(local - 12.0) / 0.2);
  };
  for (int i = 0; i < static_cast<int>(3 * trial_s * 400); ++i) {
    const double t = i / 400.0;
    text += csv::number_text(t) + "," + csv::number_text(pressure(t)) + "," + (i % 13 == 0 ? csv::number_text(t) : "") + "\n";
  }
  const Recording r = parse_measurements_csv(text, "log.csv");
  ASSERT_EQ(r.trials.size(), 3u);
  const double release_s = 12.0 + 0.2 * std::log(20.0 / 0.4);  // first sample within 0.4 kPa of rest
  for (int k = 0; k < 3; ++k) {
    const TrialRecording& tr = r.trials[static_cast<std::size_t>(k)];
    EXPECT_EQ(tr.trial, k + 1);
    EXPECT_NEAR(tr.pressure_kPa.t_s.front(), 0.0, 1e-9) << "trial " << k + 1;  // its clock starts at the split
    // the angle column carries the log's time: each trial's frames are the log's, shifted by its start
    for (std::size_t j = 0; j < tr.angle_deg.t_s.size(); ++j)
      ASSERT_NEAR(tr.angle_deg.value[j] - tr.angle_deg.t_s[j], k == 0 ? 0.0 : tr.angle_deg.value[0] - tr.angle_deg.t_s[0], 1e-9);
  }
  EXPECT_NEAR(r.trials[1].angle_deg.value.front(), release_s, 14.0 / 400);   // frames every 13 samples
  EXPECT_NEAR(r.trials[2].angle_deg.value.front(), trial_s + release_s, 14.0 / 400);
  EXPECT_NEAR(r.trials[2].angle_deg.value.back(), 3 * trial_s, 14.0 / 400);  // the last trial runs to the end
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_NE(r.warnings[0].find("log.csv: no trial column and time_s never restarts: the log was split into 3 trials"),
            std::string::npos) << r.warnings[0];
  // One staircase alone, or a log that ends in its rest: one trial, and the usual note.
  const Recording one = parse_measurements_csv("time_s,pressure_kPa,angle_deg\n0,0,0\n0.5,5,1\n1,5,1\n", "one.csv");
  ASSERT_EQ(one.trials.size(), 1u);
  EXPECT_EQ(one.warnings[0], "one.csv: no trial column: the trials are numbered 1, 2, ... where time_s restarts");
}

// Spreadsheets in locales with a decimal comma save "CSV" with ';' between fields; tab-separated
// exports exist too. Both read as the comma-separated file with the same numbers, with a note.
TEST(MeasurementsCsv, SemicolonOrTabSeparatedFilesWithDecimalCommasAreRead) {
  const Recording ref = parse_measurements_csv("trial,time_s,pressure_kPa,angle_deg\n1,0,0,0\n1,2.5,5,1.25\n", "ref.csv");
  for (const char* text : {"trial;time_s;pressure_kPa;angle_deg\r\n1;0;0;0\r\n1;2,5;5;1,25\r\n",
                           "trial\ttime_s\tpressure_kPa\tangle_deg\n1\t0\t0\t0\n1\t2,5\t5\t1,25\n",
                           "trial;time_s;pressure_kPa;angle_deg\n1;0;0;0\n1;2.5;5;1.25\n"}) {
    SCOPED_TRACE(text);
    const Recording r = parse_measurements_csv(text, "eu.csv");
    ASSERT_EQ(r.trials.size(), 1u);
    EXPECT_EQ(r.trials[0].pressure_kPa.t_s, ref.trials[0].pressure_kPa.t_s);
    EXPECT_EQ(r.trials[0].pressure_kPa.value, ref.trials[0].pressure_kPa.value);
    EXPECT_EQ(r.trials[0].angle_deg.value, ref.trials[0].angle_deg.value);
    ASSERT_EQ(r.warnings.size(), 1u);
    EXPECT_NE(r.warnings[0].find("eu.csv: read as "), std::string::npos) << r.warnings[0];
  }
  EXPECT_NE(parse_measurements_csv("trial;time_s;pressure_kPa;angle_deg\n1;2,5;5;1\n", "eu.csv").warnings[0].find(
                "with ',' as the decimal mark"),
            std::string::npos);
}

TEST(MeasurementsCsvErrors, MissingFileNamesThePath) {
  const std::string path = testing::temp_path("does_not_exist.csv");
  try {
    read_measurements_csv(path);
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_EQ(std::string(e.what()).rfind(path + ": cannot open the file", 0), 0u) << e.what();
  }
}

}  // namespace
}  // namespace pneufem
