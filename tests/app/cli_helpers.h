#pragma once
// Helpers shared by the tests that drive the pneufem binary (PNEUFEM_EXE, set by CMake) or read
// its output files back.
#include <sys/wait.h>

#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace pneufem::test {

struct CliResult {
  int code;         ///< exit code (-1 when the process did not exit normally)
  std::string out;  ///< stdout and stderr, interleaved
};

#ifdef PNEUFEM_EXE
/// Runs `pneufem <args>` through the shell (args are shell words, quote as needed).
inline CliResult run_cli(const std::string& args) {
  const std::string cmd = std::string(PNEUFEM_EXE) + " " + args + " 2>&1";
  FILE* p = popen(cmd.c_str(), "r");
  std::string out;
  char buf[4096];
  while (p && fgets(buf, sizeof buf, p)) out += buf;
  const int status = p ? pclose(p) : -1;
  return {WIFEXITED(status) ? WEXITSTATUS(status) : -1, out};
}
#endif

/// The whole file as a string ("" when it cannot be read).
inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// An empty temporary directory path (removed if it existed; not created).
inline std::filesystem::path fresh_dir(const std::string& name) {
  const std::filesystem::path d = std::filesystem::temp_directory_path() / ("pneufem_" + name);
  std::filesystem::remove_all(d);
  return d;
}

}  // namespace pneufem::test
