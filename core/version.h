#pragma once
// pneufem's version, as every output records it (summary.json, metrics.json, diagnosis.json,
// sweep.json, history lines, the ideal-model cache key) and `pneufem --version` prints.
#include <string>

namespace pneufem {

/// The project version and the git description of the tree at build time, e.g. "0.1.0 (61816e1)".
std::string version_string();

}  // namespace pneufem
