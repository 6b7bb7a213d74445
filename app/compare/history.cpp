#include "app/compare/history.h"

#include <cmath>
#include <cstdint>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <nlohmann/json.hpp>

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
         ", \"trial_nrmse\": " + json::array(e.trial_nrmse) +
         (e.trial_rmse_deg.empty() ? std::string() : ", \"trial_rmse_deg\": " + json::array(e.trial_rmse_deg)) +
         ", \"source\": " + json::quote(e.source) + "}";
}

/// A number of a history line: JSON has no NaN, so json::num wrote a non-finite value as null.
bool read_number(const nlohmann::json& v, double& out) {
  if (v.is_number()) {
    out = v.get<double>();
    return true;
  }
  if (v.is_null()) {
    out = std::nan("");
    return true;
  }
  return false;
}

std::string string_member(const nlohmann::json& line, const char* key) {
  const auto it = line.find(key);
  return it != line.end() && it->is_string() ? it->get<std::string>() : std::string();
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
    const nlohmann::json j = nlohmann::json::parse(line, nullptr, /*allow_exceptions=*/false);
    if (!j.is_object()) continue;  // a damaged or foreign line
    HistoryEntry e;
    const auto nrmse = j.find("nrmse");
    if (nrmse == j.end() || !read_number(*nrmse, e.nrmse)) continue;
    e.time_utc = string_member(j, "time_utc");
    e.label = string_member(j, "label");
    e.scene_hash = string_member(j, "scene_hash");
    e.source = string_member(j, "source");
    if (const auto trials = j.find("trial_nrmse"); trials != j.end() && trials->is_array())
      for (const nlohmann::json& v : *trials) {
        double x = 0.0;
        if (!read_number(v, x)) break;
        e.trial_nrmse.push_back(x);
      }
    if (const auto trials = j.find("trial_rmse_deg"); trials != j.end() && trials->is_array())
      for (const nlohmann::json& v : *trials) {
        double x = 0.0;
        if (!read_number(v, x)) break;
        e.trial_rmse_deg.push_back(x);
      }
    out.push_back(e);
  }
  return out;
}

}  // namespace pneufem
