#include "scenes/stl_scene.h"

#include "core/errors.h"
#include "scenes/scene_keys.h"
#include "scenes/scene_settings.h"

namespace pneufem {

namespace {

using detail::kmm;

/// The surface of `key` (mesh.file or mesh.cavity_file), read and checked; an error of the file
/// is prefixed with the key and where it was set.
TriSurface surface_of(const Scene& s, const std::string& key, double unit) {
  const std::string file = s.string(key);
  try {
    return read_closed_surface(s.resolve_path(file), unit);
  } catch (const SceneKeyError&) {
    throw;
  } catch (const InputError& e) {
    s.fail(key, e.what());
  }
}

StlMeshSpec stl_spec(const Scene& s) {
  StlMeshSpec spec;
  StuffingOptions& o = spec.stuffing;
  const MeshSettings m = mesh_settings(s);
  o.h = m.h_m;
  o.h_z = m.h_z_m;
  o.half = m.half;
  o.feature_planes = s.boolean("mesh.feature_planes");
  spec.wall_cells = s.integer("mesh.wall_cells");
  const std::vector<double> slab = s.numbers("mesh.fabric_slab_mm");
  if (!slab.empty()) {
    if (slab.size() != 2 || !(slab[0] < slab[1]))
      s.fail("mesh.fabric_slab_mm", "must be [z_bottom, z_top] with z_bottom < z_top (mm), or [] for no fabric layer");
    o.has_slab = true;
    o.slab_z0 = slab[0] * kmm;
    o.slab_z1 = slab[1] * kmm;
    o.slab_cells = m.fabric_layers;
  }
  spec.element = m.element;
  const std::vector<double> inlet = s.numbers("mesh.cavity_inlet_mm");
  if (inlet.size() == 3)
    spec.cavity_inlet = Eigen::Vector3d(inlet[0], inlet[1], inlet[2]) * kmm;
  else if (!inlet.empty())
    s.fail("mesh.cavity_inlet_mm", "must be [x, y, z] (mm), a point inside the chamber the inlet feeds, or [] for every "
                                   "interior void");
  spec.fixed_face = s.string("mesh.fixed_face");
  spec.fixed_point = s.vec3("mesh.fixed_point_mm") * kmm;
  spec.fixed_normal = s.vec3("mesh.fixed_normal");
  if (m.membrane_fabric && !o.has_slab)
    s.fail("mesh.fabric_model", "\"membrane\" with mesh.source = \"stl\" puts the membrane on the mid-plane of "
                                "mesh.fabric_slab_mm: give the fabric layer's z range there");
  o.slab_mid = m.membrane_fabric;
  return spec;
}

}  // namespace

Mesh stl_scene_mesh(const Scene& s, std::vector<std::string>* warnings, StlMeshReport* report) {
  const std::string file = s.string("mesh.file");
  if (file.empty()) s.fail("mesh.file", "mesh.source = \"stl\" needs the path of the actuator's .stl or .obj in mesh.file");
  const double unit = mesh_settings(s).length_unit_m;
  StlMeshSpec spec = stl_spec(s);
  TriSurface surface = surface_of(s, "mesh.file", unit);
  if (!s.string("mesh.cavity_file").empty()) {
    if (spec.cavity_inlet)
      s.fail("mesh.cavity_inlet_mm", "give either mesh.cavity_inlet_mm or mesh.cavity_file, not both (the cavity file's "
                                     "shells are the cavity)");
    const TriSurface cavity = surface_of(s, "mesh.cavity_file", unit);
    spec.cavity_first_shell = surface.shells();
    append_surface(surface, cavity, true);  // its shells bound voids of the solid
    try {
      close_and_orient(surface);
    } catch (const InputError& e) {
      s.fail("mesh.cavity_file", e.what());
    }
    for (int sh = spec.cavity_first_shell; sh < surface.shells(); ++sh)
      if (surface.shell_depth[sh] % 2 == 0)
        s.fail("mesh.cavity_file", "shell " + std::to_string(sh - spec.cavity_first_shell + 1) +
                                       " of the cavity surface does not lie inside the actuator's solid (mesh.file); "
                                       "the two files must be in the same frame and unit");
  }
  StlMeshReport rep;
  Mesh m;
  try {
    m = mesh_closed_surface(surface, spec, &rep);
  } catch (const SceneKeyError&) {
    throw;
  } catch (const InputError& e) {
    const std::string what = e.what();
    // The mesher names the key it refuses; others are the file's.
    for (const char* key : {"mesh.cavity_inlet_mm", "mesh.fixed_face", "mesh.fabric_slab_mm", "mesh.half", "mesh.wall_cells", "mesh.h_mm"})
      if (what.find(key) != std::string::npos)
        s.fail(key, what.rfind(std::string(key) + ": ", 0) == 0 ? what.substr(std::string(key).size() + 2) : what);
    s.fail("mesh.file", what);
  }
  if (warnings) warnings->insert(warnings->end(), rep.notes.begin(), rep.notes.end());
  if (report) *report = rep;
  return m;
}

}  // namespace pneufem
