// The deck reader's pass over the deck (reader.h): the keyword dispatch, *NODE, *ELEMENT of
// solid elements, and the end of the deck (solids split into tetrahedra, surface elements resolved,
// names exported, advice); read_inp (scenes/inp/deck.h).
#include "scenes/inp/deck.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "engine/tet_element.h"
#include "scenes/inp/reader.h"

namespace pneufem {

namespace inp {

namespace {

/// Keywords that join surfaces or nodes (ties, couplings, equations, contact): pneufem applies
/// none of them, it needs one conforming mesh.
bool constraint_keyword(const std::string& name) {
  static const std::set<std::string> constraints = {
      "TIE", "COUPLING", "KINEMATIC COUPLING", "DISTRIBUTING COUPLING", "MPC", "EQUATION", "RIGID BODY",
      "CONTACT PAIR", "CONTACT", "CONTACT INCLUSIONS", "EMBEDDED ELEMENT", "SHELL TO SOLID COUPLING"};
  return constraints.count(name) != 0;
}

/// Keywords read by the materials pass (scenes/inp/materials.h), which a scene runs over the same deck:
/// no note that they are skipped here.
bool material_pass_keyword(const std::string& name) {
  static const std::set<std::string> material = {
      "MATERIAL", "HYPERELASTIC", "ELASTIC", "DENSITY", "MULLINS EFFECT", "VISCOELASTIC", "SOLID SECTION",
      "UNIAXIAL TEST DATA", "BIAXIAL TEST DATA", "PLANAR TEST DATA", "VOLUMETRIC TEST DATA", "SHEAR TEST DATA",
      "SIMPLE SHEAR TEST DATA"};
  return material.count(name) != 0;
}

// A C3D10 whose Jacobian falls below this fraction of its straight-sided tetrahedron's anywhere
// (nodes, integration points) is refused: at 0 it folds over itself (a mid-node a quarter of its
// edge off the midpoint, along the edge) and near 0 its stiffness and stresses are meaningless.
// 0.1 is Gmsh's own floor for curved elements (Mesh.HighOrderThresholdMin), so Gmsh's curved
// meshes pass; straight-sided elements have 1.
constexpr double kMinScaledJacobian = 0.1;

/// "0.62": a ratio in a message.
std::string ratio_text(double r) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", r);
  return buf;
}

/// InputError naming the most distorted C3D10 of `mesh` (read from `deck`) and how many there are,
/// when any falls below kMinScaledJacobian. Elements whose corners are inverted are left to the
/// warning about them (and to the element kernels' own check).
void refuse_distorted_tet10(const Mesh& mesh, const std::string& deck) {
  if (mesh.type != ElementType::Tet10) return;
  int distorted = 0;
  int worst = -1;
  Tet10Distortion worst_d;
  for (int e = 0; e < mesh.num_elements(); ++e) {
    if (!(corner_volume(mesh, e) > 0.0)) continue;
    const Tet10Distortion d = tet10_distortion(mesh, e);
    if (!(d.min_scaled_jacobian >= kMinScaledJacobian)) {
      ++distorted;
      if (worst < 0 || d.min_scaled_jacobian < worst_d.min_scaled_jacobian) worst = e, worst_d = d;
    }
  }
  if (distorted == 0) return;
  static constexpr int kEdge[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};
  const int* n = mesh.element(worst);
  const int k = worst_d.farthest_mid_node;
  const std::string where = worst_d.at_node >= 0 ? "at its node " + mesh.node_name(n[worst_d.at_node])
                                                 : "at an integration point";
  throw InputError(deck + ": " + mesh.element_label(worst) + " is a C3D10 too distorted to compute: its Jacobian falls to " +
                   ratio_text(worst_d.min_scaled_jacobian) + " of its straight-sided tetrahedron's " + where +
                   " (at least " + ratio_text(kMinScaledJacobian) + " is needed), its mid-node " + mesh.node_name(n[k]) +
                   " lying " + ratio_text(worst_d.mid_node_offset) + " edge lengths off the midpoint of edge " +
                   mesh.node_name(n[kEdge[k - 4][0]]) + "-" + mesh.node_name(n[kEdge[k - 4][1]]) + "; " +
                   std::to_string(distorted) +
                   " element(s) are so. Move the mid-nodes to the edge midpoints (or curve the edges less) or remesh");
}

}  // namespace

InpDeck DeckReader::read() {
  scopes_.emplace_back();  // the model / assembly level
  std::string_view text;
  Loc loc;
  bool any_line = false;
  while (lines_.next(text, loc)) {
    any_line = true;
    if (text.front() == '*')
      begin_block(text, loc);
    else
      data_line(text, loc);
  }
  end_block();
  if (!any_line)
    fail(Loc{0, std::max(1, lines_.last_line_of_top())}, "the deck is empty (no keyword or data lines)",
         "give a deck with *NODE and *ELEMENT, TYPE=C3D4 or C3D10 blocks");
  end_of_structure();
  finish();
  return std::move(deck_);
}

// ---- blocks -------------------------------------------------------------------------------
void DeckReader::begin_block(std::string_view text, const Loc& loc) {
  end_block();
  const Keyword kw = parse_keyword(text);
  if (recording_) return record_in_part(kw, text, loc);
  if (pending_instance_ >= 0) instantiate();  // its placement lines are read: now its part
  block_ = Block::Skip;
  material_keyword(kw, loc);  // and then skipped with a warning, as the rest of a material
  if (kw.name == "NODE")
    begin_nodes(kw, loc);
  else if (kw.name == "ELEMENT")
    begin_elements(kw, loc);
  else if (kw.name == "NSET" || kw.name == "ELSET")
    begin_set(kw, loc);
  else if (kw.name == "SURFACE")
    begin_surface(kw, loc);
  else if (kw.name == "DLOAD")
    block_ = Block::Dload;
  else if (kw.name == "DSLOAD")
    block_ = Block::Dsload;
  else if (kw.name == "BOUNDARY")
    block_ = Block::Boundary;
  else if (kw.name == "PART")
    begin_part(kw, loc);
  else if (kw.name == "END PART")
    fail(loc, "*End Part without *Part", "remove it, or add *Part, name=<name> where the part begins");
  else if (kw.name == "ASSEMBLY")
    begin_assembly(kw, loc);
  else if (kw.name == "END ASSEMBLY")
    end_assembly(loc);
  else if (kw.name == "INSTANCE")
    begin_instance(kw, loc);
  else if (kw.name == "END INSTANCE")
    end_instance(loc);
  else if (constraint_keyword(kw.name))
    warn_once("constraint " + kw.name, loc,
              "*" + kw.name + (kw.has("NAME") ? " " + kw.get("NAME") : std::string()) +
                  " ignored: pneufem applies no ties, couplings, equations or contact and needs one conforming "
                  "mesh; if it joins instances, merge the instances in Abaqus (Merge/Cut Instances) so the mesh "
                  "is conforming");
  else if (kw.name == "MEMBRANE SECTION" || kw.name == "SHELL SECTION")
    // A fabric modelled as membrane or shell elements: its triangles are read as a surface, so
    // say how to give it stiffness, since a solid-fabric scene would silently leave it out.
    warn_once("section " + upper(kw.get("ELSET")), loc,
              "*" + kw.name + ", ELSET=" + upper(kw.get("ELSET")) +
                  ": its elements are read as a surface, without stiffness; to model them as the fabric set "
                  "mesh.fabric_model = \"membrane\" and mesh.fabric_surface = \"" + upper(kw.get("ELSET")) +
                  "\" (thickness geometry.fabric_thickness_mm, E and nu from [materials.fabric])");
  else if (!material_pass_keyword(kw.name))
    warn_once("keyword " + kw.name, loc,
              "*" + kw.name +
                  " skipped (only the mesh, sets, surfaces, *DLOAD Pn, *DSLOAD P and *BOUNDARY are read here, the "
                  "materials and *SOLID SECTION lines by a scene; steps, amplitudes and outputs come from the scene)");
}

// Abaqus: *HYPERELASTIC, MODULI=LONG TERM | INSTANTANEOUS (the default) says which response the
// hyperelastic constants are when the material is also *VISCOELASTIC (Abaqus Analysis User's Manual,
// "Time domain viscoelasticity"); the parameter is read on *VISCOELASTIC too. The value's case, and
// an underscore for its space, are free.
void DeckReader::material_keyword(const Keyword& kw, const Loc& loc) {
  if (kw.name == "MATERIAL") {
    material_ = upper(kw.get("NAME"));
    return;
  }
  if ((kw.name != "HYPERELASTIC" && kw.name != "VISCOELASTIC") || !kw.has("MODULI")) return;
  const std::string written = kw.get("MODULI");
  std::string v = upper(written);
  std::replace(v.begin(), v.end(), '_', ' ');
  v.erase(std::unique(v.begin(), v.end(), [](char a, char b) { return a == ' ' && b == ' '; }), v.end());
  std::string word;
  if (v == "INSTANTANEOUS")
    word = "instantaneous";
  else if (v == "LONG TERM")
    word = "long_term";
  else
    fail(loc, "*" + kw.name + ", MODULI=" + written + ": unknown value",
         "use MODULI=INSTANTANEOUS (the hyperelastic constants are the instantaneous response, Abaqus's default) or "
         "MODULI=LONG TERM (they are the long-term, fully relaxed response)");
  deck_.moduli.push_back(InpModuli{material_, word, where(loc)});
}

void DeckReader::end_block() {
  if ((block_ == Block::Element || block_ == Block::SurfaceElement) && !pending_.empty()) {
    fail(pending_loc_,
         "element " + std::to_string(pending_[0]) + " lists " + std::to_string(pending_.size() - 1) +
             " nodes but a " + type_name_ + " has " + std::to_string(npe_),
         "list all its nodes (a line ending with ',' continues on the next data line)");
  }
  if (open_members_) unsorted_.insert(open_members_);
  open_members_ = nullptr;
  open_set_.clear();
  member_scope_ = -1;
  block_ = Block::None;
}

void DeckReader::data_line(std::string_view text, const Loc& loc) {
  if (recording_) {
    recording_->lines.push_back(RecordedLine{text, loc});
    return;
  }
  split_fields(text, fields_, trailing_comma_);
  switch (block_) {
    case Block::None:
      fail(loc, "data line before any keyword", "start the deck with a keyword line such as *NODE");
    case Block::Skip:
      return;
    case Block::Node:
      return node_line(loc);
    case Block::Element:
      return element_line(loc);
    case Block::SurfaceElement:
      return surface_element_line(loc);
    case Block::NodeSet:
    case Block::ElementSet:
      return set_line(loc);
    case Block::Surface:
      return surface_line(loc);
    case Block::Dload:
      return dload_line(loc);
    case Block::Dsload:
      return dsload_line(loc);
    case Block::Boundary:
      return boundary_line(loc);
    case Block::Placement:
      return placement_line(loc);
  }
}


// ---- *NODE --------------------------------------------------------------------------------
void DeckReader::begin_nodes(const Keyword& kw, const Loc& loc) {
  if (kw.has("INPUT")) fail(loc, "*NODE, INPUT= is not supported", "put the node lines in a file read with *INCLUDE");
  const std::string system = upper(kw.get("SYSTEM"));
  if (!system.empty() && system != "R")
    fail(loc, "*NODE, SYSTEM=" + system + " (non-Cartesian coordinates) is not supported",
         "write Cartesian coordinates (SYSTEM=R)");
  block_ = Block::Node;
  open_set(scope().node_sets, kw.get("NSET"));
}

void DeckReader::node_line(const Loc& loc) {
  const std::optional<long> id = parse_long(fields_[0]);
  if (!id || *id <= 0)
    fail(loc, "node id '" + std::string(fields_[0]) + "' is not a positive integer",
         "a *NODE data line is 'id, x, y, z'");
  if (fields_.size() < 4)
    fail(loc,
         "node " + std::to_string(*id) + " has " + std::to_string(fields_.size() - 1) +
             " coordinate(s) but pneufem needs 3-D nodes",
         "give 'id, x, y, z' (2-D decks are not supported)");
  Eigen::Vector3d x;
  for (int k = 0; k < 3; ++k) {
    const std::string_view f = fields_[static_cast<std::size_t>(k) + 1];
    const std::optional<double> v = f.empty() ? std::optional<double>(0.0) : parse_double(f);  // Abaqus: blank = 0
    if (!v)
      fail(loc,
           "node " + std::to_string(*id) + ": coordinate " + "xyz"[k] + " '" + std::string(f) +
               "' is not a finite number",
           "fix the value");
    x[k] = *v * length_to_m_;
  }
  Scope& s = scope();
  const int index = deck_.mesh.num_nodes();
  if (!s.node_index.try_emplace(*id, index).second)
    fail(loc, "node " + std::to_string(*id) + " is defined twice", "node ids must be unique: renumber or remove one");
  deck_.mesh.X.push_back(s.placement.apply(x));
  deck_.mesh.node_ids.push_back(*id);
  deck_.mesh.node_scope.push_back(static_cast<std::uint16_t>(scope_));
  s.max_node_id = std::max(s.max_node_id, *id);
  ++s.nodes;
  if (open_members_) open_members_->push_back(index);
}

// ---- *ELEMENT -----------------------------------------------------------------------------
void DeckReader::begin_elements(const Keyword& kw, const Loc& loc) {
  if (kw.has("INPUT"))
    fail(loc, "*ELEMENT, INPUT= is not supported", "put the element lines in a file read with *INCLUDE");
  const std::string type = upper(kw.get("TYPE"));
  if (type.empty()) fail(loc, "*ELEMENT without TYPE=", "add TYPE=C3D4 or TYPE=C3D10");
  if (const SurfaceShape shape = surface_element_shape(type); shape.corners > 0)
    return begin_surface_elements(kw, loc, type, shape);
  if (line_element_type(type)) {
    warn_once("type " + type, loc,
              "*ELEMENT, TYPE=" + type + " skipped (line elements: pneufem reads solids, and triangles and "
              "quadrilaterals as named surfaces)");
    block_ = Block::Skip;
    return;
  }
  const std::optional<SolidType> solid = solid_type(type);
  if (!solid)
    fail(loc,
         "element type " + type + " is not supported (pneufem reads the solid elements C3D4, C3D10, C3D5, C3D6, "
         "C3D15, C3D8 and C3D20, with the suffixes H, R, I, M, S)",
         "convert the mesh to one of them (triangular and quadrilateral surface elements such as CPS3, CPS6, "
         "CPS4, CPS8, S3, S4R are read as named surfaces; line elements are skipped)");
  solid_ = *solid;
  type_name_ = solid_name(solid_);
  if (type != type_name_)
    warn_once("type " + type, loc,
              type + " is read as " + type_name_ +
                  " (hybrid, reduced-integration, incompatible-mode or modified: the scene chooses the formulation)");
  const ElementType et = solid_quadratic(solid_) ? ElementType::Tet10 : ElementType::Tet4;
  if (!first_type_loc_) {
    deck_.mesh.type = et;
    first_type_loc_ = loc;
    first_type_ = type_name_;
  } else if (deck_.mesh.type != et) {
    fail(loc,
         "TYPE=" + type + " mixes element orders with the " + first_type_ + " elements of " + where(*first_type_loc_),
         "use one element order throughout (all linear: C3D4, C3D5, C3D6, C3D8; or all quadratic: C3D10, C3D15, "
         "C3D20)");
  }
  npe_ = solid_nodes(solid_);
  block_ = Block::Element;
  const std::string elset = kw.get("ELSET");
  open_set(scope().element_sets, elset);
  const std::string region = elset.empty() ? std::string("default") : lower(elset);
  if (deck_.mesh.find_region(region) < 0 && deck_.mesh.region_names.size() > kMaxRegions)
    fail(loc, "more than " + std::to_string(kMaxRegions + 1) + " distinct ELSET= names on *ELEMENT",
         "group the elements into fewer element sets (regions)");
  region_ = deck_.mesh.region_id(region);
}

/// Appends a data line of an *ELEMENT block (solid or surface: type_name_, npe_) to pending_
/// (id, then nodes). False while the element continues on the next line (trailing comma); true
/// when it is complete.
bool DeckReader::gather_element(const Loc& loc) {
  if (pending_.empty()) pending_loc_ = loc;
  for (const std::string_view f : fields_) {
    const std::optional<long> v = parse_long(f);
    if (!v) {
      const std::string who =
          pending_.empty() ? std::string("element id") : "element " + std::to_string(pending_[0]) + ": node";
      fail(loc, who + " '" + std::string(f) + "' is not an integer",
           "an *ELEMENT data line is 'id, node1, node2, ...'");
    }
    pending_.push_back(*v);
  }
  const std::size_t need = static_cast<std::size_t>(npe_) + 1;
  if (pending_.size() < need && trailing_comma_) return false;  // continued on the next data line
  if (pending_.size() != need)
    fail(pending_loc_,
         "element " + std::to_string(pending_[0]) + " lists " + std::to_string(pending_.size() - 1) +
             " nodes but a " + type_name_ + " has " + std::to_string(npe_),
         pending_.size() < need ? "list all its nodes (end a line with ',' to continue on the next)"
                                : "fix the connectivity (or the TYPE= of the block)");
  return true;
}

/// Index of node `node` of the element being read (pending_[0]); fails if it is not defined.
int DeckReader::element_node(long node) const {
  const auto& ids = scopes_[static_cast<std::size_t>(scope_)].node_index;
  const auto it = ids.find(node);
  if (it == ids.end())
    fail(pending_loc_,
         "element " + std::to_string(pending_[0]) + " refers to node " + std::to_string(node) +
             ", which is not defined",
         "define the node under *NODE before this *ELEMENT block, or fix the connectivity");
  return it->second;
}

void DeckReader::element_line(const Loc& loc) {
  if (!gather_element(loc)) return;
  const std::size_t need = static_cast<std::size_t>(npe_) + 1;
  Mesh& mesh = deck_.mesh;
  const long id = pending_[0];
  if (id <= 0) fail(pending_loc_, "element id " + std::to_string(id) + " is not positive", "use ids >= 1");
  const int index = solids_.size();
  Scope& s = scope();
  if (!s.element_index.try_emplace(id, index).second)
    fail(pending_loc_, "element " + std::to_string(id) + " is defined twice",
         "element ids must be unique: renumber or remove one");
  element_nodes_.clear();
  for (std::size_t k = 1; k < need; ++k) element_nodes_.push_back(element_node(pending_[k]));
  solids_.add(solid_, element_nodes_);
  solid_loc_.push_back(pending_loc_);
  solid_part_instance_.push_back(static_cast<std::uint16_t>(context_.empty() ? 0 : scope_));
  mesh.element_ids.push_back(id);
  mesh.element_scope.push_back(static_cast<std::uint16_t>(scope_));
  s.max_element_id = std::max(s.max_element_id, id);
  mesh.region.push_back(region_);
  if (open_members_) open_members_->push_back(index);
  pending_.clear();
}

// ---- end of deck --------------------------------------------------------------------------
void DeckReader::finish() {
  Mesh& mesh = deck_.mesh;
  const Loc end{0, std::max(1, lines_.last_line_of_top())};
  std::vector<std::string> unused_parts;
  for (const auto& [key, part] : parts_)
    if (!part.instanced) unused_parts.push_back(part.name);
  if (!unused_parts.empty() && instance_index_.empty() && solids_.size() == 0) {
    const PartDef& p = parts_.begin()->second;
    fail(p.loc, "part '" + p.name + "' is defined but never instanced, so the deck has no mesh",
         "instance it: *Assembly, name=Assembly / *Instance, name=" + p.name + "-1, part=" + p.name +
             " / *End Instance / *End Assembly");
  }
  if (!unused_parts.empty())
    deck_.warnings.push_back(lines_.file_name(0) + ": part(s) " + inp::join_names(unused_parts) +
                             " never instanced: their mesh is not read");
  if (mesh.num_nodes() == 0) fail(end, "the deck defines no nodes", "add a *NODE block with 'id, x, y, z' lines");
  if (solids_.size() == 0)
    fail(end, "the deck defines no elements", "add an *ELEMENT, TYPE=C3D4 or TYPE=C3D10 block");
  for (Scope& s : scopes_) {
    for (auto& [name, v] : s.node_sets) normalise(v);
    for (auto& [name, v] : s.element_sets) normalise(v);
  }
  split();
  resolve_surface_elements();
  for (Scope& s : scopes_)
    for (auto& [name, faces] : s.surfaces) {  // a face listed twice would be loaded twice
      std::unordered_set<long long> seen;
      std::erase_if(faces, [&](const FaceRef& f) {
        return !seen.insert(static_cast<long long>(f.element) * 4 + f.local_face).second;
      });
    }
  export_names();
  check_instances();
  number_scopes();
  // Advice the solver would otherwise give far less clearly.
  std::vector<char> used(static_cast<std::size_t>(mesh.num_nodes()), 0);
  for (int n : mesh.conn) used[static_cast<std::size_t>(n)] = 1;
  const auto unused = std::count(used.begin(), used.end(), 0);
  if (unused > 0)
    deck_.warnings.push_back(lines_.file_name(0) + ": " + std::to_string(unused) +
                             " node(s) belong to no element (they carry no stiffness)");
  int inverted = 0;
  int first_inverted = 0;
  for (int e = 0; e < mesh.num_elements(); ++e)
    if (corner_volume(mesh, e) <= 0.0 && inverted++ == 0) first_inverted = e;
  if (inverted > 0)
    deck_.warnings.push_back(lines_.file_name(0) + ": " + std::to_string(inverted) +
                             " element(s) have zero or negative volume (first: element " +
                             mesh.element_name(first_inverted) + "); check the node order");
  refuse_distorted_tet10(mesh, lines_.file_name(0));
  mesh.ensure_ids();
}

/// Hexahedra, wedges and pyramids -> tetrahedra (solid_split.h), those of every instance and of
/// the model/assembly level at once, so the sets and surfaces of every scope and the pressure
/// faces follow the split. New ids continue each scope's own (number_scopes offsets them later).
void DeckReader::split() {
  SplitSets sets;
  for (Scope& s : scopes_) {
    sets.node_sets.push_back(&s.node_sets);
    sets.element_sets.push_back(&s.element_sets);
    sets.surfaces.push_back(&s.surfaces);
  }
  split_solids(solids_, deck_, [&](int s) { return solid_where(s); }, sets);
  const Mesh& mesh = deck_.mesh;
  for (std::size_t e = 0; e < mesh.element_ids.size(); ++e) {
    long& last = scopes_[mesh.element_scope[e]].max_element_id;
    last = std::max(last, mesh.element_ids[e]);
  }
  for (std::size_t n = 0; n < mesh.node_ids.size(); ++n) {
    long& last = scopes_[mesh.node_scope[n]].max_node_id;
    last = std::max(last, mesh.node_ids[n]);
  }
}

/// Where solid element s was read, "<file>:<line>", and the part and instance when it is a
/// part's line read for an instance.
std::string DeckReader::solid_where(int s) const {
  const std::size_t i = static_cast<std::size_t>(s);
  const std::string w = where(solid_loc_[i]);
  const std::uint16_t instance = solid_part_instance_[i];
  return instance == 0 ? w : w + ": " + part_context(scopes_[instance]);
}

}  // namespace inp

InpDeck read_inp(const std::string& path, double length_to_m) {
  if (!(length_to_m > 0.0) || !std::isfinite(length_to_m))
    throw InputError(path + ": length_to_m = " + std::to_string(length_to_m) +
                     " is not a positive length; give the deck's length unit in metres (1e-3 for mm)");
  InpDeck deck = inp::DeckReader(path, length_to_m).read();
  for (std::string& w : deck.warnings) w = printable(w);  // deck text quoted in a note, as in errors
  return deck;
}

}  // namespace pneufem
