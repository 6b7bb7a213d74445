#pragma once
// Abaqus / CalculiX input decks (.inp): reading the mesh, sets, surfaces, boundary conditions and
// pressure faces of a user's model, and writing our meshes so CalculiX can run the identical mesh.
//
// Supported on read (case-insensitive keywords, continuation lines, comments "**"):
//   *NODE [, NSET=]            *ELEMENT, TYPE=<solid> [, ELSET=]
//   <solid>: tetrahedra C3D4, C3D10, read as they are; hexahedra C3D8, C3D20, wedges C3D6, C3D15 and
//        pyramids C3D5, split conformingly into tetrahedra (scenes/solid_split.h: Abaqus node and face
//        numbering, the split rule, curved C3D20/C3D15 stay curved); element sets, regions, surfaces,
//        *DLOAD faces, node sets and *BOUNDARY follow the split, with a note counting it; mixed decks
//        of these shapes are fine
//   *ELEMENT, TYPE=<triangle>, ELSET=  (CPS3/CPS6, S3/S6, M3D3/M3D6, STRI3/STRI65, ...: how Gmsh and
//        other meshers write named surfaces; membrane/shell sheets, also embedded in the solid, with a
//        note) -> the surface ELSET of the tetrahedron faces they cover, matched by corner nodes (any
//        winding), and a node set of the same name unless one exists; line and quadrilateral elements
//        are skipped with a warning; *MEMBRANE/SHELL SECTION: a warning naming mesh.fabric_surface
//   *NSET, NSET= [, GENERATE]  *ELSET, ELSET= [, GENERATE]   (members may name other sets)
//   *SURFACE, NAME= [, TYPE=ELEMENT]  lines "elset_or_element, Sn"  (S1..S4 tetrahedra, S1..S5
//        wedges and pyramids, S1..S6 hexahedra; a quadrilateral face -> the 2 tetrahedron faces tiling it)
//   *DLOAD  lines "element_or_elset, Pn, magnitude"  (pressure faces as Sn; magnitudes kept)
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
//  * formulation variants (C3D8R, C3D8H, C3D20RH, C3D10M, ...: suffixes H, R, I, M, S) are read as
//    their base type (with a warning); one element order per deck: linear (C3D4, C3D5, C3D6, C3D8
//    -> Tet4; mesh.promote_to_tet10 recommended) or quadratic (C3D10, C3D15, C3D20 -> Tet10);
//  * a split element's first tetrahedron keeps its id, the others get ids above the deck's largest;
//    Mesh::element_label names the deck element ("element 1043 (tet 3 of C3D8 57)");
//  * a data line ending with ',' continues on the next line only where more entries are due
//    (element connectivity); elsewhere the trailing comma is ignored; blank fields in *NODE are 0;
//  * *INCLUDE is textual, as in CalculiX: a data block may continue into the included file;
//  * sets and *BOUNDARY/*DLOAD/*SURFACE lines may only name nodes, elements and sets defined
//    above them; GENERATE skips undefined ids (with a warning), explicit lists reject them;
//  * *DLOAD: each (element, face) once, the first magnitude wins (a differing repeat warns);
//    fixed_dofs: each (node, dof) once, in order of appearance (a split's new nodes last);
//  * warnings also report nodes used by no element and tetrahedra with non-positive volume (for
//    an element to be split it is an error naming the element and the node order to use).
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
