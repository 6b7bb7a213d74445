// The text layer of the deck reader (text.h): fields and numbers of a line, keyword lines,
// and the deck's lines with *INCLUDE resolved.
#include "scenes/inp/text.h"

#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "core/errors.h"
#include "core/message_text.h"

namespace pneufem::inp {

namespace {

namespace fs = std::filesystem;

// The limits that keep a deck's *INCLUDE graph finite and its text in memory (the lines are views
// into the whole files, kept until the deck has been read). A deck split by Abaqus/CAE or by hand
// nests a few files and includes tens; a file including the next twice, 24 deep, would mean 2^24
// inclusions, so the count of inclusions is bounded as well as the depth and the bytes.
constexpr int kMaxIncludeDepth = 32;       // deeper nesting than any real deck; cycles are caught before it
constexpr int kMaxIncludes = 10000;        // *INCLUDE lines followed per deck: a fan-out ends in well under 1 s
// All the text read, a file counted each time it is included, all of it in memory at once: 1 GiB
// is ~5x a deck of 10^6 C3D10 elements, far beyond what the engine solves on one machine.
constexpr std::uintmax_t kMaxDeckBytes = std::uintmax_t{1} << 30;

/// "1.5 MiB", "1024.0 MiB": a size in a message.
std::string mebibytes(std::uintmax_t bytes) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f MiB", static_cast<double>(bytes) / (1024.0 * 1024.0));
  return buf;
}

}  // namespace

// ---- fields, numbers, keywords ---------------------------------------------------------------

bool is_blank(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\f' || c == '\v'; }

std::string_view trim(std::string_view s) {
  while (!s.empty() && is_blank(s.front())) s.remove_prefix(1);
  while (!s.empty() && is_blank(s.back())) s.remove_suffix(1);
  return s;
}

std::string upper(std::string_view s) {
  std::string out(s);
  for (char& c : out)
    if (c >= 'a' && c <= 'z') c = static_cast<char>(c - 'a' + 'A');
  return out;
}

std::string lower(std::string_view s) {
  std::string out(s);
  for (char& c : out)
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  return out;
}

void split_fields(std::string_view line, std::vector<std::string_view>& fields, bool& trailing_comma) {
  fields.clear();
  line = trim(line);
  trailing_comma = !line.empty() && line.back() == ',';
  if (trailing_comma) line.remove_suffix(1);
  std::size_t start = 0;
  while (true) {
    const std::size_t comma = line.find(',', start);
    fields.push_back(trim(line.substr(start, comma == std::string_view::npos ? line.npos : comma - start)));
    if (comma == std::string_view::npos) break;
    start = comma + 1;
  }
}

std::optional<long> parse_long(std::string_view s) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  long v = 0;
  const auto [ptr, ec] = std::from_chars(s.data(), s.data() + s.size(), v);
  if (s.empty() || ec != std::errc() || ptr != s.data() + s.size()) return std::nullopt;
  return v;
}

std::optional<double> parse_double(std::string_view s) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  if (s.empty() || s.size() > 64) return std::nullopt;
  std::array<char, 64> buf{};
  for (std::size_t i = 0; i < s.size(); ++i) buf[i] = (s[i] == 'd' || s[i] == 'D') ? 'e' : s[i];
  double v = 0.0;
  const auto [ptr, ec] = std::from_chars(buf.data(), buf.data() + s.size(), v);
  if (ec != std::errc() || ptr != buf.data() + s.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

std::string keyword_name(std::string_view field) {
  field = trim(field.substr(1));  // drop '*'
  std::string out;
  bool space = false;
  for (char c : field) {
    if (is_blank(c)) {
      space = true;
      continue;
    }
    if (space && !out.empty()) out.push_back(' ');
    space = false;
    out.push_back(c);
  }
  return upper(out);
}

Keyword parse_keyword(std::string_view line) {
  std::vector<std::string_view> fields;
  bool trailing = false;
  split_fields(line, fields, trailing);
  Keyword kw;
  kw.name = keyword_name(fields[0]);
  for (std::size_t i = 1; i < fields.size(); ++i) {
    const std::string_view f = fields[i];
    if (f.empty()) continue;
    const std::size_t eq = f.find('=');
    std::string key = upper(trim(f.substr(0, eq)));
    std::string_view value = eq == f.npos ? std::string_view() : trim(f.substr(eq + 1));
    if (value.size() >= 2 && value.front() == '"' && value.back() == '"') value = value.substr(1, value.size() - 2);
    kw.params[std::move(key)] = std::string(value);
  }
  return kw;
}

// ---- the deck's lines -------------------------------------------------------------------------

LineSource::LineSource(const std::string& path) { push_file(path, std::nullopt); }

std::string LineSource::where(const Loc& loc) const {
  return file_names_[static_cast<std::size_t>(loc.file)] + ":" + std::to_string(loc.line);
}

std::string LineSource::include_chain(const std::string& next_file) const {
  // The files after the deck are named from the deck's directory, as its INPUT= lines name them.
  const fs::path top_dir = fs::path(file_names_.front()).parent_path();
  auto short_name = [&](const std::string& file) {
    const fs::path rel = fs::path(file).lexically_relative(top_dir);
    return rel.empty() || top_dir.empty() ? file : rel.string();
  };
  std::string chain;
  for (const Frame& fr : stack_) {
    const std::string& file = file_names_[static_cast<std::size_t>(fr.file)];
    chain += (chain.empty() ? file : short_name(file)) + ":" + std::to_string(fr.line) + " -> ";
  }
  return chain + short_name(next_file);
}

void LineSource::push_file(const std::string& path, const std::optional<Loc>& from) {
  std::ifstream in;
  std::error_code ec;
  if (!fs::is_directory(path, ec)) in.open(path, std::ios::binary);
  if (!in) {
    if (!from) throw InputError(printable(path + ": cannot open the deck; check the path and the file permissions"));
    throw InputError(printable(where(*from) + ": cannot open include file '" + path +
                     "'; check INPUT= (a relative path is taken from the directory of the including file)"));
  }
  in.seekg(0, std::ios::end);
  const std::streamoff size = std::max<std::streamoff>(in.tellg(), 0);
  in.seekg(0, std::ios::beg);
  bytes_read_ += static_cast<std::uintmax_t>(size);
  if (bytes_read_ > kMaxDeckBytes) {
    const std::string what = "the deck's text reaches " + mebibytes(bytes_read_) + " with " + path +
                             ", over the limit of " + mebibytes(kMaxDeckBytes) + " (a file counts each time it is included)";
    if (!from) throw InputError(printable(path + ": " + what + "; split the model or coarsen the mesh"));
    throw InputError(printable(where(*from) + ": " + what + "; include chain " + include_chain(path) +
                     "; include each file once"));
  }
  std::string text;
  if (size > 0) {
    text.resize(static_cast<std::size_t>(size));
    in.read(text.data(), size);
    text.resize(static_cast<std::size_t>(std::max<std::streamsize>(in.gcount(), 0)));
  }
  if (text.starts_with("\xEF\xBB\xBF")) text.erase(0, 3);  // UTF-8 byte-order mark
  buffers_.push_back(std::move(text));
  file_names_.push_back(path);
  const std::string id = fs::weakly_canonical(path, ec).string();
  file_ids_.push_back(ec || id.empty() ? path : id);
  stack_.push_back(Frame{static_cast<int>(file_names_.size()) - 1, 0, 0});
}

bool LineSource::next(std::string_view& text, Loc& loc) {
  while (!stack_.empty()) {
    Frame& fr = stack_.back();
    const std::string& buf = buffers_[static_cast<std::size_t>(fr.file)];
    if (fr.pos >= buf.size()) {
      if (stack_.size() == 1) last_line_of_top_ = fr.line;
      stack_.pop_back();
      continue;
    }
    const std::size_t nl = buf.find('\n', fr.pos);
    const std::size_t end = nl == std::string::npos ? buf.size() : nl;
    text = trim(std::string_view(buf).substr(fr.pos, end - fr.pos));
    fr.pos = end + 1;
    ++fr.line;
    loc = Loc{fr.file, fr.line};
    if (text.empty() || text.starts_with("**")) continue;
    if (text.front() == '*' && keyword_name(text.substr(0, text.find(','))) == "INCLUDE") {
      include(text, loc);
      continue;
    }
    return true;
  }
  return false;
}

void LineSource::include(std::string_view text, const Loc& loc) {
  const Keyword kw = parse_keyword(text);
  const std::string input = kw.get("INPUT");
  auto fail = [&](const std::string& what, const std::string& todo) {
    throw InputError(printable(where(loc) + ": " + what + "; " + todo));
  };
  if (input.empty()) fail("*INCLUDE without INPUT=<file>", "add INPUT=<path of the file to include>");
  fs::path p(input);
  if (p.is_relative()) p = fs::path(file_names_[static_cast<std::size_t>(loc.file)]).parent_path() / p;
  const std::string path = p.string();
  std::error_code ec;
  std::string id = fs::weakly_canonical(p, ec).string();
  if (ec || id.empty()) id = path;
  for (const Frame& fr : stack_)
    if (file_ids_[static_cast<std::size_t>(fr.file)] == id)
      fail("*INCLUDE of " + path + " closes a cycle, a file including itself: " + include_chain(path),
           "remove the *INCLUDE that closes the cycle");
  if (static_cast<int>(stack_.size()) >= kMaxIncludeDepth)
    fail("*INCLUDE nested deeper than " + std::to_string(kMaxIncludeDepth) + " files: " + include_chain(path),
         "include the files from fewer levels");
  if (++includes_ > kMaxIncludes)
    fail("more than " + std::to_string(kMaxIncludes) + " *INCLUDE lines followed in one deck (here " +
             include_chain(path) + ")",
         "include each file once; a file that includes another several times multiplies at every level");
  push_file(p.string(), loc);
}

}  // namespace pneufem::inp
