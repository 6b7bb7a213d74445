// Sets in a deck (reader.h): *NSET and *ELSET blocks, and how a data line's tokens are looked
// up as ids, sets and surfaces of its scope (a part read for an instance, an instance, or the
// model/assembly level, where "Actuator-1.Set-1" names an instance's set).
#include <algorithm>
#include <array>

#include "scenes/inp/reader.h"

namespace pneufem::inp {

// ---- *NSET / *ELSET -----------------------------------------------------------------------
void DeckReader::begin_set(const Keyword& kw, const Loc& loc) {
  const bool nodes = kw.name == "NSET";
  const std::string key = nodes ? "NSET" : "ELSET";
  const std::string name = kw.get(key);
  if (name.empty()) fail(loc, "*" + key + " without " + key + "=<name>", "add the set name");
  if (nodes && kw.has("ELSET"))
    fail(loc, "*NSET, ELSET= (nodes of an element set) is not supported", "list the nodes or node sets instead");
  if (kw.has("INPUT")) fail(loc, "*" + key + ", INPUT= is not supported", "use *INCLUDE for the member lines");
  int members_in = -1;
  if (kw.has("INSTANCE")) {
    // An assembly-level set of one instance's nodes or elements: its data lines use that
    // instance's ids and set names.
    const std::string instance = kw.get("INSTANCE");
    if (scope_ != 0)
      fail(loc, "*" + key + ", INSTANCE= inside a part or an instance",
           "use INSTANCE= on assembly-level sets only (between the instances and *End Assembly)");
    const auto it = instance_index_.find(upper(instance));
    if (it == instance_index_.end())
      fail(loc, "*" + key + ", INSTANCE=" + instance + ": no such instance above",
           instance_index_.empty() ? std::string("define it with *Instance, name=" + instance + ", part=<part>")
                                   : "use one of " + inp::join_names(instance_names()));
    members_in = it->second;
  }
  block_ = nodes ? Block::NodeSet : Block::ElementSet;
  generate_ = kw.has("GENERATE");
  Scope& s = scope();
  open_set(nodes ? s.node_sets : s.element_sets, name);
  // CAE's INTERNAL sets (the element sets behind a *SURFACE, picked regions) are the deck's
  // plumbing: used while reading, not offered to the scene.
  if (kw.has("INTERNAL")) (nodes ? s.internal_node_sets : s.internal_element_sets).insert(open_set_);
  member_scope_ = members_in;
}

void DeckReader::set_line(const Loc& loc) {
  const bool nodes = block_ == Block::NodeSet;
  const char* kind = nodes ? "node" : "element";
  std::vector<int>& members = *open_members_;
  if (generate_) {
    const auto& ids = nodes ? home().node_index : home().element_index;
    std::array<long, 3> g{0, 0, 1};
    const std::size_t n = fields_.size();
    if (n < 2 || n > 3) fail(loc, "a GENERATE data line needs 'first, last[, step]'", "write e.g. '1, 100, 1'");
    for (std::size_t i = 0; i < n; ++i) {
      const std::optional<long> v = parse_long(fields_[i]);
      if (!v)
        fail(loc, "GENERATE value '" + std::string(fields_[i]) + "' is not an integer",
             "write 'first, last[, step]'");
      g[i] = *v;
    }
    const auto [first, last, step] = g;
    if (first < 1 || step <= 0 || last < first)
      fail(loc,
           "GENERATE range " + std::to_string(first) + ", " + std::to_string(last) + ", " + std::to_string(step) +
               " is empty or invalid",
           "give 1 <= first <= last and a positive step");
    const long count = (last - first) / step + 1;
    long found = 0;
    if (static_cast<std::size_t>(count) <= 4 * ids.size() + 64) {
      for (long k = 0; k < count; ++k) {
        const auto it = ids.find(first + k * step);
        if (it != ids.end()) {
          members.push_back(it->second);
          ++found;
        }
      }
    } else {  // huge sparse range: scan the defined ids instead
      const std::size_t before = members.size();
      for (const auto& [id, index] : ids)
        if (id >= first && id <= last && (id - first) % step == 0) members.push_back(index);
      std::sort(members.begin() + static_cast<std::ptrdiff_t>(before), members.end());  // hash order is arbitrary
      found = static_cast<long>(members.size() - before);
    }
    const long missing = count - found;
    if (missing > 0)
      deck_.warnings.push_back(at(loc) + "GENERATE " + std::to_string(first) + ", " + std::to_string(last) +
                               ", " + std::to_string(step) + " of " + open_set_ + ": " + std::to_string(missing) +
                               " undefined " + kind + " id(s) skipped");
    return;
  }
  for (const std::string_view f : fields_) {
    if (f.empty()) continue;
    if (const int index = find_id(nodes, f, loc, "set " + open_set_, "define it before this line or remove it from the set");
        index >= 0) {
      members.push_back(index);
    } else {
      const std::vector<int> other = named_set(nodes, f, loc, nodes ? "*NSET" : "*ELSET");  // copy: may be `members`
      members.insert(members.end(), other.begin(), other.end());
    }
  }
}

// ---- names and ids in data lines ------------------------------------------------------------
std::vector<std::string> DeckReader::instance_names() const {
  std::vector<std::string> out;
  for (std::size_t i = 1; i < scopes_.size(); ++i) out.push_back(scopes_[i].name);
  return out;
}

int DeckReader::qualifier(std::string_view token, std::string_view& rest) const {
  if (scope_ != 0 || instance_index_.empty()) return -1;
  const auto [instance, r] = inp::split_qualified(token);
  if (instance.empty()) return -1;
  const auto it = instance_index_.find(upper(instance));
  if (it == instance_index_.end()) return -1;
  rest = r;
  return it->second;
}

std::string DeckReader::id_text(int scope, long id) const {
  return scope == scope_ ? std::to_string(id) : scopes_[static_cast<std::size_t>(scope)].name + "." + std::to_string(id);
}

int DeckReader::find_id(bool nodes, std::string_view token, const Loc& loc, const std::string& context,
                        const std::string& todo) {
  int s = home_index();
  std::string_view rest = token;
  if (const int q = qualifier(token, rest); q >= 0) s = q;
  const std::optional<long> id = parse_long(rest);
  if (!id) return -1;
  const Scope& sc = scopes_[static_cast<std::size_t>(s)];
  const auto& ids = nodes ? sc.node_index : sc.element_index;
  const auto it = ids.find(*id);
  if (it != ids.end()) return it->second;
  std::string hint = todo;
  if (s == 0 && !instance_index_.empty())
    hint += "; at the assembly level a bare id names an assembly-level " + std::string(nodes ? "node" : "element") +
            ": write <instance>." + std::to_string(*id) + " (e.g. " + scopes_[1].name + "." + std::to_string(*id) +
            ") or put INSTANCE= on the set";
  fail(loc, std::string(nodes ? "node " : "element ") + id_text(s, *id) + " in " + context + " is not defined", hint);
}

template <class V>
V* DeckReader::find_named(std::map<std::string, V> Scope::*names, std::string_view token, const Loc& loc,
                          const std::string& context, const std::string& kind) {
  std::string_view rest;
  if (const int q = qualifier(token, rest); q >= 0) {
    auto& m = scopes_[static_cast<std::size_t>(q)].*names;
    const auto it = m.find(upper(rest));
    return it == m.end() ? nullptr : &it->second;
  }
  const std::string key = upper(token);
  const int h = home_index();
  auto& own = scopes_[static_cast<std::size_t>(h)].*names;
  if (const auto it = own.find(key); it != own.end()) return &it->second;
  if (h != 0) return nullptr;
  std::vector<std::size_t> in;
  for (std::size_t i = 1; i < scopes_.size(); ++i)
    if ((scopes_[i].*names).count(key)) in.push_back(i);
  if (in.empty()) return nullptr;
  if (in.size() > 1) {
    std::vector<std::string> instances, choices;
    for (std::size_t i : in) {
      instances.push_back(scopes_[i].name);
      choices.push_back(scopes_[i].name + "." + std::string(token));
    }
    fail(loc, kind + " '" + std::string(token) + "' in " + context + " is ambiguous: instances " +
                  inp::join_names(instances) + " each define one",
         "name one with its instance: " + inp::join_names(choices, " or "));
  }
  return &(scopes_[in[0]].*names).at(key);
}

const std::vector<int>& DeckReader::named_set(bool nodes, std::string_view name, const Loc& loc,
                                              const std::string& context) {
  const std::string kind = nodes ? "node" : "element";
  if (std::vector<int>* set = find_named(nodes ? &Scope::node_sets : &Scope::element_sets, name, loc, context,
                                         kind + " set")) {
    if (unsorted_.erase(set) != 0) normalise(*set);
    return *set;
  }
  const std::string set_name(name);  // an lvalue: GCC 12 warns (-Wrestrict) on "literal" + std::string(name)
  if (find_named(nodes ? &Scope::element_sets : &Scope::node_sets, name, loc, context, kind + " set"))
    fail(loc,
         "'" + set_name + "' in " + context +
             (nodes ? " is an element set, not a node set" : " is a node set, not an element set"),
         "use a " + kind + " set here");
  fail(loc, "unknown " + kind + " set '" + set_name + "' in " + context,
       "define it with *" + std::string(nodes ? "NSET" : "ELSET") + (nodes ? "" : " (or ELSET= on *ELEMENT)") +
           " before this line; set names are case-insensitive" +
           (instance_index_.empty() || scope_ != 0 ? "" : "; an instance's set is <instance>.<set> here"));
}

void DeckReader::open_set(std::map<std::string, std::vector<int>>& sets, const std::string& name) {
  open_set_ = upper(name);
  open_members_ = open_set_.empty() ? nullptr : &sets[open_set_];
}

void DeckReader::normalise(std::vector<int>& v) {
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
}

// find_named is used for sets (here) and surfaces (read_loads.cpp).
template std::vector<int>* DeckReader::find_named(std::map<std::string, std::vector<int>> Scope::*, std::string_view,
                                                  const Loc&, const std::string&, const std::string&);
template std::vector<FaceRef>* DeckReader::find_named(std::map<std::string, std::vector<FaceRef>> Scope::*,
                                                      std::string_view, const Loc&, const std::string&,
                                                      const std::string&);

}  // namespace pneufem::inp
