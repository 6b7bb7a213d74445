#pragma once
// Scene -> discrete problem: mesh (built-in pneu-net or an Abaqus/CalculiX deck), materials,
// parts, boundary conditions, cavity faces, bending-angle definition, load history and solver
// settings. This is the only place that turns scene keys into engine objects; the settings that
// are typed structs (mesh source, load protocol, solver, output) are read by scenes/scene_settings.h.
#include <memory>
#include <string>
#include <vector>

#include "engine/explicit.h"
#include "engine/load_history.h"
#include "engine/model.h"
#include "engine/quasi_static.h"
#include "engine/rom.h"
#include "scenes/scene.h"
#include "scenes/scene_settings.h"

namespace pneufem {

/// Everything a run needs. Held by pointer: the engine keeps references into `model`.
struct BuiltModel {
  Model model;
  LoadHistory load;
  SolverSettings solver;
  OutputSettings output;
  MeshStats stats;
  std::vector<std::string> warnings;
};

/// Builds the material named `name` (scene table materials.<name>): its law, stiffness_scale and
/// enabled effects (built-in and registered, damage/registry.h).
MaterialPtr make_material(const Scene& scene, const std::string& name);
/// The same with the stiffness additionally multiplied by `region_scale` (regions.<tag>.stiffness_scale).
MaterialPtr make_material(const Scene& scene, const std::string& name, double region_scale);

/// The elastic reference of a scene: every effect table (materials.<m>.<effect>.enabled) switched
/// off, no gravity, no pressure lag. Stiffness scales are elastic and stay. The reference of the
/// 1-dof path model and of the reduced-order model (engine/path_model.h, engine/rom.h).
Scene elastic_reference_scene(const Scene& scene);

/// Builds only the mesh described by the scene (mesh.* and geometry.*), with its sets.
Mesh build_mesh(const Scene& scene, std::vector<std::string>* warnings = nullptr);

std::unique_ptr<BuiltModel> build_model(const Scene& scene);

/// The scene's inlet pressure history ([load]: the staircase or load.csv), before any chamber lag
/// (load.pressure_lag_s and load.pressure_lag2_s act on it in build_model and when a recording is
/// driven). Cheap: no mesh.
LoadHistory inlet_load(const Scene& scene);
/// The chambers' pressure history: the inlet's through load.pressure_lag_s (and _lag2_s), the load of
/// build_model. Cheap: no mesh.
LoadHistory chamber_load(const Scene& scene);

/// Load history from a pressure CSV (columns trial,time_s,pressure_kPa; other columns and rows
/// without a pressure value are ignored). The 400 Hz signal is simplified to a piecewise-linear
/// history within `tolerance_kPa` (Ramer-Douglas-Peucker) so each breakpoint is one static state.
LoadHistory pressure_history_from_csv(const std::string& path, double tolerance_kPa, double output_every_s);

}  // namespace pneufem
