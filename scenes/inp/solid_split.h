#pragma once
// Decks of hexahedra, wedges and pyramids on pneufem's tetrahedral engine: every solid element of a
// deck is split into tetrahedra, conformingly, and the deck's sets, surfaces, *DLOAD faces and
// *BOUNDARY dofs follow the split.
//
// Element conventions, 1-based as in a deck (Abaqus Elements Guide, "Three-dimensional solid element
// library": node ordering and face numbering; CalculiX numbers the same faces alike: ccx
// src/getnodel.f, tables ifaceq (C3D8/C3D20), ifacew1 (C3D6), ifacew2 (C3D15) list each face's
// corner and mid-edge nodes, in the outward order; the Abaqus lists below run inward):
//   C3D8   corners 1-2-3-4 around one face, counter-clockwise seen from the opposite face 5-6-7-8,
//          node 4+i opposite node i. Faces S1 1-2-3-4, S2 5-8-7-6, S3 1-5-6-2, S4 2-6-7-3, S5 3-7-8-4,
//          S6 4-8-5-1.
//   C3D20  the C3D8 corners, then the mid-edge nodes 9 (1-2), 10 (2-3), 11 (3-4), 12 (4-1), 13 (5-6),
//          14 (6-7), 15 (7-8), 16 (8-5), 17 (1-5), 18 (2-6), 19 (3-7), 20 (4-8).
//   C3D6   triangle 1-2-3 counter-clockwise seen from the opposite triangle 4-5-6, node 3+i opposite
//          node i. Faces S1 1-2-3, S2 4-6-5, S3 1-4-5-2, S4 2-5-6-3, S5 3-6-4-1.
//   C3D15  the C3D6 corners, then 7 (1-2), 8 (2-3), 9 (3-1), 10 (4-5), 11 (5-6), 12 (6-4), 13 (1-4),
//          14 (2-5), 15 (3-6).
//   C3D5   pyramid (Abaqus; CalculiX has none): base 1-2-3-4 counter-clockwise seen from the apex 5.
//          Faces S1 1-2-3-4, S2 1-5-2, S3 2-5-3, S4 3-5-4, S5 4-5-1: the C3D8 faces with the face
//          5-8-7-6 collapsed into the apex.
//   C3D4, C3D10 as engine/mesh.h (kept as they are).
// Formulation suffixes (H hybrid, R reduced integration, I incompatible modes, M modified, S) are
// dropped: the scene chooses the formulation of the tetrahedra.
//
// The split (Dompierre, Labbe, Vallet & Camarero 1999, "How to subdivide pyramids, prisms and
// hexahedra into tetrahedra", 8th International Meshing Roundtable): every quadrilateral face is cut
// along the diagonal through its corner of smallest node id. The two elements sharing a face see the
// same four ids and cut it alike, so the tetrahedra are conforming without any search. Within an
// element, the corner v of smallest id is the smallest corner of each face it touches, so all those
// faces are cut through v, and the element is the union of the cones from v over the triangles of
// the faces not touching v: pyramid 2, wedge 3, hexahedron 6 tetrahedra, always, with no interior
// (Steiner) point. A hexahedron whose three faces away from v are cut along diagonals that avoid the
// corner opposite v is split into 5 instead (its four other corners cut off around one central
// tetrahedron), which gives better-shaped tetrahedra.
//
// Quadratic elements (C3D20, C3D15) become Tet10: the element's own mid-edge nodes are kept; a cut
// diagonal gets one new node, shared by the elements of its face, at the element's isoparametric
// image of the diagonal's parametric midpoint (so curved elements stay curved). A new node joins a
// node set, and gets a *BOUNDARY dof, when every node of the face it lies on (of the element, for a
// body diagonal) has it: a fixed face stays fixed.
#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "scenes/inp/deck.h"

namespace pneufem {

/// The solid element types a deck may hold, formulation suffixes dropped (C3D8RH -> C3D8).
enum class SolidType : std::uint8_t { C3D4, C3D10, C3D5, C3D6, C3D15, C3D8, C3D20 };

/// C3D4 ... C3D20 of a deck's TYPE= (upper case; C3D8, C3D8H, C3D8R, C3D8I, C3D8RH, C3D8IH, ...),
/// or nullopt when it is no solid element pneufem reads.
std::optional<SolidType> solid_type(const std::string& type);
const char* solid_name(SolidType t);
int solid_nodes(SolidType t);  ///< nodes per element (4, 10, 5, 6, 15, 8, 20)
int solid_faces(SolidType t);  ///< faces S1..Sn (4, 4, 5, 5, 5, 6, 6)
bool solid_quadratic(SolidType t);

/// The image x(xi) of a reference point under the element's isoparametric map (every type but the
/// pyramid, whose shape functions are rational and which is linear only). Reference coordinates: C3D8/C3D20
/// [-1, 1]^3 with node 1 at (-1, -1, -1), 2 (1, -1, -1), 3 (1, 1, -1), 5 (-1, -1, 1); C3D6/C3D15
/// (g, h, r) with g, h >= 0, g + h <= 1, r in [-1, 1], node 1 at (0, 0, -1), 2 (1, 0, -1),
/// 3 (0, 1, -1), 4 (0, 0, 1); C3D4/C3D10 barycentric (node 1 at 0, 2 at (1, 0, 0), ...); C3D5
/// base (+-1, +-1, 0), apex (0, 0, 1).
Eigen::Vector3d solid_point(SolidType t, const int* nodes, const std::vector<Eigen::Vector3d>& X,
                            const Eigen::Vector3d& xi);
/// Reference coordinates of node `k` (0-based) of an element of type `t`.
Eigen::Vector3d solid_reference_node(SolidType t, int k);

/// The solid elements of a deck in the order read.
struct SolidElements {
  std::vector<SolidType> type;
  std::vector<int> first = {0};  ///< element s has nodes[first[s] .. first[s + 1])
  std::vector<int> nodes;        ///< node indices

  int size() const { return static_cast<int>(type.size()); }
  const int* element(int s) const { return nodes.data() + first[static_cast<std::size_t>(s)]; }
  void add(SolidType t, const std::vector<int>& element_nodes) {
    type.push_back(t);
    nodes.insert(nodes.end(), element_nodes.begin(), element_nodes.end());
    first.push_back(static_cast<int>(nodes.size()));
  }
};

/// Sets that a split carries over besides those of deck.mesh: a deck reader keeps the sets and
/// surfaces of each id scope (the assembly, every instance) apart until the deck is read.
struct SplitSets {
  std::vector<std::map<std::string, std::vector<int>>*> node_sets, element_sets;
  std::vector<std::map<std::string, std::vector<FaceRef>>*> surfaces;
};

/// Replaces the solid elements by tetrahedra in `deck`, whose mesh so far holds the nodes, node sets,
/// and per solid element its external id and region, and whose element sets, surfaces and
/// pressure_faces refer to solid elements (FaceRef::local_face = Abaqus face number - 1); so do
/// those of `also`. Afterwards they refer to the tetrahedra: an element set holds every tetrahedron
/// of its elements, a face maps to the 2 (quadrilateral) or 1 (triangle) tetrahedron faces that
/// tile it, in order. mesh.type must be the deck's order (Tet4 for linear, Tet10 for quadratic
/// elements). The first tetrahedron of an element keeps its id, the others get ids above the
/// largest of the element's id scope, new nodes above the largest node id of theirs: with
/// mesh.element_scope / node_scope filled per element / node (the instances of a deck, which number
/// their ids each on its own, before the reader numbers them apart) ids stay distinct per scope and
/// the tetrahedra and new nodes join their element's scope; without, the deck is one scope.
/// mesh.element_sources says where each tetrahedron came from when anything was split. A note
/// (warning) counts what was split. `where(s)` locates solid s's data line for messages.
/// Throws InputError(where(s) + ": ...") for an element that repeats a node or whose split has a
/// tetrahedron of zero or negative volume (inverted, wrongly numbered or degenerate).
void split_solids(const SolidElements& solids, InpDeck& deck, const std::function<std::string(int)>& where,
                  const SplitSets& also = {});

/// mesh.promote_to_tet10 for a deck: promote_to_tet10 of the mesh, and its *BOUNDARY dofs extended
/// to the new mid-edge nodes whose two corners both have the dof fixed (as promote_to_tet10 does
/// for node sets), so a face fixed node by node stays fixed. The faces of pressure_faces map one to
/// one.
void promote_deck_to_tet10(InpDeck& deck);

}  // namespace pneufem
