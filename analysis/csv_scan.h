#pragma once
// Internal scanning helpers shared by the CSV readers of analysis/ (measurements.cpp,
// deeplabcut.cpp); not part of the library's API. The whole file is read into one buffer and
// scanned in place: lines by memchr, fields by comma, numbers by std::from_chars (locale-free,
// no allocation), so a 10^6-row file costs a few hundred milliseconds, not seconds of iostreams.
#include <string>
#include <string_view>
#include <vector>

namespace pneufem::csv {

/// The bytes of `path`. Throws InputError "<path>: cannot open ..." when it cannot be read.
std::string read_file(const std::string& path);

struct Line {
  std::string_view text;  ///< without the line terminator ("\n" or "\r\n")
  int number = 0;         ///< 1-based
};

/// Iterates the lines of a buffer; skips a leading UTF-8 byte-order mark.
class LineCursor {
 public:
  explicit LineCursor(std::string_view text);
  /// Next line, false at the end of the buffer. A final line without "\n" is returned too.
  bool next(Line& line);

 private:
  std::string_view text_;
  std::size_t pos_ = 0;
  int number_ = 0;
};

/// Splits `line` at every comma into `fields` (views into `line`, untrimmed). Quotes are not
/// interpreted: the numeric files read here never need them.
void split(std::string_view line, std::vector<std::string_view>& fields);

/// `s` without leading and trailing blanks (space, tab).
std::string_view trim(std::string_view s);

/// Lower-case copy, with surrounding blanks and one pair of surrounding double quotes removed
/// (spreadsheet exports sometimes quote header cells).
std::string header_name(std::string_view cell);

enum class Number { ok, empty, not_a_number, not_finite };

/// Strict decimal parse of a whole (trimmed) field; a leading '+' is accepted. NaN and infinities
/// are reported as not_finite, never returned.
Number parse_double(std::string_view field, double& value);

/// An integer field; "3", "+3" and an integral decimal such as "3.0" (MATLAB writes these) are
/// accepted, "3.5" is not_a_number.
Number parse_int(std::string_view field, long& value);

/// A field shortened to at most 40 characters, printable (core/message_text.h) and quoted, for
/// error messages.
std::string quoted(std::string_view field);

/// Shortest text that reads back to exactly `v` (std::to_chars).
std::string number_text(double v);

/// Throws InputError "<source>:<line>:<column>: <what>; <todo>" (column is 1-based).
[[noreturn]] void fail(const std::string& source, int line, int column, const std::string& what,
                       const std::string& todo);

}  // namespace pneufem::csv
