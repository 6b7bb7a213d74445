// The typed settings of scenes/scene_settings.h, read from their keys.
#include "scenes/scene_settings.h"

#include "scenes/scene_keys.h"

namespace pneufem {

using detail::choice;
using detail::kkPa;
using detail::kmm;
using detail::positive;

MeshSettings mesh_settings(const Scene& s) {
  MeshSettings m;
  m.source = choice<MeshSettings::Source>(s, "mesh.source", {{"pneunet", MeshSettings::Source::PneuNet},
                                                             {"inp", MeshSettings::Source::Inp},
                                                             {"stl", MeshSettings::Source::Stl}});
  m.file = s.string("mesh.file");
  const bool pneunet = m.source == MeshSettings::Source::PneuNet, stl = m.source == MeshSettings::Source::Stl;
  if (pneunet) {
    m.h_mm = s.number("mesh.h_mm");
    m.h_m = m.h_mm * kmm;
  }
  if (stl) m.h_m = positive(s, "mesh.h_mm") * kmm;
  if (pneunet || stl) {
    m.h_z_m = s.number("mesh.h_z_mm") * kmm;
    if (m.h_z_m < 0) s.fail("mesh.h_z_mm", "must be >= 0 (0 = same as mesh.h_mm)");
    m.half = s.boolean("mesh.half");
    m.fabric_layers = s.integer("mesh.fabric_layers");
    const std::string el = s.string("mesh.element");
    if (el != "tet10" && el != "tet4") s.fail("mesh.element", "must be \"tet10\" or \"tet4\", got \"" + el + "\"");
    m.element = el == "tet10" ? ElementType::Tet10 : ElementType::Tet4;
  }
  {
    const std::string v = s.string("mesh.fabric_model");
    if (v != "solid" && v != "membrane") s.fail("mesh.fabric_model", "must be \"solid\" or \"membrane\", got \"" + v + "\"");
    m.membrane_fabric = v == "membrane";
  }
  if (!pneunet) {
    const std::string u = s.string("mesh.length_unit");
    if (u != "mm" && u != "m") s.fail("mesh.length_unit", "must be \"mm\" or \"m\", got \"" + u + "\"");
    m.length_unit_m = u == "mm" ? 1e-3 : 1.0;
  }
  return m;
}

PneuNetParams pneunet_settings(const Scene& s) {
  PneuNetParams p;
  p.width = s.number("geometry.width_mm") * kmm;
  p.base_thickness = s.number("geometry.base_thickness_mm") * kmm;
  p.body_height = s.number("geometry.body_height_mm") * kmm;
  p.chambers = s.integer("geometry.chambers");
  p.chamber_length = s.number("geometry.chamber_length_mm") * kmm;
  p.interior_wall = s.number("geometry.interior_wall_mm") * kmm;
  p.side_wall = s.number("geometry.side_wall_mm") * kmm;
  p.roof = s.number("geometry.roof_mm") * kmm;
  p.end_cap = s.number("geometry.end_cap_mm") * kmm;
  p.channel_width = s.number("geometry.channel_width_mm") * kmm;
  p.channel_height = s.number("geometry.channel_height_mm") * kmm;
  p.fabric_z0 = s.number("geometry.fabric_z0_mm") * kmm;
  p.fabric_thickness = s.number("geometry.fabric_thickness_mm") * kmm;
  const MeshSettings m = mesh_settings(s);
  if (m.source != MeshSettings::Source::PneuNet)
    s.fail("mesh.source", "the built-in pneu-net's geometry needs mesh.source = \"pneunet\"");
  p.h = m.h_m;
  p.h_z = m.h_z_m;
  p.fabric_layers = m.fabric_layers;
  p.wall_layers = s.integer("mesh.wall_layers");
  if (p.wall_layers < 0) s.fail("mesh.wall_layers", "must be >= 0 (0 = from mesh.h_mm)");
  p.half = m.half;
  p.element = m.element;
  p.fabric_model = m.membrane_fabric ? FabricModel::Membrane : FabricModel::Solid;
  return p;
}

LoadSettings load_settings(const Scene& s) {
  LoadSettings l;
  l.protocol = choice<LoadSettings::Protocol>(s, "load.protocol", {{"staircase", LoadSettings::Protocol::Staircase},
                                                                   {"csv", LoadSettings::Protocol::Csv}});
  l.rest_s = s.number("load.rest_s");
  l.output_every_s = s.number("load.output_every_s");
  l.max_Pa = s.number("load.max_kPa") * kkPa;
  l.step_Pa = s.number("load.step_kPa") * kkPa;
  l.hold_s = s.number("load.hold_s");
  l.ramp_s = s.number("load.ramp_s");
  l.mark_s = s.number("load.mark_s");
  l.trials = s.integer("load.trials");
  l.csv = s.string("load.csv");
  return l;
}

/// The [solver] keys, each checked.
SolverSettings solver_settings(const Scene& s) {
  SolverSettings sv;
  sv.mode = choice<SolverSettings::Mode>(s, "solver.mode", {{"quasi_static", SolverSettings::Mode::QuasiStatic},
                                                           {"explicit", SolverSettings::Mode::Explicit}});
  sv.quasi_static.method = choice<EquilibriumMethod>(s, "solver.method", {{"newton", EquilibriumMethod::Newton},
                                                                          {"relaxation", EquilibriumMethod::Relaxation}});
  sv.quasi_static.newton.rel_tol = positive(s, "solver.rel_tol");
  sv.quasi_static.relaxation.rel_tol = sv.quasi_static.newton.rel_tol;
  sv.quasi_static.newton.max_iterations = s.integer("solver.max_iterations");
  if (sv.quasi_static.newton.max_iterations < 1) s.fail("solver.max_iterations", "must be >= 1");
  sv.quasi_static.newton.stiff_relaxation_steps = s.integer("solver.stiff_relaxation_steps");
  if (sv.quasi_static.newton.stiff_relaxation_steps < 0) s.fail("solver.stiff_relaxation_steps", "must be >= 0 (0 = off)");
  sv.quasi_static.newton.indefinite = choice<StaticOptions::Indefinite>(
      s, "solver.indefinite_tangent",
      {{"last_factor", StaticOptions::Indefinite::LastFactor}, {"shift", StaticOptions::Indefinite::Shift}});
  sv.quasi_static.newton.energy_line_search = choice<bool>(s, "solver.line_search", {{"energy", true}, {"slope", false}});
  sv.quasi_static.newton.max_increment_Pa = positive(s, "solver.max_increment_kPa") * kkPa;
  sv.quasi_static.newton.min_increment_Pa = positive(s, "solver.min_increment_kPa") * kkPa;
  sv.quasi_static.relaxation.max_iterations = s.integer("solver.relaxation_max_iterations");
  sv.quasi_static.newton.verbose = s.boolean("solver.verbose");
  sv.quasi_static.time_tol = positive(s, "solver.time_tol");
  sv.quasi_static.time_control =
      choice<TimeControl>(s, "solver.time_control", {{"change", TimeControl::Change}, {"error", TimeControl::Error}, {"drive", TimeControl::Drive}});
  sv.quasi_static.min_dt_s = positive(s, "solver.min_dt_s");
  sv.quasi_static.max_dt_s = positive(s, "solver.max_dt_s");
  if (sv.quasi_static.max_dt_s < sv.quasi_static.min_dt_s) s.fail("solver.max_dt_s", "must be >= solver.min_dt_s");
  sv.quasi_static.max_segment_steps = s.integer("solver.max_segment_steps");
  if (sv.quasi_static.max_segment_steps < 1) s.fail("solver.max_segment_steps", "must be >= 1");
  sv.quasi_static.cycle_jump.on = s.boolean("solver.cycle_jump");
  sv.quasi_static.cycle_jump.tol = positive(s, "solver.cycle_jump_tol");
  sv.quasi_static.cycle_jump.change = positive(s, "solver.cycle_jump_change");
  sv.quasi_static.newton.krylov_max_iterations = s.integer("solver.krylov_max_iterations");
  if (sv.quasi_static.newton.krylov_max_iterations < 0) s.fail("solver.krylov_max_iterations", "must be >= 0");
  sv.quasi_static.newton.krylov_on_ramps = s.boolean("solver.krylov_ramps");
  sv.explicit_dynamics.dt_safety = positive(s, "solver.dt_safety");
  if (sv.explicit_dynamics.dt_safety > 1.0) s.fail("solver.dt_safety", "must be <= 1 (fraction of the stable step)");
  sv.explicit_dynamics.target_dt_s = s.number("solver.target_dt_s");
  sv.explicit_dynamics.damping_alpha_1_s = s.number("solver.damping_1_s");
  if (sv.explicit_dynamics.damping_alpha_1_s < 0) s.fail("solver.damping_1_s", "must be >= 0");
  sv.explicit_dynamics.adaptive_damping = s.boolean("solver.adaptive_damping");
  sv.time_scale = positive(s, "solver.time_scale");
  sv.force_mass_scaling = s.boolean("solver.force_mass_scaling");
  sv.model = choice<SolverSettings::Model>(s, "solver.model", {{"full", SolverSettings::Model::Full},
                                                             {"reduced", SolverSettings::Model::Reduced}});
  sv.reduced.max_modes = s.integer("solver.reduced_modes");
  if (sv.reduced.max_modes < 1) s.fail("solver.reduced_modes", "must be >= 1");
  sv.reduced.ecsw_tolerance = positive(s, "solver.reduced_ecsw_tol");
  sv.reduced.softened_levels = s.integer("solver.reduced_softened_levels");
  sv.reduced.stiff_parts = choice<RomBasisOptions::StiffParts>(s, "solver.reduced_fabric", {{"linear", RomBasisOptions::StiffParts::linear},
                                                                                          {"exact", RomBasisOptions::StiffParts::exact},
                                                                                          {"sampled", RomBasisOptions::StiffParts::sampled}});
  sv.reduced.release_responses = s.boolean("solver.reduced_release_modes");
  if (sv.reduced.ecsw_tolerance >= 1.0) s.fail("solver.reduced_ecsw_tol", "must lie in (0, 1)");
  sv.reduced.ecsw_blocks = s.integer("solver.reduced_ecsw_blocks");
  if (sv.reduced.ecsw_blocks < 0) s.fail("solver.reduced_ecsw_blocks", "must be >= 0 (0: one block per softening cluster)");
  sv.reduced_check_deg = positive(s, "solver.reduced_check_deg");
  sv.reduced_check_at = choice<SolverSettings::CheckAt>(s, "solver.reduced_check_at", {{"tops", SolverSettings::CheckAt::Tops},
                                                                                       {"reports", SolverSettings::CheckAt::Reports}});
  sv.reduced_enrich_rounds = s.integer("solver.reduced_enrich_rounds");
  if (sv.model == SolverSettings::Model::Reduced && sv.mode != SolverSettings::Mode::QuasiStatic)
    s.fail("solver.model", "\"reduced\" needs solver.mode = \"quasi_static\"");
  return sv;
}

OutputSettings output_settings(const Scene& s) {
  OutputSettings o;
  o.vtu = s.string("output.vtu");
  if (o.vtu != "steps" && o.vtu != "all" && o.vtu != "none") s.fail("output.vtu", "must be \"steps\", \"all\" or \"none\"");
  return o;
}

std::string mode_name(SolverSettings::Mode mode) { return mode == SolverSettings::Mode::Explicit ? "explicit" : "quasi_static"; }

std::string model_name(SolverSettings::Model model) { return model == SolverSettings::Model::Reduced ? "reduced" : "full"; }

}  // namespace pneufem
