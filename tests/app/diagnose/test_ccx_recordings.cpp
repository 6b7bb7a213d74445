// pneufem diagnose on recordings it did not make: the angle is CalculiX's static solution of a
// gmsh-meshed pneu-net (tests/data/ccx_gmsh), read as a curve theta_e(p) and played back through
// a rig written here — a pressure regulator with overshoot, a chamber-pressure lag or none, sensor
// noise at 100 Hz, video at 30 fps — nothing of pneufem's synth, materials or solver. The model is
// the deck's own scene. Before the pressure breakpoints were fitted to the record (app/simulate/drive.h) and
// the reduced model's elastic curve was made exact between its samples (engine/path_model.cpp), the
// control recording was "missing" a stiffness change and fatigue.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "app/diagnose/command.h"
#include "scenes/scene.h"

namespace fs = std::filesystem;

namespace pneufem {
namespace {

const std::string kData = std::string(PNEUFEM_TEST_DATA_DIR) + "/ccx_gmsh/";

/// CalculiX's angle (plane fit, deg) against pressure (kPa), monotone cubic (Fritsch-Carlson).
struct Curve {
  std::vector<double> p, a, m;
  explicit Curve(const std::string& csv) {
    std::ifstream in(csv);
    std::string line;
    std::getline(in, line);  // header: pressure_kPa,angle_kabsch_deg,angle_planefit_deg,...
    while (std::getline(in, line)) {
      std::stringstream s(line);
      std::string c0, c1, c2;
      std::getline(s, c0, ',');
      std::getline(s, c1, ',');
      std::getline(s, c2, ',');
      p.push_back(std::stod(c0));
      a.push_back(std::stod(c2));
    }
    const std::size_t n = p.size();
    std::vector<double> d(n - 1);
    for (std::size_t k = 0; k + 1 < n; ++k) d[k] = (a[k + 1] - a[k]) / (p[k + 1] - p[k]);
    m.assign(n, 0.0);
    m.front() = d.front();
    m.back() = d.back();
    for (std::size_t k = 1; k + 1 < n; ++k)
      if (d[k - 1] * d[k] > 0) m[k] = 2.0 / (1.0 / d[k - 1] + 1.0 / d[k]);  // equal spacing
  }
  double operator()(double x) const {
    x = std::clamp(x, p.front(), p.back());
    const std::size_t k = std::min<std::size_t>(std::upper_bound(p.begin(), p.end(), x) - p.begin() - 1, p.size() - 2);
    const double h = p[k + 1] - p[k], t = (x - p[k]) / h;
    return (2 * t * t * t - 3 * t * t + 1) * a[k] + (t * t * t - 2 * t * t + t) * h * m[k] +
           (-2 * t * t * t + 3 * t * t) * a[k + 1] + (t * t * t - t * t) * h * m[k + 1];
  }
};

/// Writes a two-trial staircase recording 0 -> 45 kPa (5 kPa steps, `hold_s` holds) and returns its path.
std::string make_recording(const std::string& name, double lag_s, double hold_s) {
  const Curve theta(kData + "ccx_angles.csv");
  std::uint64_t state = 2026;
  auto uniform = [&state] {
    state = state * 6364136223846793005ULL + 1442695040888963407ULL;
    return (static_cast<double>(state >> 11) + 0.5) / 9007199254740992.0;
  };
  auto gauss = [&] { return std::sqrt(-2 * std::log(uniform())) * std::cos(2 * M_PI * uniform()); };
  const double dt = 0.01, wn = 2 * M_PI * 1.5, zeta = 0.8;  // regulator: 1.5 Hz, ~1.5 % overshoot
  const fs::path path = fs::temp_directory_path() / ("pneufem_ccx_rec_" + name + ".csv");
  std::ofstream out(path);
  out << "trial,time_s,pressure_kPa,angle_deg\n";
  for (int trial = 1; trial <= 2; ++trial) {
    const int n = static_cast<int>(std::lround(10 * hold_s / dt));
    double x = 0, v = 0, pc = 0;
    int frame = 0;
    for (int i = 0; i <= n; ++i) {
      const double t = i * dt;
      const double u = 5.0 * std::min(9, static_cast<int>(t / hold_s));
      if (i > 0) {
        v += (wn * wn * (u - x) - 2 * zeta * wn * v) * dt;
        x += v * dt;
        pc += lag_s > 0 ? (x - pc) * (1 - std::exp(-dt / lag_s)) : x - pc;
      }
      out << trial << ',' << t << ',' << x + 0.08 * gauss() << ",\n";
      while (frame / 30.0 <= t + 1e-12 && frame / 30.0 < 10 * hold_s) {
        out << trial << ',' << frame / 30.0 << ",," << theta(std::max(pc, 0.0)) + 0.08 * gauss() << '\n';
        ++frame;
      }
    }
  }
  return path.string();
}

DiagnosisResult diagnose(const std::string& name, double lag_s) {
  DiagnoseOptions o;
  o.data_path = make_recording(name, lag_s, 5.0);
  o.out_dir = (fs::temp_directory_path() / ("pneufem_ccx_diag_" + name)).string();
  fs::remove_all(o.out_dir);
  // A static candidate, a history one and the lag: what a static misfit (the reduced model's own
  // error) would be taken for, what noise on a creep-free record could pass for, and the truth.
  o.candidates = {"stiffness", "viscoelastic", "pressure_lag"};
  o.cache_dir = (fs::temp_directory_path() / "pneufem_diagnose_cache").string();  // shared elastic work (app/simulate/result_cache.h)
  return run_diagnosis(Scene::load(kData + "scene.toml"), o);
}

TEST(DiagnoseCalculixRecording, NoHiddenEffectNamesNone) {
  const DiagnosisResult r = diagnose("none", 0.0);
  // The model is CalculiX's to 0.08 %, so its error is nearly the tracking noise: measured 1.21 x
  // the noise floor here (0.0018; the ramps, a tenth of these 5 s steps, carry the reduced model's
  // and the pressure breakpoints' small errors), 1.07 x on a three-trial recording with 10 s holds,
  // where it was 2.7 x before the fixes. Bound 1.5 x.
  EXPECT_LT(r.baseline_nrmse, 1.5 * r.noise_floor_nrmse);
  EXPECT_TRUE(r.selected.empty()) << r.missing_effect;
  EXPECT_TRUE(r.missing_effect.empty()) << r.missing_effect;
}

TEST(DiagnoseCalculixRecording, HiddenLagIsNamedWithItsTimeConstant) {
  const DiagnosisResult r = diagnose("lag", 1.0);
  ASSERT_FALSE(r.selected.empty());
  EXPECT_EQ(r.missing_effect, "pressure_lag");
  ASSERT_FALSE(r.candidates.empty());
  const CandidateResult& c = r.candidates.front();
  ASSERT_EQ(c.effect, "pressure_lag");
  // tau 1.0 s: measured 0.995 s on the three-trial recording; 5 % covers the regulator's
  // overshoot being seen through the lag and the noise on two trials.
  EXPECT_NEAR(c.params.at(0), 1.0, 0.05);
  EXPECT_LT(r.final_nrmse, 1.2 * r.noise_floor_nrmse);
}

}  // namespace
}  // namespace pneufem
