#pragma once
// Abaqus / CalculiX input decks (.inp): reading the mesh, sets, surfaces, boundary conditions and
// pressure faces of a user's model, and writing our meshes so CalculiX can run the identical mesh.
//
// Supported on read (case-insensitive keywords, continuation lines, comments "**"):
//   *NODE [, NSET=]            *ELEMENT, TYPE=C3D4|C3D10 [, ELSET=]
//   *ELEMENT, TYPE=<triangle>, ELSET=  (CPS3/CPS6, S3/S6, M3D3/M3D6, STRI3/STRI65, ...: how Gmsh and
//        other meshers write named surfaces; membrane/shell sheets, also embedded in the solid, with a
//        note) -> the surface ELSET of the tetrahedron faces they cover, matched by corner nodes (any
//        winding), and a node set of the same name unless one exists; line and quadrilateral elements
//        are skipped with a warning; *MEMBRANE/SHELL SECTION: a warning naming mesh.fabric_surface
//   *NSET, NSET= [, GENERATE]  *ELSET, ELSET= [, GENERATE]   (members may name other sets)
//   *SURFACE, NAME= [, TYPE=ELEMENT]  lines "elset_or_element, S1..S4"
//   *DLOAD  lines "element_or_elset, Pn, magnitude"  (pressure faces; magnitudes kept)
//   *BOUNDARY lines "node_or_nset, first_dof[, last_dof[, value]]"  (dofs 1-3; value must be 0)
//   *INCLUDE, INPUT=file (relative to the including file)
// Everything else (materials, steps, outputs) is skipped: the scene maps sets to materials.
// Errors are InputError("<file>:<line>: <what>; <what to do>").
//
// Conventions of the reader:
//  * set and surface names are stored upper-cased (Abaqus names are case-insensitive); a set
//    defined again (or by several ELSET= blocks) collects the union, as in CalculiX;
//  * region of an element = the ELSET= of its *ELEMENT block in lower case (so the canonical
//    names of regions:: round-trip), or "default";
//  * C3D4H/C3D10H/C3D10M are read as C3D4/C3D10 (with a warning); one element order per deck;
//  * a data line ending with ',' continues on the next line only where more entries are due
//    (element connectivity); elsewhere the trailing comma is ignored; blank fields in *NODE are 0;
//  * *INCLUDE is textual, as in CalculiX: a data block may continue into the included file;
//  * sets and *BOUNDARY/*DLOAD/*SURFACE lines may only name nodes, elements and sets defined
//    above them; GENERATE skips undefined ids (with a warning), explicit lists reject them;
//  * *DLOAD: each (element, face) once, the first magnitude wins (a differing repeat warns);
//    fixed_dofs: each (node, dof) once, in order of appearance;
//  * warnings also report nodes used by no element and elements with non-positive volume.
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
/// The deck runs in CalculiX 2.20 and read_inp returns the same mesh (same node and element
/// order; names upper-cased, regions lower-cased). Details: elements are written in their
/// order, one *ELEMENT block per run of equal region; coordinates use the shortest exact text
/// when it fits CalculiX's 20-character real field, else the most digits that fit (>= 14);
/// an element set named like a region is read back as their union. Throws InputError for
/// names a deck cannot hold.
void write_inp_mesh(std::ostream& os, const Mesh& mesh, double length_to_m);

}  // namespace pneufem
