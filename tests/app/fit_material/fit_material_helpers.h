#pragma once
// Test data the fit-material tests share (test_command.cpp, test_test_data.cpp,
// test_deck_test_data.cpp): files written under the test temp directory, Treloar's data as CSV.
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "app/fit_material/test_data.h"

namespace pneufem::test::fit_material {

using fit::TestMode;

inline const std::string kData = PNEUFEM_TEST_DATA_DIR;
inline const std::string kEcoflex = kData + "/soro-materials-db/ecoflex_00-50.csv";

/// Writes `text` to a fresh file under the test temp directory and returns its path.
inline std::string write_temp(const std::string& name, const std::string& text) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / "pneufem_fit_material";
  std::filesystem::create_directories(dir);
  const std::filesystem::path p = dir / name;
  std::ofstream(p) << text;
  return p.string();
}

/// A Treloar .dat file (stretch, MPa; no header) as CSV with the header 'stretch,stress_MPa'.
inline std::string treloar_csv(const std::string& mode) {
  std::ifstream in(kData + "/treloar1944/treloar_" + mode + ".dat");
  std::string text = "stretch,stress_MPa\n";
  for (std::string l, P; in >> l >> P;) text += l + "," + P + "\n";
  return write_temp(mode + ".csv", text);
}

inline fit::TestCurve read(const std::string& path, TestMode m = TestMode::uniaxial) {
  std::vector<std::string> notes;
  return read_test_csv(path, m, notes);
}

}  // namespace pneufem::test::fit_material
