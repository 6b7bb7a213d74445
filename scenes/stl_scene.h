#pragma once
// mesh.source = "stl": the scene's [mesh] keys to the STL mesher (scenes/stl/mesher.h). Internal
// to scenes/ (build_model.cpp calls it), and the `mesh` command for its report.
#include <string>
#include <vector>

#include "engine/mesh.h"
#include "scenes/scene.h"
#include "scenes/stl/mesher.h"

namespace pneufem {

/// The mesh of mesh.file (a closed .stl or .obj surface) and, when mesh.cavity_file is given, the
/// cavity's surface. The surface's repairs (turned normals, dropped triangles) go to `warnings`.
/// Errors name the key (mesh.file, mesh.cavity_inlet_mm, mesh.fixed_face, ...) and where it was set.
Mesh stl_scene_mesh(const Scene& s, std::vector<std::string>* warnings = nullptr, StlMeshReport* report = nullptr);

}  // namespace pneufem
