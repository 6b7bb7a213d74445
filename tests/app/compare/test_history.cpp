// The study history (app/compare/history.h): what append_history writes, read_history reads back
// exactly; lines it cannot read (damaged, foreign, without an "nrmse") are skipped; null numbers
// (a non-finite NRMSE) read back as NaN; keys are found by the JSON structure, not by text search.
#include "app/compare/history.h"

#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

namespace {

namespace fs = std::filesystem;
using namespace pneufem;

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("pneufem_history_" + name);
  fs::remove_all(d);
  return d;
}

TEST(History, WhatIsAppendedReadsBackExactly) {
  const fs::path d = fresh_dir("round_trip");
  HistoryEntry a;
  a.time_utc = "2026-11-22T06:10:00Z";
  a.label = "with \"quotes\", a comma and a \\ backslash";
  a.scene_hash = "0123456789abcdef";
  a.nrmse = 1.0 / 3.0;
  a.trial_nrmse = {0.1, 2.0 / 7.0, std::nan("")};
  a.source = "diagnose";
  HistoryEntry b;
  b.label = "second";
  b.nrmse = std::nan("");
  append_history(d.string(), a);
  append_history(d.string(), b);
  const std::vector<HistoryEntry> h = read_history(d.string());
  ASSERT_EQ(h.size(), 2u);
  EXPECT_EQ(h[0].time_utc, a.time_utc);
  EXPECT_EQ(h[0].label, a.label);
  EXPECT_EQ(h[0].scene_hash, a.scene_hash);
  EXPECT_EQ(h[0].source, "diagnose");
  EXPECT_EQ(h[0].nrmse, a.nrmse);
  ASSERT_EQ(h[0].trial_nrmse.size(), 3u);
  EXPECT_EQ(h[0].trial_nrmse[1], a.trial_nrmse[1]);
  EXPECT_TRUE(std::isnan(h[0].trial_nrmse[2]));
  EXPECT_EQ(h[1].label, "second");
  EXPECT_EQ(h[1].source, "compare");
  EXPECT_TRUE(std::isnan(h[1].nrmse));
  EXPECT_TRUE(h[1].trial_nrmse.empty());
}

TEST(History, UnreadableLinesAreSkippedAndKeysAreNotFoundInsideStrings) {
  const fs::path d = fresh_dir("skip");
  fs::create_directories(d);
  std::ofstream(d / "history.jsonl")
      << "{\"label\": \"truncated\", \"nrmse\": 0.5\n"                           // damaged
      << "not json at all\n"                                                   // foreign
      << "[1, 2, 3]\n"                                                         // not an object
      << "{\"label\": \"no error\"}\n"                                         // no nrmse
      << "{\"label\": \"text \\\"nrmse\\\": 9\", \"nrmse\": \"high\"}\n"       // nrmse not a number
      << "\n"
      << "{\"source\": \"compare\", \"label\": \"\\\"nrmse\\\": 7\", \"nrmse\": 0.25, \"extra\": {\"nrmse\": 3}}\n";
  const std::vector<HistoryEntry> h = read_history(d.string());
  ASSERT_EQ(h.size(), 1u);
  EXPECT_EQ(h[0].label, "\"nrmse\": 7");
  EXPECT_EQ(h[0].nrmse, 0.25);
  EXPECT_TRUE(h[0].trial_nrmse.empty());
  EXPECT_TRUE(read_history((d / "none").string()).empty());
}

TEST(CompareHistory, AppendsAndReadsBack) {
  const fs::path d = fs::temp_directory_path() / ("pneufem_history_" + std::to_string(::getpid()));
  fs::remove_all(d);
  HistoryEntry e;
  e.time_utc = "2026-01-01T00:00:00Z";
  e.label = "quote \" and \\ backslash";
  e.scene_hash = "0123456789abcdef";
  e.nrmse = 0.125;
  e.trial_nrmse = {0.1, std::nan(""), 0.15};
  e.source = "diagnose";
  append_history(d.string(), e);
  append_history(d.string(), e);
  const std::vector<HistoryEntry> h = read_history(d.string());
  ASSERT_EQ(h.size(), 2u);
  EXPECT_EQ(h[1].label, e.label);
  EXPECT_EQ(h[1].source, "diagnose");
  EXPECT_EQ(h[1].nrmse, 0.125);
  ASSERT_EQ(h[1].trial_nrmse.size(), 3u);
  EXPECT_TRUE(std::isnan(h[1].trial_nrmse[1]));
  fs::remove_all(d);
}

}  // namespace
