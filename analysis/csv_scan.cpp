#include "analysis/csv_scan.h"

#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <system_error>

#include "core/errors.h"
#include "core/message_text.h"

namespace pneufem::csv {

std::string read_file(const std::string& path) {
  std::unique_ptr<std::FILE, int (*)(std::FILE*)> f(std::fopen(path.c_str(), "rb"), &std::fclose);
  if (!f)
    throw InputError(path + ": cannot open the file (" + std::strerror(errno) +
                     "); check the path and the file permissions");
  // One allocation of the file's size, then one read; the loop covers files that grow or report
  // no size (pipes).
  std::string data;
  if (std::fseek(f.get(), 0, SEEK_END) == 0) {
    const long size = std::ftell(f.get());
    if (size > 0) data.reserve(static_cast<std::size_t>(size));
    std::rewind(f.get());
  }
  char buf[1 << 16];
  std::size_t got = 0;
  if (data.capacity() > 0) {
    data.resize(data.capacity());
    got = std::fread(data.data(), 1, data.size(), f.get());
    data.resize(got);
  }
  while ((got = std::fread(buf, 1, sizeof buf, f.get())) > 0) data.append(buf, got);
  if (std::ferror(f.get())) throw InputError(path + ": read error; check that the file is a readable regular file");
  return data;
}

LineCursor::LineCursor(std::string_view text) : text_(text) {
  if (text_.size() >= 3 && text_.compare(0, 3, "\xEF\xBB\xBF") == 0) pos_ = 3;
}

bool LineCursor::next(Line& line) {
  if (pos_ >= text_.size()) return false;
  const char* begin = text_.data() + pos_;
  const void* nl = std::memchr(begin, '\n', text_.size() - pos_);
  const std::size_t len = nl ? static_cast<std::size_t>(static_cast<const char*>(nl) - begin) : text_.size() - pos_;
  std::string_view s(begin, len);
  if (!s.empty() && s.back() == '\r') s.remove_suffix(1);
  pos_ += len + 1;
  line.text = s;
  line.number = ++number_;
  return true;
}

void split(std::string_view line, std::vector<std::string_view>& fields) {
  fields.clear();
  std::size_t start = 0;
  while (true) {
    const void* comma = std::memchr(line.data() + start, ',', line.size() - start);
    if (!comma) {
      fields.push_back(line.substr(start));
      return;
    }
    const std::size_t at = static_cast<std::size_t>(static_cast<const char*>(comma) - line.data());
    fields.push_back(line.substr(start, at - start));
    start = at + 1;
  }
}

std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

std::string header_name(std::string_view cell) {
  std::string_view s = trim(cell);
  if (s.size() >= 2 && s.front() == '"' && s.back() == '"') s = trim(s.substr(1, s.size() - 2));
  std::string out(s);
  for (char& c : out) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return out;
}

Number parse_double(std::string_view field, double& value) {
  std::string_view s = trim(field);
  if (s.empty()) return Number::empty;
  if (s.front() == '+') s.remove_prefix(1);
  const char* end = s.data() + s.size();
  const auto [ptr, ec] = std::from_chars(s.data(), end, value);
  // from_chars reports out-of-range values (1e999) as errors; they are not finite either way.
  if (ec == std::errc::result_out_of_range) return Number::not_finite;
  if (ec != std::errc() || ptr != end) return Number::not_a_number;
  return std::isfinite(value) ? Number::ok : Number::not_finite;
}

Number parse_int(std::string_view field, long& value) {
  std::string_view s = trim(field);
  if (s.empty()) return Number::empty;
  std::string_view digits = s.front() == '+' ? s.substr(1) : s;
  const char* end = digits.data() + digits.size();
  const auto [ptr, ec] = std::from_chars(digits.data(), end, value);
  if (ec == std::errc() && ptr == end) return Number::ok;
  double d = 0.0;
  const Number as_double = parse_double(s, d);
  if (as_double != Number::ok) return as_double;
  if (d != std::floor(d) || std::abs(d) > 1e15) return Number::not_a_number;
  value = static_cast<long>(d);
  return Number::ok;
}

std::string quoted(std::string_view field) {
  // Built piece by piece: GCC 12 warns (-Wrestrict, a false positive) on "'" + std::string.
  std::string s = "'";
  s += printable(field, 40);
  s += '\'';
  return s;
}

std::string number_text(double v) {
  char buf[64];
  const auto [ptr, ec] = std::to_chars(buf, buf + sizeof buf, v);
  return std::string(buf, ec == std::errc() ? ptr : buf);
}

void fail(const std::string& source, int line, int column, const std::string& what, const std::string& todo) {
  throw InputError(source + ":" + std::to_string(line) + ":" + std::to_string(column) + ": " + what + "; " + todo);
}

}  // namespace pneufem::csv
