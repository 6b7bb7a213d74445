#pragma once
// A scene's settings as typed structs: where the mesh comes from ([mesh]), the load protocol
// ([load]) and the solvers ([solver], [output]), and the built-in pneu-net's geometry ([geometry]). Each struct is read from its keys here, once,
// with the checks and messages of the scene reader (a failure names the key, where it was set
// and the values allowed); build_model (scenes/build_model.h) and the commands (app/) read the
// fields, not the keys. What is not here yet is read by build_model from its keys.
#include <string>

#include "engine/explicit.h"
#include "engine/mesh.h"
#include "engine/quasi_static.h"
#include "engine/rom.h"
#include "scenes/pneunet.h"
#include "scenes/scene.h"

namespace pneufem {

/// [mesh]: where the mesh comes from and how it is made. Each field is read for the sources that
/// use it and keeps its default for the others.
struct MeshSettings {
  enum class Source { PneuNet, Inp, Stl };
  Source source = Source::PneuNet;  ///< mesh.source: "pneunet" (built-in mesher), "inp" (a deck) or "stl"
  std::string file;                 ///< mesh.file: the deck or surface ("" for the built-in mesher)
  double h_mm = 0.0;                ///< mesh.h_mm: the built-in mesher's element size (mm); 0 for another source
  // The meshers' (source "pneunet" or "stl"), lengths in m:
  double h_m = 0.0;                          ///< mesh.h_mm (> 0 for "stl")
  double h_z_m = 0.0;                        ///< mesh.h_z_mm: the size along z (0 = h)
  bool half = false;                         ///< mesh.half: the x >= 0 half with a symmetry plane
  int fabric_layers = 1;                     ///< mesh.fabric_layers: elements through the fabric layer
  ElementType element = ElementType::Tet10;  ///< mesh.element: "tet10" or "tet4"
  /// mesh.fabric_model = "membrane" (every source; for "stl" the mesher also needs mesh.fabric_slab_mm).
  bool membrane_fabric = false;
  /// mesh.length_unit: metres per length unit of the file (source "inp" or "stl": "mm" or "m").
  double length_unit_m = 1e-3;
};

/// The [mesh] settings above. Fails naming the key for an unknown source, element, fabric model or
/// length unit and for a negative mesh.h_z_mm.
MeshSettings mesh_settings(const Scene& scene);

/// The built-in pneu-net of the scene: [geometry] in m and the mesher's [mesh] keys (mesh_settings
/// and mesh.wall_layers), for a scene with mesh.source = "pneunet". Not yet validated
/// (PneuNetParams::validate).
PneuNetParams pneunet_settings(const Scene& scene);

/// [load]: the protocol of the pressure history, pressures in Pa. inlet_load (scenes/build_model.h)
/// builds the LoadHistory from it and checks the keys that must agree with each other (ramp, mark
/// and hold; the protocol's size), naming the key.
struct LoadSettings {
  enum class Protocol { Staircase, Csv };
  Protocol protocol = Protocol::Staircase;  ///< load.protocol: "staircase" or "csv" (load.csv)
  double rest_s = 0.0;                      ///< load.rest_s: rest between trials (s)
  double output_every_s = 0.0;              ///< load.output_every_s: extra reports inside each hold (0 = none)
  // The staircase (protocol = "staircase"):
  double max_Pa = 0.0;   ///< load.max_kPa: the top level
  double step_Pa = 0.0;  ///< load.step_kPa: the step between levels
  double hold_s = 0.0;   ///< load.hold_s: each level's hold
  double ramp_s = 0.0;   ///< load.ramp_s: the controller's time to reach a level
  double mark_s = 0.0;   ///< load.mark_s: the mark after each step's start (the paper's 2.5 s)
  int trials = 1;        ///< load.trials
  // protocol = "csv":
  std::string csv;       ///< load.csv as written (Scene::resolve_path makes it a path)
};

/// The [load] settings above. Fails naming load.protocol for an unknown protocol.
LoadSettings load_settings(const Scene& scene);

/// [solver]: the solvers of a run, each key checked.
struct SolverSettings {
  enum class Mode { QuasiStatic, Explicit };
  Mode mode = Mode::QuasiStatic;
  enum class Model { Full, Reduced };  ///< quasi-static: the full FEM or the reduced model (engine/rom.h)
  Model model = Model::Full;
  RomBasisOptions reduced;             ///< solver.reduced_modes, _ecsw_tol, _softened_levels, _fabric, _release_modes
  double reduced_check_deg = 0.25;     ///< indicator tolerance of a reduced run's reports
  enum class CheckAt { Tops, Reports };  ///< where the corrected history is corrected (app/simulate/reduced.h)
  CheckAt reduced_check_at = CheckAt::Tops;
  int reduced_enrich_rounds = 2;       ///< basis enrichments from the corrected states before a fallback
  QuasiStaticOptions quasi_static;
  ExplicitOptions explicit_dynamics;
  double time_scale = 1.0;  ///< explicit mode: protocol time / simulated time
  /// explicit mode: run even where the mass added by selective mass scaling changes the answer
  /// (app/simulate/command.cpp, run_explicit, refuses it otherwise).
  bool force_mass_scaling = false;
};

/// The [solver] settings above.
SolverSettings solver_settings(const Scene& scene);

/// The scene's names of the solver's mode and model ("quasi_static", "explicit"; "full", "reduced").
std::string mode_name(SolverSettings::Mode mode);
std::string model_name(SolverSettings::Model model);

/// [output].
struct OutputSettings {
  std::string vtu = "steps";  ///< output.vtu: "steps", "all" or "none"
};

/// The [output] settings above.
OutputSettings output_settings(const Scene& scene);

}  // namespace pneufem
