// The progress lines of long commands (core/progress.h): the text, and what each mode writes.
#include "core/progress.h"

#include <chrono>
#include <string>
#include <thread>

#include <gtest/gtest.h>

namespace pneufem {
namespace {

TEST(ProgressText, BarShareElapsedAndTheEstimateLeft) {
  // 25 % after 30 s at an even pace: 90 s left.
  EXPECT_EQ(progress_text("simulate", 0.25, 30.0, "trial 1/4", 8),
            "simulate [##......]  25 %  trial 1/4  elapsed 30 s, ~1 min 30 s left");
  // A log line has no bar.
  EXPECT_EQ(progress_text("sweep", 0.5, 3600.0, "", 0), "sweep  50 %  elapsed 1 h 00 min, ~1 h 00 min left");
  // No estimate before 1 % or 2 s, nor when done; the share is clamped and never rounded up to 100.
  EXPECT_EQ(progress_text("x", 0.005, 100.0, "", 0), "x   0 %  elapsed 1 min 40 s");
  EXPECT_EQ(progress_text("x", 0.5, 1.0, "", 0), "x  50 %  elapsed 1 s");
  EXPECT_EQ(progress_text("x", 0.999, 50.0, "", 4), "x [###.]  99 %  elapsed 50 s, ~0 s left");
  EXPECT_EQ(progress_text("x", 1.7, 50.0, "", 4), "x [####] 100 %  elapsed 50 s");
  EXPECT_EQ(progress_text("x", -1.0, 0.0, "", 2), "x [..]   0 %  elapsed 0 s");
}

TEST(ProgressText, Durations) {
  EXPECT_EQ(duration_text(0.4), "0 s");
  EXPECT_EQ(duration_text(59.4), "59 s");
  EXPECT_EQ(duration_text(61.0), "1 min 01 s");
  EXPECT_EQ(duration_text(3599.0), "59 min 59 s");
  EXPECT_EQ(duration_text(5 * 3600.0 + 7 * 60.0), "5 h 07 min");
  EXPECT_EQ(duration_text(-1.0), "?");
}

// Off writes nothing; a terminal's line is redrawn in place (carriage return, erase to the end) and
// ended once; a log gets plain lines, at most one per interval, none before the first interval.
TEST(ProgressMeter, WhatEachModeWrites) {
  testing::internal::CaptureStderr();
  {
    ProgressMeter off("x", ProgressMeter::Mode::Off);
    off.update(0.5, "half");
    off.message("stage");
  }
  EXPECT_EQ(testing::internal::GetCapturedStderr(), "");

  testing::internal::CaptureStderr();
  {
    ProgressMeter tty("run", ProgressMeter::Mode::Terminal);
    tty.update(0.1, "a");
    tty.update(0.2, "b");
    tty.message("fallback");
    tty.update(0.3, "c");
  }  // the destructor ends the open line
  const std::string t = testing::internal::GetCapturedStderr();
  EXPECT_EQ(t.find("\rrun ["), 0u) << t;
  EXPECT_NE(t.find("\033[K"), std::string::npos);
  EXPECT_NE(t.find("\nfallback\n\rrun ["), std::string::npos) << t;  // the line is ended before a message
  EXPECT_EQ(t.back(), '\n');

  testing::internal::CaptureStderr();
  {
    ProgressMeter log("run", ProgressMeter::Mode::Log, 0.2);
    log.update(0.1, "too early");  // before the first interval: nothing
    std::this_thread::sleep_for(std::chrono::milliseconds(250));
    log.update(0.5, "now");
    log.update(0.6, "again too soon");
  }
  const std::string l = testing::internal::GetCapturedStderr();
  EXPECT_EQ(l.find("too early"), std::string::npos) << l;
  EXPECT_EQ(l.find("too soon"), std::string::npos) << l;
  EXPECT_EQ(l.rfind("run  50 %  now  elapsed 0 s", 0), 0u) << l;
  EXPECT_EQ(l.find('\r'), std::string::npos);
}

}  // namespace
}  // namespace pneufem
