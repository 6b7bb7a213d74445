// write_file_atomic (core/atomic_file.h): the whole text or the previous file, never a part; a
// failure names the path and leaves no temporary file behind.
#include "core/atomic_file.h"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <stdexcept>
#include <string>

#include <gtest/gtest.h>

namespace {

namespace fs = std::filesystem;

fs::path fresh_dir(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("pneufem_core_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(AtomicFile, WritesAndReplacesTheWholeTextWithoutATemporaryFileLeft) {
  const fs::path d = fresh_dir("write");
  const std::string path = (d / "out.txt").string();
  pneufem::write_file_atomic(path, "first\n");
  EXPECT_EQ(slurp(path), "first\n");
  const std::string binary("a\0b\r\n", 5);
  pneufem::write_file_atomic(path, binary);
  EXPECT_EQ(slurp(path), binary);
  EXPECT_FALSE(fs::exists(path + ".tmp"));
}

TEST(AtomicFile, AMissingDirectoryIsAnErrorNamingThePath) {
  const fs::path d = fresh_dir("missing");
  const std::string path = (d / "no_such_dir" / "out.txt").string();
  try {
    pneufem::write_file_atomic(path, "x");
    FAIL() << "expected an error";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path + ".tmp"), std::string::npos) << e.what();
  }
  EXPECT_FALSE(fs::exists(path));
}

}  // namespace
