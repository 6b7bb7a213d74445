#pragma once
// The text layer of the deck reader (scenes/inp/deck.h): a deck's lines with *INCLUDE resolved, and the
// fields, numbers and keyword lines on them. Nothing here knows what a keyword means; the reader
// (scenes/inp/reader.h) does. Internal to scenes/inp/.
#include <cstdint>
#include <deque>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace pneufem::inp {

bool is_blank(char c);
std::string_view trim(std::string_view s);
std::string upper(std::string_view s);
std::string lower(std::string_view s);

/// Splits a data or keyword line at commas into trimmed fields. A trailing comma (Abaqus:
/// "continued on the next line") does not produce an empty last field; it is reported instead.
void split_fields(std::string_view line, std::vector<std::string_view>& fields, bool& trailing_comma);

/// Whole-field integer ("+12" allowed); nullopt for anything else.
std::optional<long> parse_long(std::string_view s);

/// Whole-field finite real. Accepts what Fortran list input accepts in decks: "1.", ".5", "+2",
/// "1e-3" and the double-precision exponent "1.0D-3". Rejects inf/nan.
std::optional<double> parse_double(std::string_view s);

/// Keyword name: "*Solid  Section, ..." -> "SOLID SECTION".
std::string keyword_name(std::string_view field);

/// A keyword line: "*Element, type=C3D8, elset=Body".
struct Keyword {
  std::string name;                           ///< upper case, single spaces
  std::map<std::string, std::string> params;  ///< upper-case key -> value as written (unquoted)
  bool has(const std::string& key) const { return params.count(key) != 0; }
  std::string get(const std::string& key) const {
    const auto it = params.find(key);
    return it == params.end() ? std::string() : it->second;
  }
};

Keyword parse_keyword(std::string_view line);

/// Where a line stands: a file of the LineSource and the line in it.
struct Loc {
  int file = 0;  ///< index into LineSource::file_name
  int line = 0;  ///< 1-based
};

/// The lines of a deck, one at a time. *INCLUDE is textual (as in CalculiX): the included lines
/// are read in place of the *INCLUDE line, so a data block may continue into an included file.
/// The files stay in memory until the source is destroyed: the lines are views into them.
class LineSource {
 public:
  /// Opens the deck; InputError if it cannot be read.
  explicit LineSource(const std::string& path);

  /// Next non-blank, non-comment line (trimmed), with *INCLUDE resolved. False at the end.
  bool next(std::string_view& text, Loc& loc);

  /// "<file>:<line>" as messages name a line.
  std::string where(const Loc& loc) const;
  const std::string& file_name(int file) const { return file_names_[static_cast<std::size_t>(file)]; }
  /// The number of lines of the deck itself (not its includes), once it has been read to the end.
  int last_line_of_top() const { return last_line_of_top_; }

 private:
  struct Frame {
    int file = 0;
    std::size_t pos = 0;
    int line = 0;
  };
  void push_file(const std::string& path, const std::optional<Loc>& from);
  void include(std::string_view text, const Loc& loc);
  /// "main.inp:2 -> a.inp:5 -> <next_file>": the *INCLUDE lines open now, for messages.
  std::string include_chain(const std::string& next_file) const;

  std::deque<std::string> buffers_;  // whole files; kept until the end (lines are views into them)
  std::vector<std::string> file_names_;
  std::vector<std::string> file_ids_;  // canonical paths, to find a file that includes itself
  std::vector<Frame> stack_;
  int last_line_of_top_ = 0;
  int includes_ = 0;              // *INCLUDE lines followed so far (bounded: kMaxIncludes)
  std::uintmax_t bytes_read_ = 0;  // text read so far, includes counted each time (kMaxDeckBytes)
};

}  // namespace pneufem::inp
