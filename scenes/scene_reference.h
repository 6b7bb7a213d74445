#pragma once
// The scene reference (docs/scene_reference.md) as Markdown, generated from the two places a scene
// key is declared: the default scene file (its keys, defaults and comments) and the effect registry
// (the effect tables: keys, units, defaults, calibration ranges). `pneufem scene --reference`
// prints it; a ctest (scene_reference_is_current) fails when the committed file differs.
#include <string>

namespace pneufem {

/// The whole reference: one section per table of the default scene, a row per key with its
/// default, its unit (from the key's suffix, or the registry's) and the file's comment as meaning.
std::string scene_reference_markdown();

/// The unit a key's name carries ("h_mm" -> "mm", "density_kg_m3" -> "kg/m³"), "" when none.
std::string unit_of_key(const std::string& key);

}  // namespace pneufem
