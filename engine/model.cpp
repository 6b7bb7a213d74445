#include "engine/model.h"

#include <algorithm>
#include <sstream>

#include "core/errors.h"

namespace pneufem {

void validate(const Model& m) {
  const int ne = m.mesh.num_elements(), nn = m.mesh.num_nodes();
  if (nn == 0 || ne == 0) throw InputError("the model has no nodes or no elements");
  for (int v : m.mesh.conn)
    if (v < 0 || v >= nn) throw InputError("element connectivity refers to a node index outside the mesh");
  if (static_cast<int>(m.element_part.size()) != ne)
    throw InputError("internal: element_part has the wrong size");
  std::vector<int> unassigned;
  for (int e = 0; e < ne; ++e) {
    const int p = m.element_part[e];
    if (p < 0 || p >= static_cast<int>(m.parts.size()) || !m.parts[p].material) unassigned.push_back(e);
  }
  if (!unassigned.empty()) {
    std::ostringstream s;
    s << unassigned.size() << " element(s) have no material, e.g. " << m.mesh.element_label(unassigned[0])
      << ": map every element set to a material in the scene's [[parts]] table";
    throw InputError(s.str());
  }
  for (const Part& p : m.parts)
    if (!(p.density_kg_m3 > 0.0)) throw InputError("part '" + p.name + "': density must be > 0 kg/m^3");
  if (static_cast<int>(m.fixed.size()) != 3 * nn) throw InputError("internal: fixed-dof mask has the wrong size");
  if (std::none_of(m.fixed.begin(), m.fixed.end(), [](unsigned char c) { return c != 0; }))
    throw InputError("no degree of freedom is fixed: name the fixed node set (scene key 'fixed_set')");
  for (const FaceRef& f : m.pressure_faces)
    if (f.element < 0 || f.element >= ne || f.local_face < 0 || f.local_face > 3)
      throw InputError("a pressure face refers to an element or face number outside the mesh");
  const int npf = nodes_per_face(m.mesh.type);
  for (const MembraneSet& ms : m.membranes) {
    if (!(ms.thickness_m > 0.0)) throw InputError("membrane '" + ms.name + "': thickness must be > 0 m");
    if (!(ms.density_kg_m3 > 0.0)) throw InputError("membrane '" + ms.name + "': density must be > 0 kg/m^3");
    if (ms.nodes.empty() || ms.nodes.size() % npf != 0)
      throw InputError("membrane '" + ms.name + "': needs a positive whole number of triangles of " +
                       std::to_string(npf) + " nodes (Tri" + std::to_string(npf) + " on this mesh)");
    for (int n : ms.nodes)
      if (n < 0 || n >= nn) throw InputError("membrane '" + ms.name + "': a triangle node index is outside the mesh");
  }
  for (int n : m.angle.tip_nodes)
    if (n < 0 || n >= nn) throw InputError("a tip node index is outside the mesh");
}

}  // namespace pneufem
