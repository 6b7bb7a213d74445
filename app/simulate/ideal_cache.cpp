#include "app/simulate/ideal_cache.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "app/simulate/result_cache.h"
#include "core/atomic_file.h"
#include "core/errors.h"

namespace pneufem {

namespace fs = std::filesystem;

namespace {

/// True when `recs` are one trial reported at exactly `times` (the protocol's report times).
bool matches(const std::vector<StateRecord>& recs, const std::vector<double>& times) {
  if (recs.size() != times.size()) return false;
  for (std::size_t i = 0; i < recs.size(); ++i)
    if (recs[i].trial != 1 || std::abs(recs[i].time_s - times[i]) > 1e-9 * (1.0 + std::abs(times[i])) ||
        !std::isfinite(recs[i].angle_deg))
      return false;
  return true;
}

}  // namespace

std::string ideal_cache_key(const Scene& ideal_scene, const Model& model, const std::string& version) {
  Fnv1a h;
  h.str(version);
  hash_model(h, ideal_scene, model);
  return h.hex();
}

std::string angles_csv(const std::vector<StateRecord>& recs, bool exact) {
  // Trials skipped by cycle jumping (StateRecord::extrapolated) add a column: 1 = extrapolated, 0 = solved.
  const bool jumped = std::any_of(recs.begin(), recs.end(), [](const StateRecord& r) { return r.extrapolated; });
  std::string s = jumped ? "trial,time_s,pressure_kPa,angle_deg,extrapolated\n" : "trial,time_s,pressure_kPa,angle_deg\n";
  char line[160];
  for (const StateRecord& r : recs) {
    if (exact)
      std::snprintf(line, sizeof line, "%d,%.17g,%.17g,%.17g", r.trial, r.time_s, r.pressure_Pa * 1e-3, r.angle_deg);
    else
      std::snprintf(line, sizeof line, "%d,%.6f,%.6f,%.6f", r.trial, r.time_s, r.pressure_Pa * 1e-3, r.angle_deg);
    s += line;
    s += jumped ? (r.extrapolated ? ",1\n" : ",0\n") : "\n";
  }
  return s;
}

std::vector<StateRecord> read_angles_csv(const std::string& path) {
  std::ifstream in(path);
  std::string line;
  std::vector<StateRecord> out;
  std::getline(in, line);
  while (std::getline(in, line)) {
    StateRecord r;
    double pk = 0;
    if (std::sscanf(line.c_str(), "%d,%lf,%lf,%lf", &r.trial, &r.time_s, &pk, &r.angle_deg) == 4) {
      r.pressure_Pa = pk * 1e3;
      out.push_back(r);
    }
  }
  return out;
}

IdealResult cached_ideal(const std::string& dir, const std::string& key, const Scene& ideal_scene,
                         const std::vector<double>& expected_times_s,
                         const std::function<std::vector<StateRecord>()>& compute, std::vector<std::string>& warnings) {
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (!fs::is_directory(dir)) throw InputError("--ideal-cache " + dir + ": cannot create the directory");
  const fs::path base = fs::path(dir) / ("ideal_" + key);
  const std::string csv = base.string() + ".csv";
  // Whoever holds the lock computes; the others wait for it and then read its result.
  FileLock lock(base.string() + ".lock", "--ideal-cache");
  if (fs::exists(csv)) {
    std::vector<StateRecord> recs = read_angles_csv(csv);
    if (matches(recs, expected_times_s)) return {std::move(recs), "cache " + csv};
    warnings.push_back("--ideal-cache: " + csv + " does not hold this protocol's report times (edited or damaged?); "
                       "recomputed and replaced");
  }
  IdealResult r{compute(), "computed"};
  write_file_atomic(base.string() + ".toml", ideal_scene.to_toml());
  write_file_atomic(csv, angles_csv(r.records, true));
  return r;
}

}  // namespace pneufem
