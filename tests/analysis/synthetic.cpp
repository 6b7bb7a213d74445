#include "tests/analysis/synthetic.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <random>
#include <stdexcept>

#include <unistd.h>

namespace pneufem::testing {

namespace {

/// Unit step response: first-order rise plus an overshoot bump (s / s_o) e^(1 - s / s_o), which
/// peaks at s_o; its onset is exactly s = 0.
double response(double s, double tau, double overshoot, double s_o) {
  if (s <= 0.0) return 0.0;
  return -std::expm1(-s / tau) + overshoot * (s / s_o) * std::exp(1.0 - s / s_o);
}

/// Static pressure -> angle curve (deg), mildly stiffening like a pneu-net's.
double static_angle(double p_kPa) { return 1.2 * p_kPa + 0.04 * p_kPa * p_kPa; }

double command_time(const StaircaseSpec& spec, std::size_t k) {
  return static_cast<double>(k) * spec.hold_s + spec.command_phase_s;
}

}  // namespace

double staircase_pressure(const StaircaseSpec& spec, double t) {
  double p = spec.levels_kPa.front();
  for (std::size_t k = 1; k < spec.levels_kPa.size(); ++k)
    p += (spec.levels_kPa[k] - spec.levels_kPa[k - 1]) *
         response(t - command_time(spec, k), spec.tau_s, spec.overshoot, spec.overshoot_s);
  return p;
}

double staircase_angle(const StaircaseSpec& spec, double t) {
  double a = static_angle(spec.levels_kPa.front());
  for (std::size_t k = 1; k < spec.levels_kPa.size(); ++k)
    a += (static_angle(spec.levels_kPa[k]) - static_angle(spec.levels_kPa[k - 1])) *
         response(t - command_time(spec, k), spec.angle_tau_s, 0.0, 1.0);
  return a;
}

TrialRecording make_staircase_trial(const StaircaseSpec& spec, int trial, unsigned seed, StaircaseTruth* truth,
                                    Series* clean_angle) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, 1.0);
  const double duration = static_cast<double>(spec.levels_kPa.size()) * spec.hold_s;
  TrialRecording tr;
  tr.trial = trial;
  const auto np = static_cast<std::size_t>(std::floor(duration * spec.rate_Hz));
  for (std::size_t i = 0; i < np; ++i) {
    const double t = static_cast<double>(i) / spec.rate_Hz;
    tr.pressure_kPa.t_s.push_back(t);
    tr.pressure_kPa.value.push_back(staircase_pressure(spec, t) + spec.noise_kPa * noise(rng));
  }
  const auto na = static_cast<std::size_t>(std::floor(duration * spec.fps));
  for (std::size_t j = 0; j < na; ++j) {
    const double t = static_cast<double>(j) / spec.fps;
    tr.angle_deg.t_s.push_back(t);
    tr.angle_deg.value.push_back(staircase_angle(spec, t) + spec.angle_noise_deg * noise(rng));
  }
  if (clean_angle) *clean_angle = tr.angle_deg;
  for (std::size_t j : spec.outlier_frames)
    if (j < na) tr.angle_deg.value[j] += 50.0;
  if (truth) {
    truth->command_s.assign(1, 0.0);
    truth->level_kPa = spec.levels_kPa;
    for (std::size_t k = 1; k < spec.levels_kPa.size(); ++k) truth->command_s.push_back(command_time(spec, k));
  }
  return tr;
}

namespace {

/// The test process's scratch directory, removed with everything in it when the process ends.
struct ScratchDir {
  std::filesystem::path path =
      std::filesystem::temp_directory_path() / ("pneufem_measurements_" + std::to_string(::getpid()));
  ScratchDir() { std::filesystem::create_directories(path); }
  ~ScratchDir() {
    std::error_code ec;
    std::filesystem::remove_all(path, ec);
  }
};

}  // namespace

std::string temp_path(const std::string& name) {
  static ScratchDir dir;
  static std::atomic<int> counter{0};
  return (dir.path / (std::to_string(counter++) + "_" + name)).string();
}

void write_text(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary);
  out.write(text.data(), static_cast<std::streamsize>(text.size()));
  if (!out) throw std::runtime_error("cannot write test file " + path);
}

}  // namespace pneufem::testing
