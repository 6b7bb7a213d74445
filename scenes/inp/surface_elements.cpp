// Surface elements in a deck (reader.h): a mesher (Gmsh among them) writes a deck's named
// boundary surfaces as plane, shell or membrane elements, not as element-face *SURFACE blocks:
// triangles on a tetrahedral mesh, quadrilaterals on a hexahedral one. pneufem reads them as the
// faces of its tetrahedra they cover: their *ELEMENT blocks are gathered while reading, and
// resolved to tetrahedron faces once the deck is read and its solids split.
#include <algorithm>
#include <array>
#include <map>
#include <set>

#include "scenes/inp/reader.h"

namespace pneufem::inp {

SurfaceShape surface_element_shape(const std::string& type) {
  // Abaqus plane stress/strain, axisymmetric, shell, membrane, surface and rigid elements, and the
  // CalculiX S8; their corners come first, mid-edge nodes after.
  static const std::map<std::string, SurfaceShape> shapes = [] {
    std::map<std::string, SurfaceShape> m;
    for (const char* t : {"CPS3", "CPE3", "CAX3", "S3", "S3R", "S3RS", "STRI3", "M3D3", "SFM3D3", "DS3", "R3D3"})
      m[t] = {3, 3};
    for (const char* t : {"CPS6", "CPS6M", "CPE6", "CPE6M", "CAX6", "CAX6M", "S6", "STRI65", "M3D6", "SFM3D6", "DS6"})
      m[t] = {3, 6};
    for (const char* t : {"CPS4", "CPS4R", "CPS4I", "CPE4", "CPE4R", "CPE4I", "CPE4H", "CPE4RH", "CPE4IH", "CAX4",
                          "CAX4R", "CAX4I", "CAX4H", "CAX4RH", "S4", "S4R", "S4R5", "S4RS", "S4RSW", "M3D4", "M3D4R",
                          "SFM3D4", "SFM3D4R", "DS4", "R3D4"})
      m[t] = {4, 4};
    for (const char* t : {"CPS8", "CPS8R", "CPE8", "CPE8R", "CPE8H", "CPE8RH", "CAX8", "CAX8R", "CAX8H", "CAX8RH",
                          "S8", "S8R", "S8R5", "M3D8", "M3D8R", "SFM3D8", "SFM3D8R", "DS8"})
      m[t] = {4, 8};
    return m;
  }();
  const auto it = shapes.find(type);
  return it == shapes.end() ? SurfaceShape{} : it->second;
}

bool line_element_type(const std::string& type) {
  static const std::set<std::string> lines = {"T2D2", "T2D3", "T3D2", "T3D3", "B21", "B22",
                                              "B31", "B32", "B33", "R2D2"};
  return lines.count(type) != 0;
}

// ---- reading the blocks --------------------------------------------------------------------------
void DeckReader::begin_surface_elements(const Keyword& kw, const Loc& loc, const std::string& type,
                                        const SurfaceShape& shape) {
  type_name_ = type;
  npe_ = shape.nodes;
  surface_corners_ = shape.corners;
  surface_set_ = upper(kw.get("ELSET"));
  if (surface_set_.empty())
    fail(loc, "*ELEMENT, TYPE=" + type + " without ELSET=",
         "name the surface (ELSET=CAVITY, say): pneufem reads triangular and quadrilateral elements as named "
         "surfaces");
  warn_once("surface " + surface_set_, loc,
            "*ELEMENT, TYPE=" + type + ", ELSET=" + surface_set_ + " read as faces of the tetrahedra" +
                (shape.corners == 4 ? " (a quadrilateral as the two of its split)" : "") + ": surface and node set " +
                surface_set_ + " (usable as mesh.cavity_surface, fixed_set, tip_set, fabric_surface)");
  block_ = Block::SurfaceElement;
}

void DeckReader::surface_element_line(const Loc& loc) {
  if (!gather_element(loc)) return;
  SurfaceElement t{pending_[0], pending_loc_, static_cast<std::uint16_t>(context_.empty() ? 0 : scope_),
                   surface_corners_, {-1, -1, -1, -1}};
  for (std::size_t k = 0; k < static_cast<std::size_t>(surface_corners_); ++k)
    t.corners[k] = element_node(pending_[k + 1]);
  surface_elements_[{scope_, surface_set_}].push_back(t);
  pending_.clear();
}

// ---- resolving them to faces of the tetrahedra -----------------------------------------------------
/// Each element of a surface element set -> the tetrahedron faces it covers, matched by corner
/// nodes, so neither its winding nor its first node matters, and the faces' outward normals,
/// which orient the cavity pressure, come from the tetrahedra. A triangle covers one face. A
/// quadrilateral covers the two faces that its solid's split cut it into (solid_split.h: along
/// the diagonal through its smallest node id; both diagonals are tried, so a deck's own tetrahedra
/// on a quadrilateral match too), listed in the order of (element, face) as a *SURFACE face of
/// the solid maps. A face shared by two tetrahedra (an embedded sheet) is kept with a note:
/// build_model refuses it as a cavity, a membrane may lie there. The set becomes a surface and,
/// unless a node set of that name exists, a node set of the faces' nodes (on a quadratic
/// quadrilateral, also the node the split put on its diagonal).
void DeckReader::resolve_surface_elements() {
  if (surface_elements_.empty()) return;
  Mesh& mesh = deck_.mesh;
  using Face = std::pair<FaceRef, int>;              // a tetrahedron face, the tetrahedra that have it
  std::map<std::array<int, 3>, Face> faces;           // sorted corners -> face
  for (int e = 0; e < mesh.num_elements(); ++e)
    for (int f = 0; f < 4; ++f) {
      const int* ln = face_local_nodes(mesh.type, f);
      std::array<int, 3> key = {mesh.element(e)[ln[0]], mesh.element(e)[ln[1]], mesh.element(e)[ln[2]]};
      std::sort(key.begin(), key.end());
      auto [it, inserted] = faces.try_emplace(key, FaceRef{e, f}, 0);
      ++it->second.second;
    }
  auto find = [&](int a, int b, int c) -> const Face* {
    std::array<int, 3> key = {a, b, c};
    std::sort(key.begin(), key.end());
    const auto it = faces.find(key);
    return it == faces.end() ? nullptr : &it->second;
  };
  const std::string other_instance =
      scopes_.size() > 1 ? "; in an assembly, from the same instance: merge the instances in Abaqus (Merge/Cut "
                           "Instances) so the mesh is conforming)"
                         : ")";
  const int npf = nodes_per_face(mesh.type);
  for (const auto& [where_named, elements] : surface_elements_) {
    const auto& [scope_index, name] = where_named;
    Scope& s = scopes_[static_cast<std::size_t>(scope_index)];
    std::vector<FaceRef>& surface = s.surfaces[name];
    std::vector<int> nodes;
    std::size_t inside = 0, quads = 0;
    for (const SurfaceElement& t : elements) {
      const auto& c = t.corners;
      std::array<const Face*, 2> tiles = {nullptr, nullptr};
      if (t.n_corners == 3) {
        tiles[0] = find(c[0], c[1], c[2]);
        if (!tiles[0])
          throw InputError(printable(surface_element_where(t) + ": surface element " + std::to_string(t.id) + " (ELSET=" + name +
                           ") matches no face of the tetrahedra; its first three nodes must be the corners of a "
                           "tetrahedron's face (export the surface from the same mesh" + other_instance));
      } else {
        ++quads;
        for (int d = 0; d < 2 && !tiles[1]; ++d) {  // the diagonal c[d] - c[d + 2]
          tiles = {find(c[d], c[d + 1], c[d + 2]), find(c[d + 2], c[(d + 3) % 4], c[d])};
          if (!tiles[0] || !tiles[1]) tiles = {nullptr, nullptr};
        }
        if (!tiles[0])
          throw InputError(printable(surface_element_where(t) + ": surface element " + std::to_string(t.id) + " (ELSET=" + name +
                           ") matches no quadrilateral face of the solid elements; its first four nodes, in order "
                           "around it (either way), must be the corners of a face of a hexahedron, wedge or pyramid "
                           "(export the surface from the same mesh" + other_instance));
        auto before = [](const Face* x, const Face* y) {
          return std::pair(x->first.element, x->first.local_face) < std::pair(y->first.element, y->first.local_face);
        };
        if (before(tiles[1], tiles[0])) std::swap(tiles[0], tiles[1]);
      }
      bool embedded = false;
      for (const Face* tile : tiles) {
        if (!tile) continue;
        embedded = embedded || tile->second > 1;  // an embedded sheet: only a membrane may use it
        surface.push_back(tile->first);
        const int* ln = face_local_nodes(mesh.type, tile->first.local_face);
        for (int a = 0; a < npf; ++a) nodes.push_back(mesh.element(tile->first.element)[ln[a]]);
      }
      if (embedded) ++inside;
    }
    if (!s.node_sets.count(name)) {
      normalise(nodes);
      s.node_sets[name] = std::move(nodes);
    }
    const char* what = quads == 0 ? " triangles" : quads == elements.size() ? " quadrilaterals" : " surface elements";
    if (inside > 0)
      deck_.warnings.push_back(where(elements.front().loc) + ": " + std::to_string(inside) + " of the " +
                               std::to_string(elements.size()) + what + " of ELSET=" + name +
                               " lie inside the solid (two tetrahedra share each): an embedded sheet, usable as "
                               "the fabric membrane (mesh.fabric_surface), not as a cavity");
  }
}

/// Where surface element t was read, "<file>:<line>", and the part and instance when it is a
/// part's line read for an instance (as solid_where).
std::string DeckReader::surface_element_where(const SurfaceElement& t) const {
  const std::string w = where(t.loc);
  return t.part_instance == 0 ? w : w + ": " + part_context(scopes_[t.part_instance]);
}

}  // namespace pneufem::inp
