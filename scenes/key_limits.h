#pragma once
// The allowed range of the numeric scene keys, declared once. Scene's typed reads (number,
// numbers, vec3, integer in scenes/scene.h) check every value they return: a number must be finite
// (no inf, no nan) and an integer must be a TOML integer that fits an int, always; a key listed
// here must also lie in its range. The error names the key, where it was set, the value, the range
// and why (`pneufem scene --reference` prints the table, docs/scene_reference.md).
//
// Checks that relate several keys (ramp_s < hold_s, the number of reports a protocol makes, the
// mesher's cell count) stay with the code that knows the relation; the laws and the effect
// decorators check their own physics (C10 > 0, Mullins r > 1, ...). This table is the outer fence:
// no value that is not a number, and none so far out that it can only be a mistake.
#include <string>
#include <vector>

namespace pneufem {

struct KeyLimit {
  std::string pattern;  ///< a dotted key; "*" stands for one name (a material, a region)
  double lo = 0.0, hi = 0.0;
  bool lo_open = false, hi_open = false;  ///< true: the bound itself is excluded
  std::string why;                        ///< one line: why these bounds
  bool contains(double v) const;
  /// The range as a reader writes it: "> 0 and <= 1000".
  std::string range_text() const;
};

/// Every declared range, in the order of the default scene.
const std::vector<KeyLimit>& key_limits();

/// The range of `key` ("materials.silicone.K_over_mu" matches "materials.*.K_over_mu"), or nullptr.
const KeyLimit* find_key_limit(const std::string& key);

}  // namespace pneufem
