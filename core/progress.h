#pragma once
// Progress of a long command on stderr: `simulate`, `compare`, `synth` and `sweep` (`diagnose`
// reports each calibration instead). On a terminal one line is redrawn in place: a bar, the share
// done, what is being done and an estimate of the time left. Elsewhere (a log file, a pipe, a batch
// job) a plain line at most every `log_every_s` seconds of wall time, so a log stays readable and
// a job that looks stuck can be told from one that works.
//
// The estimate of the time left assumes the rest goes at the average pace so far,
// elapsed (1 - f) / f, shown once 1 % is done and 2 s have passed. The share done is the caller's
// measure of the work (the physical time of the load for a run, points for a sweep), not of the
// CPU time: a ramp near the actuator's limit point costs more than a hold, so the estimate can be
// off by that ratio and is printed as an estimate ("~").
#include <chrono>
#include <string>

namespace pneufem {

class ProgressMeter {
 public:
  enum class Mode { Off, Terminal, Log };
  /// Terminal when stderr is a terminal, Log otherwise.
  static Mode for_stderr();

  ProgressMeter(std::string label, Mode mode, double log_every_s = 60.0);
  ~ProgressMeter();
  ProgressMeter(const ProgressMeter&) = delete;
  ProgressMeter& operator=(const ProgressMeter&) = delete;

  Mode mode() const { return mode_; }
  /// `fraction` of the work done (clamped to [0, 1]) and what is being done now.
  void update(double fraction, const std::string& detail);
  /// A line of its own (a fallback, a stage): on a terminal the progress line is ended first.
  void message(const std::string& text);
  /// Ends the progress line (a terminal's; nothing to do for a log).
  void done();

 private:
  std::string label_;
  Mode mode_;
  double log_every_s_;
  std::chrono::steady_clock::time_point start_, last_log_;
  bool line_open_ = false;
};

/// One progress line without the terminal's carriage return: "LABEL [#####.....]  42 %  DETAIL
/// elapsed 1 min 05 s, ~1 min 30 s left" (no bar for width 0). Pure, for tests and logs.
std::string progress_text(const std::string& label, double fraction, double elapsed_s, const std::string& detail,
                          int bar_width);

/// "12 s", "4 min 05 s", "2 h 13 min".
std::string duration_text(double seconds);

}  // namespace pneufem
