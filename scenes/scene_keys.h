#pragma once
// Reading scene keys into a model: the unit factors and the checks that the files behind
// build_model (build_model.cpp, scene_settings.cpp, scene_materials.cpp, angle_frame.cpp) share.
// Internal to scenes/.
#include <algorithm>
#include <cctype>
#include <initializer_list>
#include <map>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "engine/mesh.h"
#include "scenes/inp/assembly.h"
#include "scenes/scene.h"

namespace pneufem::detail {

/// Scene units to SI: the scene writes MPa, kPa and mm.
inline constexpr double kMPa = 1e6, kkPa = 1e3, kmm = 1e-3;

/// A failure naming the first key of table `table` that is not in `allowed`, with every allowed key.
void require_keys(const Scene& scene, const std::string& table, const std::set<std::string>& allowed,
                  const std::string& what);

/// The value of a string key that must be one of `options` (its name -> value), or a failure
/// naming the key and every allowed name.
template <class T>
T choice(const Scene& scene, const std::string& key, std::initializer_list<std::pair<const char*, T>> options) {
  const std::string v = scene.string(key);
  std::string allowed;
  std::size_t i = 0;
  for (const auto& [name, value] : options) {
    if (v == name) return value;
    allowed += std::string(i == 0 ? "" : i + 1 == options.size() ? " or " : ", ") + "\"" + name + "\"";
    ++i;
  }
  scene.fail(key, "must be " + allowed + ", got \"" + v + "\"");
}


/// The number of `key`, which must be > 0.
double positive(const Scene& scene, const std::string& key);

/// A name `key` gives that the mesh lacks but that several instances of a deck define (stored as
/// "INSTANCE.NAME" each, scenes/inp/assembly.h): a failure listing the qualified names to choose from.
template <class V>
void reject_ambiguous(const Scene& s, const std::string& key, const std::map<std::string, V>& names,
                      const std::string& name, const std::string& what) {
  std::string upper = name;
  std::transform(upper.begin(), upper.end(), upper.begin(), ::toupper);
  const std::vector<std::string> choices = inp::qualified_choices(names, upper);
  if (choices.size() > 1)
    s.fail(key, what + " '" + name + "' is defined by " + std::to_string(choices.size()) +
                    " instances of the deck; name one with its instance: " + inp::join_names(choices, " or "));
}

/// The node set named by the string key `key`, as written or upper-cased (decks' names are); a
/// failure when it is empty, ambiguous or missing (listing the sets the mesh has).
const std::vector<int>& node_set(const Scene& s, const Mesh& m, const std::string& key);

}  // namespace pneufem::detail
