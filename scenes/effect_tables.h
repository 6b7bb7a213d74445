#pragma once
// The default scene's effect tables, generated from the effect registry (damage/registry.h): the
// one place an effect's keys, units, defaults and calibration ranges are declared. The default
// scene file (scenes/data/default_scene.toml) holds a marker line where they go,
//     # @effect-tables materials.silicone
// and Scene::default_text() is that file with every marker expanded, which is what scenes start
// from and what `pneufem scene --defaults` prints.
#include <string>

#include "damage/registry.h"

namespace pneufem {

/// The tables [<material_table>.<effect>] of the built-in effects (mullins, fatigue, viscoelastic),
/// switched off, with every key at its registered default and its doc (and calibration range) as
/// a comment.
std::string effect_tables_toml(const std::string& material_table);

/// `text` with each line "# @effect-tables <material_table>" replaced by effect_tables_toml.
std::string expand_effect_tables(const std::string& text);

/// The default of `p` as a scene writes it: a float, or a one-term list for a per-term parameter
/// ("8.0", "[6.0]").
std::string toml_default(const EffectParameter& p);

/// `v` as TOML writes a float: the shortest text that reads back exactly, with ".0" when it
/// would otherwise read as an integer ("8.0", "0.01", "1e-05").
std::string toml_float(double v);

}  // namespace pneufem
