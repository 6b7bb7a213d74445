#pragma once
// A deck's materials as a layer of the scene (internal to scenes/: scene.cpp builds every scene with
// it). With mesh.source = "inp", the *MATERIAL blocks and *SOLID SECTION lines of mesh.file
// (scenes/inp/materials.h) become scene keys that sit between the default scene and the user's:
//
//   default scene  <  the deck  <  the scene file  <  --set / Scene::with
//
// so every key the scene sets wins over the deck's, key by key, and the deck's win over the defaults.
//  * *MATERIAL NAME -> [materials.name] (lower case, as region tags; the table's law keys replace
//    the default scene's table of that name when the law differs, as a scene file's do):
//    model and the law's constants (C10_MPa, ..., mu_MPa, alpha, E_MPa, nu), K_over_mu = 2/(D1 mu0)
//    (D1 = 0, incompressible in Abaqus: the default scene's ratio, with a note), density_kg_m3 (no
//    *DENSITY: the default scene's, with a note; it matters in explicit runs and with gravity);
//    *MULLINS EFFECT -> [materials.name.mullins] enabled, r, m_MPa, beta; *VISCOELASTIC, TIME=PRONY ->
//    [materials.name.viscoelastic] enabled, gamma_i = g_i/(1 - sum g), tau_s, and moduli from MODULI=
//    (Abaqus's default, instantaneous, when not given).
//  * the *SOLID SECTION lines -> [[parts]] (elset as written, the material's table name), replacing
//    the default scene's parts; a scene that sets parts keeps its own (the whole array: parts are
//    not merged entry by entry).
// Each key's origin is the deck line it came from, so errors about it name that line. Notes (every
// command prints them, simulate's summary.json records them with the build notes) say which tables
// and keys came from the deck and which of the deck's the scene overrides.
//
// *HYPERELASTIC, TEST DATA INPUT gives no law here: a scene whose parts use such a material must set
// its law (materials.name.model and constants), or loading the scene fails saying to run
// `pneufem fit-material deck:FILE`. Fitting is not done while a scene loads: a fit is a choice of law,
// weights and strain range whose result (and Drucker stability warnings) a person should see once,
// and the constants belong in the scene where every run records them; a scene is loaded many times
// per command (diagnose, sweep), each time it would fit again.
#include <functional>
#include <map>
#include <string>
#include <vector>

#include <toml++/toml.h>

#include "scenes/inp/materials.h"

namespace pneufem {

/// What a deck gave, kept with the scene for its notes.
struct DeckInfo {
  struct Material {
    std::string table;      ///< "materials.name"
    std::string deck_name;  ///< NAME= as written
    std::string where;      ///< its *MATERIAL line
    std::vector<std::string> keys;  ///< every leaf key the deck sets ("materials.name.C10_MPa", ...)
    bool test_data = false;
    std::string law_where;  ///< its *HYPERELASTIC / *ELASTIC line
    bool incompressible = false;  ///< D1 = 0
    bool no_density = false;      ///< no *DENSITY
  };
  std::string deck;         ///< path of the deck
  std::string length_unit;  ///< "mm" or "m"
  std::vector<Material> materials;
  std::vector<InpSection> sections;  ///< material = the table name (lower case)
  std::map<std::string, std::string> origins;  ///< leaf key (and "parts") -> "<file>:<line>"
  std::vector<std::string> read_notes;          ///< options the reader passed over
};

struct DeckLayer {
  toml::table table;
  DeckInfo info;
};

/// What a deck that does not say takes: the default scene's silicone's K0/mu0 (for D1 = 0) and density.
struct DeckDefaults {
  double K_over_mu = 100.0;
  double density_kg_m3 = 1070.0;
};

/// The layer of the deck at `path` (length_unit "mm" or "m"). Throws InputError for what
/// read_inp_materials refuses and for material names that cannot be a scene table.
DeckLayer deck_layer(const std::string& path, const std::string& length_unit, const DeckDefaults& defaults);

/// The merged scene as deck_notes reads it: Scene's accessors of the same names, bound by scene.cpp.
/// Functions rather than the Scene itself, so that this file and scenes/scene do not include each
/// other (no loop in the include graph: tests/docs/check_includes.py).
struct MergedScene {
  std::function<bool(const std::string&)> has;
  std::function<int(const std::string&)> array_size;
  std::function<std::string(const std::string&)> string;
  std::function<double(const std::string&)> number;
  std::function<std::string(const std::string&)> origin;  ///< "scene.toml:12", "--set", "default scene"
  /// The exact origin of a key: "" when no layer above the default scene set it.
  std::function<std::string(const std::string&)> origin_of;
};

/// The notes on what the deck gave the merged `scene`, and the check that no part's material is
/// TEST DATA INPUT without a law from the scene.
std::vector<std::string> deck_notes(const DeckInfo& info, const MergedScene& scene);

}  // namespace pneufem
