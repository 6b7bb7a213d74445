#pragma once
// Abaqus / CalculiX input decks (.inp): reading the mesh, sets, surfaces, boundary conditions and
// pressure faces of a user's model, and writing our meshes so CalculiX can run the identical mesh.
//
// Supported on read (case-insensitive keywords, continuation lines, comments "**"):
//   *NODE [, NSET=]            *ELEMENT, TYPE=<solid> [, ELSET=]
//   <solid>: tetrahedra C3D4, C3D10, read as they are; hexahedra C3D8, C3D20, wedges C3D6, C3D15 and
//        pyramids C3D5, split conformingly into tetrahedra (scenes/inp/solid_split.h: Abaqus node and face
//        numbering, the split rule, curved C3D20/C3D15 stay curved); element sets, regions, surfaces,
//        *DLOAD faces, node sets and *BOUNDARY follow the split, with a note counting it; mixed decks
//        of these shapes are fine
//   *ELEMENT, TYPE=<surface>, ELSET=  triangles (CPS3/CPS6, S3/S6, M3D3/M3D6, STRI3/STRI65, ...) and
//        quadrilaterals (CPS4/CPS4R/CPS8, S4/S4R/S8R, M3D4/M3D4R/M3D8, R3D4, ...): how Gmsh and other
//        meshers write named surfaces, of tetrahedral and hexahedral meshes; membrane/shell sheets,
//        also embedded in the solid, with a note -> the surface ELSET of the tetrahedron faces they
//        cover, matched by corner nodes (any winding; a quadrilateral covers the two tetrahedron
//        faces its solid's split cut it into, its corners in order around it), and a node set of
//        the same name unless one exists (the faces' nodes, a C3D20 face's new diagonal node
//        included); an element on no face is an error; line elements are skipped with a warning;
//        *MEMBRANE/SHELL SECTION: a warning naming mesh.fabric_surface
//   *NSET, NSET= [, GENERATE] [, INSTANCE=] [, INTERNAL]   (members may name other sets)
//   *ELSET, ELSET= [, GENERATE] [, INSTANCE=] [, INTERNAL]
//   *SURFACE, NAME= [, TYPE=ELEMENT]  lines "elset_or_element, Sn"  (S1..S4 tetrahedra, S1..S5
//        wedges and pyramids, S1..S6 hexahedra; a quadrilateral face -> the 2 tetrahedron faces
//        tiling it; CAE: "_Surf-1_S3, S3"), or a line naming another surface (its faces are added)
//   *DLOAD  lines "element_or_elset, Pn, magnitude"  (pressure faces as Sn; magnitudes kept)
//   *DSLOAD lines "surface, P, magnitude"  (CAE's pressure load: its faces join the *DLOAD faces)
//   *BOUNDARY lines "node_or_nset, first_dof[, last_dof[, value]]"  (dofs 1-3; value must be 0)
//   *INCLUDE, INPUT=file (relative to the including file)
//   *PART, NAME= ... *END PART; *ASSEMBLY, NAME= ... *END ASSEMBLY; *INSTANCE, NAME=, PART= ...
//        *END INSTANCE with the optional data lines "dx, dy, dz" and "xa, ya, za, xb, yb, zb, angle"
//        (translate, then turn by angle degrees about the axis a -> b, right-handed; Abaqus
//        Keywords Reference, *INSTANCE). Decks as Abaqus/CAE writes them (see below).
//   MODULI=INSTANTANEOUS | LONG TERM of *HYPERELASTIC or *VISCOELASTIC (Abaqus: whether the hyperelastic
//        constants are the instantaneous or the long-term response of a viscoelastic material), with
//        the *MATERIAL, NAME= above it, into InpDeck::moduli (build_model applies it to the scene's
//        materials.<m>.viscoelastic.moduli); any other value is an error naming the line
// Materials and *SOLID SECTION lines are read by a pass of their own (scenes/inp/materials.h), which a
// scene makes into its materials and parts where it does not set them (scenes/deck_materials.h); this
// reader passes over them without a note. Everything else (steps, outputs, amplitudes) is skipped
// with a warning. Ties, couplings, equations and contact (*TIE, *COUPLING,
// *MPC, *EQUATION, *CONTACT PAIR, ...) are ignored with a warning that says to merge the
// instances in Abaqus (Merge/Cut Instances): pneufem needs one conforming mesh.
// Not supported (an error says what to do): *INSTANCE imported from an earlier analysis
// (INSTANCE=/LIBRARY=), *NODE/*ELEMENT/*NSET/*ELSET with INPUT=, *NSET with ELSET=, non-Cartesian
// *NODE SYSTEM=, element types other than the solids above, the surface elements and lines.
// Errors are InputError("<file>:<line>: <what>; <what to do>").
//
// Conventions of the reader:
//  * set and surface names are stored upper-cased (Abaqus names are case-insensitive); a set
//    defined again (or by several ELSET= blocks) collects the union, as in CalculiX;
//  * region of an element = the ELSET= of its *ELEMENT block in lower case (so the canonical
//    names of regions:: round-trip), or "default";
//  * formulation variants (C3D8R, C3D8H, C3D20RH, C3D10M, C3D10HS, ...: suffixes H, R, I, M, S)
//    are read as their base type (with a warning); one element order per deck: linear (C3D4, C3D5,
//    C3D6, C3D8 -> Tet4; mesh.promote_to_tet10 recommended) or quadratic (C3D10, C3D15, C3D20 ->
//    Tet10);
//  * a split element's first tetrahedron keeps its id, the others get ids above the largest of
//    its id scope (the deck's, or its instance's); Mesh::element_label names the deck element:
//    "element 1043 (tet 3 of C3D8 57)", in a deck of several instances
//    "element Actuator-1.1043 (tet 3 of C3D8 Actuator-1.57)";
//  * a data line ending with ',' continues on the next line only where more entries are due
//    (element connectivity); elsewhere the trailing comma is ignored; blank fields in *NODE are 0;
//  * *INCLUDE is textual, as in CalculiX: a data block may continue into the included file;
//  * sets and *BOUNDARY/*DLOAD/*DSLOAD/*SURFACE lines may only name nodes, elements, sets and
//    surfaces defined above them; GENERATE skips undefined ids (with a warning), explicit lists
//    reject them;
//  * *DLOAD/*DSLOAD: each (element, face) once, the first magnitude wins (a differing repeat
//    warns); fixed_dofs: each (node, dof) once, in order of appearance (a split's new nodes last);
//  * warnings also report nodes used by no element and tetrahedra with non-positive volume (for
//    an element to be split it is an error naming the element and the node order to use).
//
// Parts and instances (scenes/inp/assembly.h):
//  * the nodes, elements, sets and surfaces of a *PART belong to every *INSTANCE of it, placed by
//    the instance (lines inside an *INSTANCE block, an independent instance's mesh, are placed
//    too); each instance numbers its own ids. With one instance the Mesh keeps the deck's ids;
//    with several (or nodes at the assembly level besides), Mesh::id_scopes offsets them to be
//    distinct and messages name them "Actuator-1.123";
//  * hexahedra, wedges and pyramids of a part are split in every instance, after the whole deck
//    is read, so the sets, surfaces and loads of the part and of the assembly follow the split;
//  * at the assembly level and in the history data, "Actuator-1.Set-1" / "Actuator-1.123" name an
//    instance's set / id; a set with INSTANCE=I lists I's ids and sets; a bare name is the
//    assembly's, else that of the one instance defining it (several: an error with the choices);
//  * the Mesh stores an instance's sets and surfaces as "ACTUATOR-1.SET-1" and, unless the
//    assembly or another instance has that name, also as "SET-1"; INTERNAL ones not at all;
//  * instances share no node: more than one with solid elements is a warning here and an error in
//    build_model (InpDeck::solid_instances).
//
// Where the code is: the reader is DeckReader (scenes/inp/reader.h, which lists the file of each
// group of keywords), on the text layer of scenes/inp/text.h (lines, *INCLUDE, fields, numbers);
// the writer is scenes/inp/writer.cpp; the split of solids into tetrahedra scenes/inp/solid_split.h.
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

/// A MODULI= parameter of the deck (see above).
struct InpModuli {
  std::string material;  ///< NAME= of the *MATERIAL it follows, upper case; empty before any *MATERIAL
  std::string value;     ///< the scene's word: "instantaneous" or "long_term"
  std::string where;     ///< "<file>:<line>" of its keyword line
};

struct InpDeck {
  Mesh mesh;  ///< coordinates scaled to metres
  std::vector<InpPressure> pressure_faces;         ///< all *DLOAD Pn, *DSLOAD P faces in order of appearance
  std::vector<std::pair<int, int>> fixed_dofs;     ///< (node index, dof 0..2) from *BOUNDARY
  std::vector<std::string> warnings;               ///< skipped keywords etc.
  std::vector<InpModuli> moduli;                   ///< every MODULI= of *HYPERELASTIC / *VISCOELASTIC, in order
  /// Instances (as the deck names them) that hold solid elements; empty for a deck without
  /// *INSTANCE. Instances share no node, so more than one is a mesh pneufem cannot simulate.
  std::vector<std::string> solid_instances;
};

/// Reads a deck; `length_to_m` converts the deck's length unit to metres (1e-3 for mm).
InpDeck read_inp(const std::string& path, double length_to_m);

/// The shortest text that reads back to exactly `v`, if it fits CalculiX's 20-character real field;
/// otherwise the most significant digits that fit (>= 14). How the writers put numbers in a deck.
std::string inp_real_text(double v);

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
