#pragma once
// Abaqus / CalculiX input decks (.inp): reading the mesh, sets, surfaces, boundary conditions and
// pressure faces of a user's model, and writing our meshes so CalculiX can run the identical mesh.
//
// Supported on read (case-insensitive keywords, continuation lines, comments "**"):
//   *NODE [, NSET=]            *ELEMENT, TYPE=C3D4|C3D10 [, ELSET=]
//   *NSET, NSET= [, GENERATE]  *ELSET, ELSET= [, GENERATE]   (members may name other sets)
//   *SURFACE, NAME= [, TYPE=ELEMENT]  lines "elset_or_element, S1..S4"
//   *DLOAD  lines "element_or_elset, Pn, magnitude"  (pressure faces; magnitudes kept)
//   *BOUNDARY lines "node_or_nset, first_dof[, last_dof[, value]]"  (dofs 1-3; value must be 0)
//   *INCLUDE, INPUT=file (relative to the including file)
// Everything else (materials, steps, outputs) is skipped: the scene maps sets to materials.
// Errors are InputError("<file>:<line>: <what>; <what to do>").
#include <map>
#include <ostream>
#include <string>
#include <vector>

#include "engine/mesh.h"

namespace pneufem {

struct InpPressure {
  FaceRef face;
  double magnitude = 0.0;  ///< in the deck's stress unit (not converted)
};

struct InpDeck {
  Mesh mesh;  ///< coordinates scaled to metres
  std::vector<InpPressure> pressure_faces;         ///< all *DLOAD Pn faces in order of appearance
  std::vector<std::pair<int, int>> fixed_dofs;     ///< (node index, dof 0..2) from *BOUNDARY
  std::vector<std::string> warnings;               ///< skipped keywords etc.
};

/// Reads a deck; `length_to_m` converts the deck's length unit to metres (1e-3 for mm).
InpDeck read_inp(const std::string& path, double length_to_m);

/// Writes *NODE, *ELEMENT (grouped by region as ELSET=<region>), every node set, element set
/// and surface (element-face form) of `mesh`, coordinates divided by `length_to_m`
/// (so 1e-3 writes mm). Node/element numbers are the mesh's external ids.
void write_inp_mesh(std::ostream& os, const Mesh& mesh, double length_to_m);

}  // namespace pneufem
