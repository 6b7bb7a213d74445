#include "core/progress.h"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace pneufem {

ProgressMeter::Mode ProgressMeter::for_stderr() { return isatty(STDERR_FILENO) ? Mode::Terminal : Mode::Log; }

ProgressMeter::ProgressMeter(std::string label, Mode mode, double log_every_s)
    : label_(std::move(label)), mode_(mode), log_every_s_(log_every_s), start_(std::chrono::steady_clock::now()),
      last_log_(start_) {}

ProgressMeter::~ProgressMeter() { done(); }

void ProgressMeter::update(double fraction, const std::string& detail) {
  if (mode_ == Mode::Off) return;
  const auto now = std::chrono::steady_clock::now();
  const double elapsed = std::chrono::duration<double>(now - start_).count();
  if (mode_ == Mode::Terminal) {
    std::fprintf(stderr, "\r%s\033[K", progress_text(label_, fraction, elapsed, detail, 20).c_str());
    std::fflush(stderr);
    line_open_ = true;
    return;
  }
  if (log_every_s_ <= 0.0 || std::chrono::duration<double>(now - last_log_).count() < log_every_s_) return;
  last_log_ = now;
  std::fprintf(stderr, "%s\n", progress_text(label_, fraction, elapsed, detail, 0).c_str());
  std::fflush(stderr);
}

void ProgressMeter::message(const std::string& text) {
  if (mode_ == Mode::Off) return;
  done();
  std::fprintf(stderr, "%s\n", text.c_str());
}

void ProgressMeter::done() {
  if (line_open_) std::fprintf(stderr, "\n");
  line_open_ = false;
}

std::string duration_text(double s) {
  char b[48];
  if (!std::isfinite(s) || s < 0.0) return "?";
  if (s < 60.0) {
    std::snprintf(b, sizeof b, "%.0f s", s);
  } else if (s < 3600.0) {
    const long t = std::lround(s);
    std::snprintf(b, sizeof b, "%ld min %02ld s", t / 60, t % 60);
  } else {
    const long m = std::lround(s / 60.0);
    std::snprintf(b, sizeof b, "%ld h %02ld min", m / 60, m % 60);
  }
  return b;
}

std::string progress_text(const std::string& label, double fraction, double elapsed_s, const std::string& detail,
                          int bar_width) {
  const double f = std::isfinite(fraction) ? std::clamp(fraction, 0.0, 1.0) : 0.0;
  std::string s = label;
  if (bar_width > 0) {
    const int full = static_cast<int>(std::floor(f * bar_width + 1e-9));
    s += " [" + std::string(static_cast<std::size_t>(full), '#') + std::string(static_cast<std::size_t>(bar_width - full), '.') + "]";
  }
  char b[64];
  std::snprintf(b, sizeof b, " %3.0f %%", std::floor(100.0 * f));
  s += b;
  if (!detail.empty()) s += "  " + detail;
  s += "  elapsed " + duration_text(elapsed_s);
  if (f >= 0.01 && f < 1.0 && elapsed_s >= 2.0) s += ", ~" + duration_text(elapsed_s * (1.0 - f) / f) + " left";
  return s;
}

}  // namespace pneufem
