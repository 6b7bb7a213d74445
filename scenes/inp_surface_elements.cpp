// Surface elements in a deck (inp_reader.h): a mesher (Gmsh among them) writes a deck's named
// boundary surfaces as triangular plane, shell or membrane elements, not as element-face *SURFACE
// blocks. pneufem reads them as the faces of its tetrahedra they cover: their *ELEMENT blocks are
// gathered while reading, and resolved to tetrahedron faces once the deck is read and split.
#include <algorithm>
#include <array>
#include <map>
#include <set>

#include "scenes/inp_reader.h"

namespace pneufem::inp {

/// Nodes of a triangular surface/shell/membrane/plane element type, or 0. Meshers (Gmsh among
/// them) write a deck's named boundary surfaces as such elements; pneufem reads them as faces of
/// its tetrahedra (DeckReader::finish).
int triangle_nodes(const std::string& type) {
  static const std::set<std::string> three = {"CPS3", "CPE3", "CAX3", "S3", "S3R", "S3RS", "STRI3", "M3D3",
                                              "SFM3D3", "DS3", "R3D3"};
  static const std::set<std::string> six = {"CPS6", "CPS6M", "CPE6", "CPE6M", "CAX6", "CAX6M", "S6",
                                            "STRI65", "M3D6", "SFM3D6", "DS6"};
  return three.count(type) ? 3 : six.count(type) ? 6 : 0;
}

/// Line and quadrilateral elements (trusses, beams, quad shells and planes): nothing a tetrahedral
/// model can use; a mesher writes them for named curves or quad-meshed faces.
bool skipped_element_type(const std::string& type) {
  static const std::set<std::string> skipped = {"T2D2", "T2D3", "T3D2", "T3D3", "B21", "B22", "B31", "B32", "B33",
                                                "R2D2", "CPS4", "CPS4R", "CPE4", "CPE4R", "CAX4", "CAX4R", "S4",
                                                "S4R", "M3D4", "M3D4R", "SFM3D4", "CPS8", "CPS8R", "CPE8", "CPE8R",
                                                "S8R", "M3D8", "M3D8R", "R3D4"};
  return skipped.count(type) != 0;
}

// ---- triangular surface elements (a mesher's named surfaces) -----------------------------------
void DeckReader::begin_surface_elements(const Keyword& kw, const Loc& loc, const std::string& type, int nodes) {
  type_name_ = type;
  npe_ = nodes;
  surface_set_ = upper(kw.get("ELSET"));
  if (surface_set_.empty())
    fail(loc, "*ELEMENT, TYPE=" + type + " without ELSET=",
         "name the surface (ELSET=CAVITY, say): pneufem reads triangular elements as named surfaces");
  warn_once("surface " + surface_set_, loc,
            "*ELEMENT, TYPE=" + type + ", ELSET=" + surface_set_ +
                " read as faces of the tetrahedra: surface and node set " + surface_set_ +
                " (usable as mesh.cavity_surface, fixed_set, tip_set, fabric_surface)");
  block_ = Block::SurfaceElement;
}

void DeckReader::surface_element_line(const Loc& loc) {
  if (!gather_element(loc)) return;
  SurfaceTriangle t{pending_[0], pending_loc_, {}};
  for (std::size_t k = 0; k < 3; ++k) t.corners[k] = element_node(pending_[k + 1]);
  surface_elements_[{scope_, surface_set_}].push_back(t);
  pending_.clear();
}

/// Each triangle of a surface element set -> the face of a tetrahedron it covers (matched by
/// its three corner nodes, so the triangle's own node order and order do not matter, and the
/// face's outward normal, which orients the cavity pressure, comes from the tetrahedron). A face
/// shared by two tetrahedra (an embedded sheet) is kept with a note: build_model refuses it as
/// a cavity, a membrane may lie there. The set becomes a surface and, unless a node set of that
/// name exists, a node set of the faces' nodes.
void DeckReader::resolve_surface_elements() {
  if (surface_elements_.empty()) return;
  Mesh& mesh = deck_.mesh;
  std::map<std::array<int, 3>, std::pair<FaceRef, int>> faces;  // sorted corners -> face, times seen
  for (int e = 0; e < mesh.num_elements(); ++e)
    for (int f = 0; f < 4; ++f) {
      const int* ln = face_local_nodes(mesh.type, f);
      std::array<int, 3> key = {mesh.element(e)[ln[0]], mesh.element(e)[ln[1]], mesh.element(e)[ln[2]]};
      std::sort(key.begin(), key.end());
      auto [it, inserted] = faces.try_emplace(key, FaceRef{e, f}, 0);
      ++it->second.second;
    }
  const int npf = nodes_per_face(mesh.type);
  for (const auto& [where_named, tris] : surface_elements_) {
    const auto& [scope_index, name] = where_named;
    Scope& s = scopes_[static_cast<std::size_t>(scope_index)];
    std::vector<FaceRef>& surface = s.surfaces[name];
    std::vector<int> nodes;
    std::size_t inside = 0;
    for (const SurfaceTriangle& t : tris) {
      std::array<int, 3> key = t.corners;
      std::sort(key.begin(), key.end());
      const auto it = faces.find(key);
      if (it == faces.end())
        fail(t.loc, "surface element " + std::to_string(t.id) + " (ELSET=" + name + ") matches no face of the tetrahedra",
             "its first three nodes must be the corners of a tetrahedron's face (export the surface from the same mesh" +
                 std::string(scopes_.size() > 1 ? "; in an assembly, from the same instance: merge the instances in "
                                                  "Abaqus (Merge/Cut Instances) so the mesh is conforming)"
                                                : ")"));
      if (it->second.second > 1) ++inside;  // an embedded sheet: only a membrane may use it
      surface.push_back(it->second.first);
      const int* ln = face_local_nodes(mesh.type, it->second.first.local_face);
      for (int a = 0; a < npf; ++a) nodes.push_back(mesh.element(it->second.first.element)[ln[a]]);
    }
    if (!s.node_sets.count(name)) {
      normalise(nodes);
      s.node_sets[name] = std::move(nodes);
    }
    if (inside > 0)
      deck_.warnings.push_back(where(tris.front().loc) + ": " + std::to_string(inside) + " of the " + std::to_string(tris.size()) +
                               " triangles of ELSET=" + name +
                               " lie inside the solid (two tetrahedra share each): an embedded sheet, usable as "
                               "the fabric membrane (mesh.fabric_surface), not as a cavity");
  }
}

}  // namespace pneufem::inp
