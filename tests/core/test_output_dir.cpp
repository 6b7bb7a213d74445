// prepare_output_dir / prepare_output_file (core/output_dir.h): the --out of every command is
// created and checked before the work, and a path that cannot be written is named with its cause.
#include "core/output_dir.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "core/errors.h"

namespace pneufem {
namespace {

namespace fs = std::filesystem;

fs::path fresh(const std::string& name) {
  const fs::path d = fs::temp_directory_path() / ("pneufem_output_dir_" + name);
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string error_of(void (*prepare)(const std::string&, const std::string&), const fs::path& p) {
  try {
    prepare(p.string(), "--out");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(OutputDir, CreatesAMissingDirectoryAndItsParentsAndLeavesNoProbe) {
  const fs::path d = fresh("create");
  prepare_output_dir((d / "a" / "b").string(), "--out");
  EXPECT_TRUE(fs::is_directory(d / "a" / "b"));
  EXPECT_TRUE(fs::is_empty(d / "a" / "b"));
  prepare_output_dir((d / "a" / "b").string(), "--out");  // an existing directory is fine
  prepare_output_file((d / "c" / "data.csv").string(), "--out");
  EXPECT_TRUE(fs::is_directory(d / "c"));
  EXPECT_FALSE(fs::exists(d / "c" / "data.csv"));
}

// The check that comes first changes nothing: bad input found after it leaves no directory behind.
TEST(OutputDir, TheCheckCreatesNothingAndFailsAsThePreparationDoes) {
  const fs::path d = fresh("check");
  check_output_dir((d / "a" / "b").string(), "--out");
  check_output_file((d / "c" / "data.csv").string(), "--out");
  EXPECT_TRUE(fs::is_empty(d));
  std::ofstream(d / "f") << "x";
  for (const fs::path& p : {d / "f", d / "f" / "sub"})
    EXPECT_EQ(error_of(check_output_dir, p), error_of(prepare_output_dir, p));
  EXPECT_EQ(error_of(check_output_file, d / "f" / "x.csv"), error_of(prepare_output_file, d / "f" / "x.csv"));
  EXPECT_NE(error_of(check_output_dir, d / "f").find("is a file, not a directory"), std::string::npos);
}

TEST(OutputDir, ARegularFileOrAPathUnderOneIsNamedWithTheCause) {
  const fs::path d = fresh("file");
  std::ofstream(d / "f") << "x";
  std::string msg = error_of(prepare_output_dir, d / "f");
  EXPECT_NE(msg.find("--out " + (d / "f").string() + ": "), std::string::npos) << msg;
  EXPECT_NE(msg.find((d / "f").string() + " is a file, not a directory; give a directory"), std::string::npos) << msg;
  msg = error_of(prepare_output_dir, d / "f" / "sub" / "dir");
  EXPECT_NE(msg.find("cannot create the directory"), std::string::npos) << msg;
  EXPECT_NE(msg.find((d / "f").string() + " is a file, not a directory"), std::string::npos) << msg;
  msg = error_of(prepare_output_file, d / "f" / "data.csv");
  EXPECT_NE(msg.find("--out " + (d / "f" / "data.csv").string() + ": "), std::string::npos) << msg;
  EXPECT_NE(msg.find("is a file, not a directory; give a file in a directory"), std::string::npos) << msg;
  msg = error_of(prepare_output_file, d);
  EXPECT_NE(msg.find("is a directory, not a file"), std::string::npos) << msg;
  EXPECT_EQ(error_of(prepare_output_dir, ""), "--out: give a directory");
}

}  // namespace
}  // namespace pneufem
