#pragma once
// Output locations checked before the work: a command that computes for minutes (compare,
// diagnose, sweep, synth, simulate) checks its --out first and creates it before computing, so a
// path that cannot be written fails in a moment with the reason, not after the computation.
#include <string>

namespace pneufem {

/// Checks, changing nothing (a probe file comes and goes), that `dir` can be the output directory: an existing writable
/// directory, or a missing one whose nearest existing ancestor is a writable directory. Called
/// first, so a bad --out fails before the inputs are even read, and bad input leaves no directory.
/// Throws InputError naming `option` (e.g. "--out"), the path and the cause: a regular file at
/// `dir` or at one of its parents, no permission to create or write, a read-only file system.
void check_output_dir(const std::string& dir, const std::string& option);

/// The same, and makes `dir` exist (with its parents): called just before the computation.
void prepare_output_dir(const std::string& dir, const std::string& option);

/// check_output_dir / prepare_output_dir for an output file's directory; `file` must not be a
/// directory.
void check_output_file(const std::string& file, const std::string& option);
void prepare_output_file(const std::string& file, const std::string& option);

}  // namespace pneufem
