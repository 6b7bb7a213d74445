#pragma once
// Whole-file writes that never leave a half-written output: the text goes to "<path>.tmp", is
// flushed, and is renamed over <path> (atomic on POSIX within one file system). A crash or a full
// disk leaves the previous file (or none) in place, never a truncated one.
//
// It lives in core/ (the ground floor, with errors.h) because every output layer — app/,
// analysis/ (measurement CSVs) and viz/ (SVG figures) — writes files this way.
#include <string>

namespace pneufem {

/// Writes `text` to `path` atomically; throws std::runtime_error naming the path (and what to
/// check) on failure, after removing the temporary file.
void write_file_atomic(const std::string& path, const std::string& text);

}  // namespace pneufem
