// pneufem diagnose on recordings GENERATED IN THIS TEST by other means than pneufem's laws (issue 35,
// items 4 and 5). The generator below starts from the small actuator's elastic angle-pressure curve
// (tests/data/othermeans/curves/small_h6.csv, a static `pneufem simulate` sweep; README.md beside it)
// and applies its effects AT THE STRUCTURE, in forms none of pneufem's laws has:
//  - creep: Fung's quasi-linear viscoelasticity of the angle with a LOGARITHMIC creep function
//    (Andrade-like, no time constant: dJ(t) = c ln(1 + t/t0)): theta = theta_e(p) + sum_k dJ(t - t_k)
//    dtheta_e_k, the elastic curve being the instantaneous response;
//  - lag: the chamber pressure behind the inlet through a first-order tube (tau);
//  - static misfits (the nulls): a 1 % stiffer silicone theta_e(0.99 p), and a geometry error that
//    bends the curve itself, theta_e(p) (1 + e (p/p_max)^2), neither a change of stiffness alone;
// through a rig unlike those of tests/data/othermeans: a slew-rate-limited valve (the inlet ramps at
// most 60 kPa/s) followed by a first-order regulator (0.08 s), pressure sampled at 1 kHz, angles at
// 60 fps with 0.03 deg tracking noise and 0.3 % outlier frames, trials of different peaks, released
// at their end. Deterministic: a fixed-seed 64-bit generator and our own normal deviates (Box-Muller
// on 53-bit uniforms), so the recording is the same on every platform.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <set>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "app/diagnose/command.h"
#include "scenes/scene.h"
#include "tests/app/diagnose/run_and_print.h"

namespace fs = std::filesystem;

namespace pneufem {
namespace {

/// theta_e(p): a monotone cubic (Fritsch-Carlson) through a static curve's points (kPa, deg).
class ElasticCurve {
 public:
  explicit ElasticCurve(const std::string& csv) {
    std::ifstream in(csv);
    if (!in) throw std::runtime_error("cannot read " + csv);
    std::string line;
    std::getline(in, line);  // header
    while (std::getline(in, line)) {
      double p = 0.0, a = 0.0;
      if (std::sscanf(line.c_str(), "%lf,%lf", &p, &a) == 2 && (p_.empty() || p > p_.back())) p_.push_back(p), a_.push_back(a);
    }
    const std::size_t n = p_.size();
    if (n < 3) throw std::runtime_error("too few points in " + csv);
    std::vector<double> d(n - 1);
    for (std::size_t k = 0; k + 1 < n; ++k) d[k] = (a_[k + 1] - a_[k]) / (p_[k + 1] - p_[k]);
    m_.assign(n, 0.0);
    m_[0] = d[0], m_[n - 1] = d[n - 2];
    for (std::size_t k = 1; k + 1 < n; ++k)
      if (d[k - 1] * d[k] > 0.0) m_[k] = 2.0 / (1.0 / d[k - 1] + 1.0 / d[k]);
  }
  double operator()(double p) const {
    p = std::clamp(p, p_.front(), p_.back());
    const std::size_t k = std::min<std::size_t>(std::upper_bound(p_.begin(), p_.end(), p) - p_.begin() - 1, p_.size() - 2);
    const double h = p_[k + 1] - p_[k], t = (p - p_[k]) / h;
    return (2 * t * t * t - 3 * t * t + 1) * a_[k] + (t * t * t - 2 * t * t + t) * h * m_[k] +
           (-2 * t * t * t + 3 * t * t) * a_[k + 1] + (t * t * t - t * t) * h * m_[k + 1];
  }
  double peak_kPa() const { return p_.back(); }

 private:
  std::vector<double> p_, a_, m_;
};

/// Fixed-seed deviates, the same on every platform (the standard distributions are not).
class Deviates {
 public:
  explicit Deviates(std::uint64_t seed) : s_(seed) {}
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }  // [0, 1)
  double normal() {
    const double u1 = 1.0 - uniform(), u2 = uniform();
    return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
  }

 private:
  std::uint64_t next() {  // splitmix64
    std::uint64_t z = (s_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  std::uint64_t s_;
};

struct Trial {
  std::vector<double> levels_kPa;  ///< commanded, each held hold_s; then released to 0 for hold_s
  double hold_s = 2.0;
};

struct Hidden {
  double log_creep_c = 0.0, log_creep_t0_s = 0.3;  ///< dJ(t) = c ln(1 + t/t0); c = 0: none
  double lag_tau_s = 0.0;                          ///< first-order tube; 0: none
  double stiffness_factor = 1.0;                   ///< theta_e(k p): k < 1 stiffer
  double bend_error = 0.0;                         ///< theta_e(p) (1 + e (p/p_max)^2)
};

constexpr double kDt = 0.002;  // the rig's and the structure's step (s)

/// The recording (canonical CSV: trial,time_s,pressure_kPa,angle_deg) of `trials` with `hidden`,
/// written to `path`.
void write_recording(const std::string& path, const std::vector<Trial>& trials, const Hidden& h, std::uint64_t seed) {
  const ElasticCurve curve(std::string(PNEUFEM_TEST_DATA_DIR) + "/othermeans/curves/small_h6.csv");
  double p_ref = 0.0;
  for (const Trial& t : trials) p_ref = std::max(p_ref, *std::max_element(t.levels_kPa.begin(), t.levels_kPa.end()));
  const auto theta_e = [&](double p) {
    const double q = std::max(0.0, p);
    return curve(h.stiffness_factor * q) * (1.0 + h.bend_error * (q / p_ref) * (q / p_ref));
  };
  // The rig and the structure, continuous over the trials.
  std::vector<int> trial_of;
  std::vector<double> time_in_trial, inlet, theta;
  double valve = 0.0, regulated = 0.0, chamber = 0.0;
  constexpr double kSlew = 60.0, kRegulatorTau = 0.08;  // kPa/s, s
  std::vector<double> d_theta;  // the elastic angle's increments, for the creep's convolution
  double theta_prev = 0.0;
  for (std::size_t k = 0; k < trials.size(); ++k) {
    std::vector<double> levels = trials[k].levels_kPa;
    levels.push_back(0.0);  // released at the end of the trial
    const int steps = static_cast<int>(std::lround(static_cast<double>(levels.size()) * trials[k].hold_s / kDt));
    for (int i = 0; i < steps; ++i) {
      const double t = i * kDt;
      const double u = levels[std::min(levels.size() - 1, static_cast<std::size_t>(t / trials[k].hold_s + 1e-9))];
      valve += std::clamp(u - valve, -kSlew * kDt, kSlew * kDt);
      regulated += (valve - regulated) * (1.0 - std::exp(-kDt / kRegulatorTau));
      chamber = h.lag_tau_s > 0.0 ? chamber + (regulated - chamber) * (1.0 - std::exp(-kDt / h.lag_tau_s)) : regulated;
      const double te = theta_e(chamber);
      d_theta.push_back(te - theta_prev);
      theta_prev = te;
      trial_of.push_back(static_cast<int>(k) + 1);
      time_in_trial.push_back(t);
      inlet.push_back(regulated);
      theta.push_back(te);
    }
  }
  if (h.log_creep_c > 0.0) {  // Fung QLV with a logarithmic creep function (direct convolution)
    const std::size_t n = theta.size();
    std::vector<double> J(n);
    for (std::size_t i = 0; i < n; ++i) J[i] = h.log_creep_c * std::log1p(i * kDt / h.log_creep_t0_s);
    for (std::size_t i = 0; i < n; ++i) {
      double extra = 0.0;
      for (std::size_t j = 0; j <= i; ++j) extra += J[i - j] * d_theta[j];
      theta[i] += extra;
    }
  }
  // Sampling: pressure at 1 kHz, angles at 60 fps, by linear interpolation of the 2 ms record.
  Deviates rng(seed);
  std::ostringstream out;
  out << "trial,time_s,pressure_kPa,angle_deg\n";
  char buf[96];
  std::size_t first = 0;
  while (first < trial_of.size()) {
    std::size_t last = first;
    while (last + 1 < trial_of.size() && trial_of[last + 1] == trial_of[first]) ++last;
    const double dur = time_in_trial[last];
    const auto at = [&](const std::vector<double>& v, double t) {
      const double x = t / kDt;
      const std::size_t i = std::min(first + static_cast<std::size_t>(x), last - 1);
      const double w = x - static_cast<double>(i - first);
      return (1.0 - w) * v[i] + w * v[i + 1];
    };
    const int n_p = static_cast<int>(dur * 1000.0), n_a = static_cast<int>(dur * 60.0);
    for (int i = 0, j = 0; i <= n_p || j <= n_a;) {
      const double tp = i * 1e-3, ta = j / 60.0;
      if (i <= n_p && (j > n_a || tp <= ta)) {
        std::snprintf(buf, sizeof buf, "%d,%.4f,%.4f,\n", trial_of[first], tp, at(inlet, tp) + 0.05 * rng.normal());
        ++i;
      } else {
        double a = at(theta, ta) + 0.03 * rng.normal();
        if (rng.uniform() < 0.003) a += (rng.uniform() < 0.5 ? -1.0 : 1.0) * (10.0 + 30.0 * rng.uniform());
        std::snprintf(buf, sizeof buf, "%d,%.4f,,%.5f\n", trial_of[first], ta, a);
        ++j;
      }
      out << buf;
    }
    first = last + 1;
  }
  std::ofstream f(path);
  f << out.str();
  if (!f) throw std::runtime_error("cannot write " + path);
}

// The actuator of the curve (scenes/examples/small_actuator.toml); the recording's own pressure
// drives the model.
const std::vector<std::string> kScene = {"geometry.chambers=5", "mesh.h_mm=6.0",  "load.max_kPa=30.0",
                                         "load.step_kPa=10.0",  "load.hold_s=4.0", "load.trials=3"};

DiagnosisResult diagnose_generated(const std::string& name, const std::vector<Trial>& trials, const Hidden& h,
                                   std::uint64_t seed, std::vector<std::string> candidates, int max_effects) {
  const fs::path dir = fs::temp_directory_path() / ("pneufem_diag_generated_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  DiagnoseOptions o;
  o.data_path = (dir / "recording.csv").string();
  write_recording(o.data_path, trials, h, seed);
  o.candidates = std::move(candidates);
  o.max_effects = max_effects;
  o.out_dir = (dir / "out").string();
  o.cache_dir = (fs::temp_directory_path() / "pneufem_diagnose_cache").string();  // shared elastic work
  return test::run_and_print_diagnosis(name, kScene, o);
}

// The generator itself, against what it was given: the elastic curve at its own points, the slew
// limit and the release, and a creep that only adds to the instantaneous angle.
TEST(GeneratedRecording, TheGeneratorReproducesItsInputs) {
  const ElasticCurve curve(std::string(PNEUFEM_TEST_DATA_DIR) + "/othermeans/curves/small_h6.csv");
  EXPECT_NEAR(curve(0.5), 0.028882, 1e-9);  // a point of the CSV: the cubic interpolates it exactly
  EXPECT_LT(curve(10.0), curve(10.25));      // monotone between points
  const fs::path p = fs::temp_directory_path() / "pneufem_generated_check.csv";
  write_recording(p.string(), {{{20.0}, 2.0}}, Hidden{}, 1);
  std::ifstream in(p);
  std::string line;
  std::getline(in, line);
  ASSERT_EQ(line, "trial,time_s,pressure_kPa,angle_deg");
  double p_at_0_2 = -1.0, p_end_hold = -1.0, a_end_hold = -1.0;
  int pressure_rows = 0, angle_rows = 0;
  while (std::getline(in, line)) {
    int tr = 0;
    double t = 0.0, v = 0.0;
    if (std::sscanf(line.c_str(), "%d,%lf,%lf,", &tr, &t, &v) == 3 && line.back() == ',') {
      ++pressure_rows;
      if (std::abs(t - 0.2) < 1e-4) p_at_0_2 = v;  // samples 1 ms apart, times printed to 0.1 ms
      if (std::abs(t - 1.99) < 1e-4) p_end_hold = v;
    } else if (std::sscanf(line.c_str(), "%d,%lf,,%lf", &tr, &t, &v) == 3) {
      ++angle_rows;
      if (std::abs(t - 119.0 / 60.0) < 1e-3) a_end_hold = v;  // frames 16.7 ms apart
    }
  }
  // 2 s at 20 kPa and 2 s released (the record ends one 2 ms step before 4 s): ~4000 samples at
  // 1 kHz and ~240 frames at 60 fps.
  EXPECT_NEAR(pressure_rows, 3998, 2);
  EXPECT_NEAR(angle_rows, 240, 1);
  // The valve ramps at 60 kPa/s: at 0.2 s the inlet is below 12 kPa (regulator behind it), not at 20.
  EXPECT_LT(p_at_0_2, 12.0 + 0.3);  // 0.3 kPa: 6 sigma of the sensor noise
  EXPECT_NEAR(p_end_hold, 20.0, 0.3);
  EXPECT_NEAR(a_end_hold, curve(20.0), 0.2);  // 0.2 deg: 6 sigma of the tracking noise (an outlier is 10+)
}

// ---- Item 4: a static misfit only, generated here (a 2 % stiffer silicone and a geometry error that
// bends the curve up to 5 % at the peak pressure), against the candidate a static misfit is taken for
// (stiffness) and those that could absorb one (creep, Mullins, fatigue): nothing is named. Measured
// (2026-11-29): baseline 0.0110 at a 0.0087 floor; stiffness 0.0105 (dAIC -79, scale 0.997), fatigue
// 0.0108 (dAIC -19), creep and Mullins with every constant at a bound; nothing significant. With a
// 1 % stiffer silicone and a 3 % bend: 0.0107 -> stiffness 0.0099 (dAIC -169), fatigue 0.0102 (dAIC
// -69), nothing significant. 75-77 s of a machine at load 8-9, the elastic path from the cache.
TEST(GeneratedNull, AStaticMisfitThatIsNotAStiffnessNamesNothing) {
  const std::vector<Trial> trials = {{{8.0, 16.0, 24.0}, 2.0}, {{12.0, 24.0}, 2.0}, {{8.0, 16.0, 24.0}, 2.0}};
  Hidden h;
  h.stiffness_factor = 0.98;
  h.bend_error = 0.05;
  const DiagnosisResult r = diagnose_generated("null_bend", trials, h, 7,
                                               {"stiffness", "viscoelastic_instantaneous", "mullins", "fatigue"}, 1);
  EXPECT_TRUE(r.selected.empty()) << r.missing_effect;
  EXPECT_TRUE(r.equivalent_models.empty());
  // The cost of the one round that ran is stated: its four candidates and their calibrations' runs
  // (each at most the 60-run budget plus the profiled re-calibration of a history effect).
  ASSERT_EQ(r.round_costs.size(), 1u);
  EXPECT_EQ(r.round_costs[0].round, 1);
  EXPECT_EQ(r.round_costs[0].candidates, 4);
  EXPECT_GE(r.round_costs[0].runs, 4 * 10);
  EXPECT_LE(r.round_costs[0].runs, 4 * 2 * 60 + 4 * 30);  // + the trade-off walks of two-constant candidates
  EXPECT_GT(r.round_costs[0].wall_s, 0.0);
}

// ---- Item 5: two effects together, generated here: logarithmic creep (no time constant; the
// catalog's creep is one Prony term) behind a first-order lag of 0.25 s, over three trials of
// different peaks. Both must be named (creep in either convention), nothing else, and the error
// after the selection must be at most 0.4x the baseline's. Measured (2026-11-29): round 1 the lag
// (NRMSE 0.1146 -> 0.0525, tau 0.245 s for the truth's 0.25, tau2 0.13 s: over-damped, taking part of
// the creep), creep alone doing nothing there (dAIC +1.7: behind the lag its rise is hidden); round 2
// instantaneous creep (-> 0.0121 at a 0.0066 floor, 0.11x; gamma 0.10, tau 4.9 s for a log creep of
// c 0.04, t0 0.3 s: other laws), stiffness not (0.0351). 370 s on a machine at load 9 with the
// elastic path traced (an empty cache).
TEST(GeneratedRecording, LogarithmicCreepBehindALagAreBothNamed) {
  const std::vector<Trial> trials = {{{10.0, 20.0, 28.0}, 2.5}, {{14.0, 28.0}, 2.5}};
  Hidden h;
  h.log_creep_c = 0.04;
  h.lag_tau_s = 0.25;
  // Candidates: the two effects and the static stand-in for either (a stiffer model takes part of a
  // creep's settled angle); the whole catalog is the DISABLED_ tests' of test_othermeans_recordings.
  const DiagnosisResult r =
      diagnose_generated("logcreep_lag", trials, h, 11, {"stiffness", "viscoelastic_instantaneous", "pressure_lag"}, 2);
  const std::set<std::string> sel(r.selected.begin(), r.selected.end());
  EXPECT_TRUE(sel.count("pressure_lag")) << "lag not named";
  EXPECT_TRUE(sel.count("viscoelastic_instantaneous") || sel.count("viscoelastic")) << "creep not named";
  for (const std::string& s : r.selected)
    EXPECT_TRUE(s == "pressure_lag" || s == "viscoelastic_instantaneous" || s == "viscoelastic") << "spurious: " << s;
  EXPECT_LE(r.final_nrmse, 0.4 * r.baseline_nrmse);
  EXPECT_EQ(r.final_parameters, 4);  // tau, tau2 and gamma, tau: the count equivalent_models compares with
  // ... and diagnosis.json carries the model-equivalence report (empty here: no other combination
  // passed its round's tests within 25 % of the final RSS; the lag alone is 19x the final RSS).
  EXPECT_TRUE(r.equivalent_models.empty());
  std::ifstream in(fs::temp_directory_path() / "pneufem_diag_generated_logcreep_lag" / "out" / "diagnosis.json");
  const std::string json((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_NE(json.find("\"equivalent_models\": []"), std::string::npos);
  EXPECT_NE(json.find("\"final_parameters\": 4"), std::string::npos);
}

}  // namespace
}  // namespace pneufem
