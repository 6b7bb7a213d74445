#include "app/compare/history.h"

#include <cmath>
#include <cstdlib>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "core/atomic_file.h"
#include "core/json_writer.h"

namespace pneufem {

namespace fs = std::filesystem;

std::string scene_hash(const Scene& scene) {
  std::uint64_t h = 1469598103934665603ULL;  // FNV-1a offset basis
  for (unsigned char c : scene.to_toml()) {
    h ^= c;
    h *= 1099511628211ULL;  // FNV prime
  }
  char buf[20];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

std::string utc_now() {
  const std::time_t t = std::time(nullptr);
  std::tm tm{};
  gmtime_r(&t, &tm);
  char buf[32];
  std::strftime(buf, sizeof buf, "%Y-%m-%dT%H:%M:%SZ", &tm);
  return buf;
}

namespace {

std::string history_line(const HistoryEntry& e) {
  return "{\"time_utc\": " + json::quote(e.time_utc) + ", \"label\": " + json::quote(e.label) +
         ", \"scene_hash\": " + json::quote(e.scene_hash) + ", \"nrmse\": " + json::num(e.nrmse) +
         ", \"trial_nrmse\": " + json::array(e.trial_nrmse) + ", \"source\": " + json::quote(e.source) + "}";
}

/// Value of a top-level string field of one of our own JSON lines ("" when absent).
std::string string_field(const std::string& line, const std::string& key) {
  const std::string k = "\"" + key + "\": \"";
  const std::size_t p = line.find(k);
  if (p == std::string::npos) return "";
  std::string out;
  for (std::size_t i = p + k.size(); i < line.size() && line[i] != '"'; ++i) {
    if (line[i] == '\\' && i + 1 < line.size()) ++i;
    out += line[i];
  }
  return out;
}

/// Numbers after "key": (a number or an array of numbers; null -> NaN).
std::vector<double> number_field(const std::string& line, const std::string& key) {
  const std::string k = "\"" + key + "\": ";
  const std::size_t p = line.find(k);
  std::vector<double> out;
  if (p == std::string::npos) return out;
  std::size_t i = p + k.size();
  const bool array = i < line.size() && line[i] == '[';
  if (array) ++i;
  while (i < line.size()) {
    while (i < line.size() && (line[i] == ' ' || line[i] == ',')) ++i;
    if (i >= line.size() || line[i] == ']' || line[i] == '}') break;
    if (line.compare(i, 4, "null") == 0) {
      out.push_back(std::nan(""));
      i += 4;
    } else {
      char* end = nullptr;
      const double v = std::strtod(line.c_str() + i, &end);
      if (end == line.c_str() + i) break;
      out.push_back(v);
      i = static_cast<std::size_t>(end - line.c_str());
    }
    if (!array) break;
  }
  return out;
}

}  // namespace

void append_history(const std::string& dir, const HistoryEntry& entry) {
  fs::create_directories(dir);
  const fs::path p = fs::path(dir) / "history.jsonl";
  std::string text;
  if (fs::exists(p)) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream ss;
    ss << in.rdbuf();
    text = ss.str();
    if (!text.empty() && text.back() != '\n') text += '\n';
  }
  text += history_line(entry) + "\n";
  write_file_atomic(p.string(), text);
}

std::vector<HistoryEntry> read_history(const std::string& dir) {
  std::vector<HistoryEntry> out;
  std::ifstream in(fs::path(dir) / "history.jsonl");
  for (std::string line; std::getline(in, line);) {
    const std::vector<double> n = number_field(line, "nrmse");
    if (n.size() != 1) continue;
    HistoryEntry e;
    e.time_utc = string_field(line, "time_utc");
    e.label = string_field(line, "label");
    e.scene_hash = string_field(line, "scene_hash");
    e.source = string_field(line, "source");
    e.nrmse = n[0];
    e.trial_nrmse = number_field(line, "trial_nrmse");
    out.push_back(e);
  }
  return out;
}

}  // namespace pneufem
