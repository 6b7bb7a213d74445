#pragma once
// A complete discrete problem: mesh, material parts, boundary conditions and loads.
// Built by scenes/ (from a scene file or an Abaqus deck); the engine never parses files.
// Units: SI throughout (m, kg, s, Pa).
#include <string>
#include <vector>

#include <Eigen/Core>

#include "engine/membrane.h"
#include "engine/mesh.h"
#include "materials/material.h"

namespace pneufem {

/// A material assignment: every element of the part uses `material` with mass density `density`.
struct Part {
  std::string name;
  MaterialPtr material;
  double density_kg_m3 = 1070.0;
};

/// How the bending angle is measured (engine/angle.h).
struct AngleSpec {
  std::vector<int> tip_nodes;                                  ///< nodes of the free end face
  Eigen::Vector3d fixed_normal_out = Eigen::Vector3d(0, -1, 0);  ///< outward normal of the fixed end face
  Eigen::Vector3d bend_direction = Eigen::Vector3d(0, 0, -1);    ///< direction the tip curls towards
  /// Mirror the tip nodes about this plane normal axis (0 = x) when the model is a half model
  /// with a symmetry plane through the origin; -1 = full model.
  int mirror_axis = -1;
};

struct Model {
  Mesh mesh;
  std::vector<Part> parts;
  std::vector<int> element_part;       ///< part index of each element
  std::vector<unsigned char> fixed;    ///< per dof (3 * nodes): 1 = prescribed zero displacement
  std::vector<FaceRef> pressure_faces; ///< faces loaded by the cavity pressure (follower load)
  /// Optional membrane layers (engine/membrane.h), e.g. the fabric modelled as a membrane;
  /// their nodes are nodes of the mesh. Empty = solid elements only.
  std::vector<MembraneSet> membranes;
  Eigen::Vector3d gravity_m_s2 = Eigen::Vector3d::Zero();
  AngleSpec angle;

  int num_dofs() const { return 3 * mesh.num_nodes(); }
  const Material& material_of(int e) const { return *parts[element_part[e]].material; }
};

/// Checks the internal consistency of a model (sizes, indices, materials present, something
/// fixed, tip nodes present); throws InputError naming the problem.
void validate(const Model& model);

}  // namespace pneufem
