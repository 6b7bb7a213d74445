// Abaqus assemblies in a deck (reader.h): *PART (its lines recorded), *ASSEMBLY, *INSTANCE
// (its placement, then its part's lines read in its id scope), and at the end of the deck the id
// scopes they made: the Mesh's set names, its id offsets, and the check that instances share no
// node. The placement and naming rules themselves are scenes/inp/assembly.h.
#include <algorithm>

#include "scenes/inp/reader.h"

namespace pneufem::inp {

// ---- *PART, *ASSEMBLY, *INSTANCE ------------------------------------------------------------
void DeckReader::begin_part(const Keyword& kw, const Loc& loc) {
  if (level_ != Level::Model)
    fail(loc, "*Part inside *Assembly", "define the parts before *Assembly (close the assembly with *End Assembly)");
  const std::string name = kw.get("NAME");
  if (name.empty()) fail(loc, "*Part without NAME=", "add NAME=<part name>");
  const auto [it, fresh] = parts_.try_emplace(upper(name), PartDef{name, loc, {}, false});
  if (!fresh)
    fail(loc, "part '" + name + "' is defined twice (first at " + where(it->second.loc) + ")",
         "rename one of them (part names are case-insensitive)");
  recording_ = &it->second;
  level_ = Level::Part;
}

/// A line of the part being recorded; *END PART ends it. Parts do not nest.
void DeckReader::record_in_part(const Keyword& kw, std::string_view text, const Loc& loc) {
  if (kw.name == "END PART") {
    recording_ = nullptr;
    level_ = Level::Model;
    return;
  }
  if (kw.name == "PART" || kw.name == "ASSEMBLY" || kw.name == "END ASSEMBLY" || kw.name == "INSTANCE" ||
      kw.name == "END INSTANCE")
    fail(loc, "*" + kw.name + " inside *Part '" + recording_->name + "' (" + where(recording_->loc) + ")",
         "close the part with *End Part first");
  recording_->lines.push_back(RecordedLine{text, loc});
}

void DeckReader::begin_assembly(const Keyword& kw, const Loc& loc) {
  if (assembly_loc_)
    fail(loc, "a second *Assembly (the first is at " + where(*assembly_loc_) + ")",
         "a deck has one assembly: put every *Instance into it");
  if (level_ != Level::Model) fail(loc, "*Assembly inside another block", "close that block first");
  assembly_loc_ = loc;
  scopes_[0].name = kw.get("NAME").empty() ? std::string("Assembly") : kw.get("NAME");
  level_ = Level::Assembly;
}

void DeckReader::end_assembly(const Loc& loc) {
  if (level_ == Level::Instance)
    fail(loc, "*End Assembly inside *Instance '" + scope().name + "' (" + where(scope().loc) + ")",
         "close the instance with *End Instance first");
  if (level_ != Level::Assembly)
    fail(loc, "*End Assembly without *Assembly", "remove it, or add *Assembly, name=Assembly before the instances");
  level_ = Level::Model;
}

void DeckReader::begin_instance(const Keyword& kw, const Loc& loc) {
  if (level_ == Level::Instance)
    fail(loc, "*Instance inside *Instance '" + scope().name + "' (" + where(scope().loc) + ")",
         "close that instance with *End Instance first");
  if (level_ != Level::Assembly)
    fail(loc, "*Instance outside *Assembly", "put the instances between *Assembly, name=Assembly and *End Assembly");
  if (kw.has("INSTANCE") || kw.has("LIBRARY"))
    fail(loc, "*Instance imported from a previous analysis (INSTANCE=, LIBRARY=) is not supported",
         "write the part into the deck (*Part ... *End Part) and instance it with PART=");
  const std::string name = kw.get("NAME"), part = kw.get("PART");
  if (name.empty() || part.empty())
    fail(loc, "*Instance without " + std::string(name.empty() ? "NAME=" : "PART="),
         "write *Instance, name=<instance>, part=<part>");
  if (name.find('.') != std::string::npos)
    fail(loc, "instance name '" + name + "' contains a '.'",
         "rename the instance: '.' separates an instance from its sets and ids ('Actuator-1.Set-1')");
  const auto p = parts_.find(upper(part));
  if (p == parts_.end())
    fail(loc, "instance '" + name + "' refers to part '" + part + "', which is not defined above",
         "define *Part, name=" + part + " ... *End Part before the assembly (part names are case-insensitive)");
  const auto [it, fresh] = instance_index_.try_emplace(upper(name), static_cast<int>(scopes_.size()));
  if (!fresh)
    fail(loc, "instance '" + name + "' is defined twice (first at " + where(scopes_[static_cast<std::size_t>(it->second)].loc) + ")",
         "rename one of them (instance names are case-insensitive)");
  if (scopes_.size() > kMaxScopes)
    fail(loc, "more than " + std::to_string(kMaxScopes) + " instances", "merge instances in Abaqus");
  p->second.instanced = true;
  Scope& s = scopes_.emplace_back();
  s.name = name;
  s.part = p->first;
  s.loc = loc;
  pending_instance_ = it->second;
  placement_lines_ = 0;
  level_ = Level::Instance;
  block_ = Block::Placement;
}

/// The data lines of *INSTANCE: a translation "dx, dy, dz", then optionally a rotation
/// "xa, ya, za, xb, yb, zb, angle" (degrees about the axis a -> b, applied after the translation).
void DeckReader::placement_line(const Loc& loc) {
  Scope& s = scopes_[static_cast<std::size_t>(pending_instance_)];
  const std::string what = "*Instance '" + s.name + "'";
  const std::size_t need = ++placement_lines_ == 1 ? 3 : 7;
  if (placement_lines_ > 2)
    fail(loc, what + " has a third data line",
         "an instance has a translation line (3 numbers) and optionally a rotation line (7 numbers: two "
         "points on the axis and the angle in degrees)");
  const char* form = need == 3 ? "'dx, dy, dz'" : "'xa, ya, za, xb, yb, zb, angle_deg' (two points on the axis, the angle in degrees)";
  if (fields_.size() != need)
    fail(loc, "the " + std::string(need == 3 ? "translation" : "rotation") + " line of " + what + " has " +
                  std::to_string(fields_.size()) + " values",
         "write " + std::string(form));
  std::array<double, 7> v{};
  for (std::size_t k = 0; k < need; ++k) {
    const std::optional<double> x = fields_[k].empty() ? std::optional<double>(0.0) : parse_double(fields_[k]);
    if (!x) fail(loc, what + ": '" + std::string(fields_[k]) + "' is not a finite number", "write " + std::string(form));
    v[k] = *x;
  }
  if (need == 3) {
    s.placement.t = Eigen::Vector3d(v[0], v[1], v[2]) * length_to_m_;
    return;
  }
  const Eigen::Vector3d a(v[0], v[1], v[2]), b(v[3], v[4], v[5]);
  if (v[6] == 0.0) return;
  if ((b - a).norm() == 0.0)
    fail(loc, what + ": the rotation axis has two equal points", "give two distinct points a, b on the axis");
  s.placement.a = a * length_to_m_;
  s.placement.R = inp::rotation_deg((b - a).normalized(), v[6]);
}

/// "part 'P' (instance 'I')": messages about a part's line read for instance s say so.
std::string DeckReader::part_context(const Scope& s) const {
  return "part '" + parts_.at(s.part).name + "' (instance '" + s.name + "')";
}

/// Reads the instance's part: its recorded lines in the instance's scope and placement.
void DeckReader::instantiate() {
  const int index = pending_instance_;
  pending_instance_ = -1;
  const Scope& s = scopes_[static_cast<std::size_t>(index)];
  const PartDef& part = parts_.at(s.part);
  scope_ = index;
  context_ = part_context(s) + ": ";
  for (const RecordedLine& l : part.lines) {
    if (l.text.front() == '*')
      begin_block(l.text, l.loc);
    else
      data_line(l.text, l.loc);
  }
  end_block();
  context_.clear();
}

void DeckReader::end_instance(const Loc& loc) {
  if (level_ != Level::Instance)
    fail(loc, "*End Instance without *Instance", "remove it, or add *Instance, name=<instance>, part=<part> above");
  level_ = Level::Assembly;
  scope_ = 0;
}

/// At the end of the deck: every *PART, *INSTANCE and *ASSEMBLY must be closed.
void DeckReader::end_of_structure() {
  if (recording_)
    fail(recording_->loc, "*Part '" + recording_->name + "' has no *End Part", "close the part with *End Part");
  if (level_ == Level::Instance) {
    const Scope& s = scopes_[static_cast<std::size_t>(pending_instance_ >= 0 ? pending_instance_ : scope_)];
    fail(s.loc, "*Instance '" + s.name + "' has no *End Instance", "close it with *End Instance");
  }
  if (level_ == Level::Assembly)
    fail(*assembly_loc_, "*Assembly has no *End Assembly",
         "close it with *End Assembly after the instances and the assembly's sets and surfaces");
}

// ---- id scopes at the end of the deck ------------------------------------------------------
/// The Mesh's set and surface names (assembly.h): the model/assembly level's as they are,
/// an instance's qualified and, when unambiguous, bare; INTERNAL ones not at all.
void DeckReader::export_names() {
  std::vector<inp::ScopedNames<std::vector<int>>> nsets, elsets;
  std::vector<inp::ScopedNames<std::vector<FaceRef>>> surfaces;
  for (std::size_t i = 0; i < scopes_.size(); ++i) {
    const Scope& s = scopes_[i];
    const std::string prefix = i == 0 ? std::string() : upper(s.name) + ".";
    nsets.push_back({prefix, &s.node_sets, &s.internal_node_sets});
    elsets.push_back({prefix, &s.element_sets, &s.internal_element_sets});
    surfaces.push_back({prefix, &s.surfaces, &s.internal_surfaces});
  }
  deck_.mesh.node_sets = inp::export_names(nsets);
  deck_.mesh.element_sets = inp::export_names(elsets);
  deck_.mesh.surfaces = inp::export_names(surfaces);
}

/// Scopes that hold nodes or elements.
int DeckReader::scopes_with_mesh() const {
  return static_cast<int>(std::count_if(scopes_.begin(), scopes_.end(), [](const Scope& s) { return s.nodes > 0; }));
}

/// Element e as the user knows it: "123", or "Actuator-1.123" once the deck has more than one
/// id scope with a mesh so far (as Mesh::element_name will name it; ids are still the deck's).
std::string DeckReader::element_name(int e) const {
  const Mesh& mesh = deck_.mesh;
  const long id = mesh.element_ids[static_cast<std::size_t>(e)];
  if (scopes_with_mesh() <= 1) return std::to_string(id);
  return scopes_[mesh.element_scope[static_cast<std::size_t>(e)]].name + "." + std::to_string(id);
}

/// Ids are per instance in a deck: with several scopes holding a mesh, each gets an offset
/// (the largest ids of the scopes before it) so the Mesh's ids are distinct, and the Mesh
/// keeps the scopes for its labels; with one, the deck's ids stay as they are.
void DeckReader::number_scopes() {
  Mesh& mesh = deck_.mesh;
  if (scopes_with_mesh() <= 1) {
    mesh.node_scope.clear();
    mesh.element_scope.clear();
    return;
  }
  long node_offset = 0, element_offset = 0;
  for (const Scope& s : scopes_) {
    mesh.id_scopes.push_back(Mesh::IdScope{s.name, node_offset, element_offset});
    node_offset += s.max_node_id;
    element_offset += s.max_element_id;
  }
  for (std::size_t n = 0; n < mesh.node_ids.size(); ++n) mesh.node_ids[n] += mesh.id_scopes[mesh.node_scope[n]].node_id_offset;
  for (std::size_t e = 0; e < mesh.element_ids.size(); ++e)
    mesh.element_ids[e] += mesh.id_scopes[mesh.element_scope[e]].element_id_offset;
  for (std::size_t e = 0; e < mesh.element_sources.size(); ++e)  // a split element's id, in the same scope
    mesh.element_sources[e].id += mesh.id_scopes[mesh.element_scope[e]].element_id_offset;
}

/// Instances never share nodes: several holding solid elements are separate bodies, which a
/// *TIE in Abaqus may join but pneufem cannot (build_model refuses such a model).
void DeckReader::check_instances() {
  std::vector<char> solid(scopes_.size(), 0);
  for (std::uint16_t s : deck_.mesh.element_scope) solid[s] = 1;
  for (std::size_t i = 0; i < scopes_.size(); ++i)
    if (solid[i] && (i > 0 || !instance_index_.empty())) deck_.solid_instances.push_back(scopes_[i].name);
  if (deck_.solid_instances.size() > 1)
    deck_.warnings.push_back(lines_.file_name(0) + ": the solid elements are in " +
                             std::to_string(deck_.solid_instances.size()) + " instances (" +
                             inp::join_names(deck_.solid_instances) +
                             ") that share no node, so the mesh is not connected and pneufem cannot simulate it; "
                             "merge the instances in Abaqus (Merge/Cut Instances) so the mesh is conforming");
}

}  // namespace pneufem::inp
