// app/compare/dlc_map.h: angles from DeepLabCut tracks (compare --dlc-map) - a map of two fixed
// and two tip body parts replaces the angles of its trials with the angle between the two
// directions, on the recording's time axis; errors name the map file, line and key.
#include "app/compare/dlc_map.h"

#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "analysis/measurements.h"
#include "core/errors.h"

namespace pneufem {
namespace {

namespace fs = std::filesystem;

/// DeepLabCut CSV: fixed parts f1, f2 straight down the screen, tip parts t1, t2 rotated by
/// theta_k counter-clockwise on the screen (image y points down).
std::string dlc_text(const std::vector<double>& theta_deg) {
  std::string s = "scorer";
  for (int i = 0; i < 12; ++i) s += ",net";
  s += "\nbodyparts,f1,f1,f1,f2,f2,f2,t1,t1,t1,t2,t2,t2\ncoords";
  for (int i = 0; i < 4; ++i) s += ",x,y,likelihood";
  s += "\n";
  char buf[256];
  for (std::size_t k = 0; k < theta_deg.size(); ++k) {
    const double a = theta_deg[k] * 3.14159265358979323846 / 180.0;
    // (X, Y) with Y up: fixed direction (0, -1); tip direction (sin a, -cos a) = (0, -1) turned by a.
    const double tx = 200.0, ty = -300.0, dx = 50.0 * std::sin(a), dy = -50.0 * std::cos(a);
    std::snprintf(buf, sizeof buf, "%zu,100,100,0.99,100,200,0.99,%.6f,%.6f,0.99,%.6f,%.6f,0.99\n", k, tx, -ty, tx + dx,
                  -(ty + dy));
    s += buf;
  }
  return s;
}

TEST(CompareDlc, MapReplacesTheAnglesOfItsTrials) {
  const fs::path d = fs::temp_directory_path() / ("pneufem_dlc_" + std::to_string(::getpid()));
  fs::remove_all(d);
  fs::create_directories(d);
  std::vector<double> theta(40, 0.0);
  for (std::size_t k = 15; k < theta.size(); ++k) theta[k] = 3.0 * static_cast<double>(k - 15);
  std::ofstream(d / "t2.csv") << dlc_text(theta);
  std::ofstream(d / "map.toml") << "fixed_parts = [\"f1\", \"f2\"]\ntip_parts = [\"t1\", \"t2\"]\nfps = 20.0\n"
                                   "[[trials]]\ntrial = 2\nfile = \"t2.csv\"\nt0_s = 0.5\n";
  Recording p;
  p.source = "p.csv";
  for (int n = 1; n <= 2; ++n) {
    TrialRecording tr;
    tr.trial = n;
    tr.pressure_kPa = {{0.0, 1.0, 2.0}, {0.0, 5.0, 5.0}};
    tr.angle_deg = {{0.0}, {7.0}};
    p.trials.push_back(tr);
  }
  const Recording r = merge_deeplabcut(p, (d / "map.toml").string());
  EXPECT_EQ(r.trials[0].angle_deg.value, std::vector<double>{7.0});  // unmapped trial keeps its CSV angle
  const Series& a = r.trials[1].angle_deg;
  ASSERT_EQ(a.t_s.size(), theta.size());
  // Coordinates carry 6 decimals on 50-100 px segments: ~1e-8 rad, so 1e-4 deg is rounding only.
  for (std::size_t k = 0; k < theta.size(); ++k) {
    EXPECT_NEAR(a.t_s[k], 0.5 + static_cast<double>(k) / 20.0, 1e-12);
    EXPECT_NEAR(a.value[k], theta[k], 1e-4) << "frame " << k;
  }
  // Errors name the map file, line and key.
  std::ofstream(d / "bad.toml") << "fixed_parts = [\"f1\", \"f2\"]\ntip_parts = [\"t1\", \"t2\"]\nfsp = 30\n";
  try {
    merge_deeplabcut(p, (d / "bad.toml").string());
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad.toml:3:1: key 'fsp': unknown key"), std::string::npos) << e.what();
  }
  std::ofstream(d / "bad2.toml") << "fixed_parts = [\"f1\", \"f2\"]\ntip_parts = [\"t1\", \"t2\"]\n"
                                    "[[trials]]\ntrial = 9\nfile = \"t2.csv\"\n";
  try {
    merge_deeplabcut(p, (d / "bad2.toml").string());
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("bad2.toml:4:9: key 'trials.trial': trial 9 has no pressure in p.csv"),
              std::string::npos)
        << e.what();
  }
  fs::remove_all(d);
}

}  // namespace
}  // namespace pneufem
