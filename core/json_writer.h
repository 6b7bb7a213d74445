#pragma once
// Minimal JSON writing helpers for the run outputs (read back with nlohmann/json, a parser).
#include <cmath>
#include <cstdio>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace pneufem::json {

inline std::string quote(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    switch (c) {
      case '"': out += "\\\""; break;
      case '\\': out += "\\\\"; break;
      case '\n': out += "\\n"; break;
      case '\r': out += "\\r"; break;
      case '\t': out += "\\t"; break;
      default:
        if (static_cast<unsigned char>(c) < 0x20) {
          char buf[8];
          std::snprintf(buf, sizeof buf, "\\u%04x", c);
          out += buf;
        } else {
          out += c;
        }
    }
  }
  return out + "\"";
}

/// Shortest round-trip representation; non-finite numbers become null (JSON has no NaN).
inline std::string num(double v) {
  if (!std::isfinite(v)) return "null";
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  double back = 0;
  for (int p = 6; p <= 17; ++p) {
    std::snprintf(buf, sizeof buf, "%.*g", p, v);
    std::sscanf(buf, "%lf", &back);
    if (back == v) break;
  }
  return buf;
}

inline std::string array(const std::vector<double>& v) {
  std::string s = "[";
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + num(v[i]);
  return s + "]";
}

/// An array of strings, each quoted: ["a", "b"].
inline std::string strings(const std::vector<std::string>& v) {
  std::string s = "[";
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + quote(v[i]);
  return s + "]";
}

/// Ordered object builder: obj.add("key", raw_json_value).
class Object {
 public:
  Object& add(const std::string& key, const std::string& raw) {
    items_.emplace_back(key, raw);
    return *this;
  }
  Object& add(const std::string& key, double v) { return add(key, num(v)); }
  Object& add_str(const std::string& key, const std::string& v) { return add(key, quote(v)); }
  std::string str(int indent = 0) const {
    const std::string pad(indent + 2, ' '), end(indent, ' ');
    std::string s = "{\n";
    for (std::size_t i = 0; i < items_.size(); ++i)
      s += pad + quote(items_[i].first) + ": " + items_[i].second + (i + 1 < items_.size() ? ",\n" : "\n");
    return s + end + "}";
  }

 private:
  std::vector<std::pair<std::string, std::string>> items_;
};

}  // namespace pneufem::json
