#pragma once
// The ideal elastic model's angles, shared between runs through a cache directory.
//
// `simulate` compares every trial with the ideal elastic model (same scene, inelastic effects off,
// one trial) for metrics.json. That model depends only on the mesh, the elastic materials, the
// loads and pneufem itself, not on the damage constants a sweep varies; on the default mesh it
// costs 218 s (BENCHMARKS.md section 7), as much as a quarter of a one-trial run. With a cache
// directory (`pneufem simulate --ideal-cache DIR`; `pneufem sweep` gives its points one) the first
// run computes it and the others read it.
//
// Key: FNV-1a (64 bit) of pneufem's version string, the resolved ideal scene (TOML, without the
// tables of the effects it switches off: their constants do not change it, Scene::model_toml) and the built
// model's mesh, boundary conditions, cavity faces and tip nodes, so a deck's contents count, not
// just its path, and a rebuilt pneufem never reads another version's results. Files:
// DIR/ideal_<key>.csv (trial,time_s,pressure_kPa,angle_deg at round-trip precision) and
// DIR/ideal_<key>.toml (the scene it belongs to, for people). Concurrent runs with one key take
// an exclusive lock (DIR/ideal_<key>.lock, flock), so the model is computed once; the files are
// written atomically.
#include <functional>
#include <string>
#include <vector>

#include "engine/model.h"
#include "engine/quasi_static.h"
#include "scenes/scene.h"

namespace pneufem {

/// Hex key of the ideal model `ideal_scene` built on `model`'s mesh (see above).
std::string ideal_cache_key(const Scene& ideal_scene, const Model& model, const std::string& version);

struct IdealResult {
  std::vector<StateRecord> records;
  std::string source;  ///< "computed" or "cache <file>"
};

/// The records of `compute()`, read from DIR when a valid entry with this key exists (it must
/// hold exactly the report times `expected_times_s` of trial 1; an invalid entry is recomputed
/// and replaced, with a warning in `warnings`), computed and stored otherwise. Throws InputError
/// when DIR cannot be created or locked.
IdealResult cached_ideal(const std::string& dir, const std::string& key, const Scene& ideal_scene,
                         const std::vector<double>& expected_times_s,
                         const std::function<std::vector<StateRecord>()>& compute, std::vector<std::string>& warnings);

/// angles.csv text: 6 decimals, or round-trip precision (%.17g) with `exact` (files read back);
/// and its reader (malformed lines are skipped).
std::string angles_csv(const std::vector<StateRecord>& records, bool exact = false);
std::vector<StateRecord> read_angles_csv(const std::string& path);

}  // namespace pneufem
