// Fuzz target: a scene file (TOML) into the typed scene — the reader (scenes/scene.h, in memory:
// Scene::from_text), the typed settings (scenes/scene_settings.h), every material with its effects
// (make_material), the pressure lag and the load history of the staircase (inlet_load,
// chamber_load: no mesh), and the resolved scene written back (to_toml, to_json). Meshing is not
// fuzzed here (seconds per input); a deck is the inp target's. A load.csv protocol would read a
// file the fuzzer names, so it stops after the settings. InputError is the documented answer to
// bad input; anything else is a finding. Lines after a line "#--set" are command-line overrides
// (--set key=value, Scene::with), the rest is the scene file.
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

#include "core/errors.h"
#include "fuzz/report.h"
#include "scenes/build_model.h"
#include "scenes/pressure_lag.h"
#include "scenes/scene.h"
#include "scenes/scene_settings.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  std::string text(reinterpret_cast<const char*>(data), size);
  std::vector<std::string> overrides;
  if (const std::size_t mark = text.find("\n#--set\n"); mark != std::string::npos) {
    std::istringstream rest(text.substr(mark + 8));
    for (std::string line; std::getline(rest, line);) overrides.push_back(line);
    text.resize(mark + 1);
  }
  try {
    const pneufem::Scene scene = pneufem::Scene::from_text(text, "fuzz.toml", overrides);
    (void)scene.to_toml();
    (void)scene.to_json();
    (void)pneufem::mesh_settings(scene);
    (void)pneufem::solver_settings(scene);
    (void)pneufem::output_settings(scene);
    for (const std::string& m : scene.table_keys("materials")) (void)pneufem::make_material(scene, m);
    (void)pneufem::scene_pressure_lag(scene);
    if (pneufem::load_settings(scene).protocol == pneufem::LoadSettings::Protocol::Staircase) {
      (void)pneufem::inlet_load(scene);
      (void)pneufem::chamber_load(scene);
    }
    (void)pneufem::elastic_reference_scene(scene).model_toml();
    pneufem::fuzz::report("accepted");
  } catch (const pneufem::InputError& e) {
    pneufem::fuzz::report("error", e.what());
  }
  return 0;
}
