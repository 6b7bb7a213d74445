#include "core/output_dir.h"

#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "core/errors.h"

namespace pneufem {

namespace {

namespace fs = std::filesystem;

/// The nearest ancestor of `p` (or `p` itself) that exists, "" when none does.
fs::path existing_ancestor(fs::path p) {
  std::error_code ec;
  p = fs::absolute(p, ec);
  while (!p.empty()) {
    if (fs::exists(fs::symlink_status(p, ec))) return p;
    if (p == p.parent_path()) break;
    p = p.parent_path();
  }
  return {};
}

/// Creating a file is the one test of writability that covers permissions, ACLs and a read-only
/// file system alike; the probe is removed at once.
void require_writable(const fs::path& dir, const std::string& named) {
  const fs::path probe = dir / (".pneufem_write_probe." + std::to_string(::getpid()));
  errno = 0;
  const bool ok = static_cast<bool>(std::ofstream(probe, std::ios::binary));
  const int err = errno;
  std::error_code ec;
  fs::remove(probe, ec);
  if (!ok)
    throw InputError(named + ": the directory " + dir.string() + " is not writable (" +
                     (err != 0 ? std::strerror(err) : "cannot create a file") +
                     "); choose another directory or fix its permissions");
}

/// check_output_dir (create = false) or prepare_output_dir (create = true), its messages starting
/// with `named` ("--out results/run1") and ending, when a file stands in the way, with `advice`.
void check_dir(const fs::path& dir, const std::string& named, const std::string& advice, bool create) {
  std::error_code ec;
  if (fs::exists(dir, ec) && !fs::is_directory(dir, ec))
    throw InputError(named + ": " + dir.string() + " is a file, not a directory; " + advice);
  if (!fs::is_directory(dir, ec)) {
    const fs::path up = existing_ancestor(dir);
    if (!up.empty() && !fs::is_directory(up, ec))
      throw InputError(named + ": cannot create the directory " + dir.string() + ": " + up.string() +
                       " is a file, not a directory; " + advice);
    if (!create) {  // creatable when the nearest existing directory above it is writable
      if (!up.empty()) require_writable(up, named);
      return;
    }
    fs::create_directories(dir, ec);
    if (ec || !fs::is_directory(dir))
      throw InputError(named + ": cannot create the directory " + dir.string() + " (" + ec.message() +
                       "); choose another location or fix the permissions of " + (up.empty() ? dir : up).string());
  }
  require_writable(dir, named);
}

constexpr const char* kDirAdvice = "give a directory (it is created when missing)";
constexpr const char* kFileAdvice = "give a file in a directory (the directory is created when missing)";

/// The directory an output file goes to; InputError when `file` is empty or a directory.
fs::path directory_of_file(const std::string& file, const std::string& option) {
  if (file.empty()) throw InputError(option + ": give a file");
  const fs::path p(file);
  std::error_code ec;
  if (fs::is_directory(p, ec))
    throw InputError(option + " " + file + ": is a directory, not a file; give the file to write, e.g. " +
                     (p / "data.csv").string());
  return p.has_parent_path() ? p.parent_path() : fs::path(".");
}

}  // namespace

void check_output_dir(const std::string& dir, const std::string& option) {
  if (dir.empty()) throw InputError(option + ": give a directory");
  check_dir(dir, option + " " + dir, kDirAdvice, false);
}

void prepare_output_dir(const std::string& dir, const std::string& option) {
  if (dir.empty()) throw InputError(option + ": give a directory");
  check_dir(dir, option + " " + dir, kDirAdvice, true);
}

void check_output_file(const std::string& file, const std::string& option) {
  check_dir(directory_of_file(file, option), option + " " + file, kFileAdvice, false);
}

void prepare_output_file(const std::string& file, const std::string& option) {
  check_dir(directory_of_file(file, option), option + " " + file, kFileAdvice, true);
}

}  // namespace pneufem
