#pragma once
// Abaqus assemblies in decks (the rules the deck reader applies to *PART / *INSTANCE, in
// scenes/inp/read_parts.cpp): where an instance places its part, and the names under which the
// sets and surfaces of instances are stored in a Mesh, so a scene may write a name either as the
// deck's assembly level would ("Actuator-1.Set-1") or bare ("Set-1") when that is unambiguous.
#include <map>
#include <set>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

namespace pneufem::inp {

/// Placement of a part instance (the data lines of *INSTANCE): translate by t, then rotate by
/// angle_deg about the axis through the points a and b (right-handed about a -> b; a and b are
/// assembly coordinates, i.e. already translated). Abaqus Keywords Reference, *INSTANCE:
/// "If both translation and rotation are specified, translation is applied before rotation."
struct Placement {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d a = Eigen::Vector3d::Zero();  ///< a point on the rotation axis
  Eigen::Vector3d t = Eigen::Vector3d::Zero();  ///< translation

  /// Assembly coordinates of the part point x.
  Eigen::Vector3d apply(const Eigen::Vector3d& x) const { return a + R * (x + t - a); }
};

/// Rotation by angle_deg about the unit vector k, right-handed (Rodrigues). Multiples of 90
/// degrees are exact (cos and sin taken as 0 and +-1), so a part turned a quarter turn lands on
/// the same coordinates as one meshed in place.
Eigen::Matrix3d rotation_deg(const Eigen::Vector3d& k, double angle_deg);

/// Splits "INSTANCE.REST" at its first '.'; {"", token} without a dot.
std::pair<std::string_view, std::string_view> split_qualified(std::string_view token);

/// The keys of `names` that qualify the upper-case bare `name` with an instance
/// ("INSTANCE.NAME"): the choices when a bare name is defined by several instances.
template <class V>
std::vector<std::string> qualified_choices(const std::map<std::string, V>& names, const std::string& name) {
  std::vector<std::string> out;
  const std::string suffix = "." + name;
  for (const auto& [key, value] : names)
    if (key.size() > suffix.size() && key.ends_with(suffix) &&
        key.find('.') == key.size() - suffix.size())
      out.push_back(key);
  return out;
}

/// "A, B and C" (`last` = " or ": "A, B or C").
std::string join_names(const std::vector<std::string>& names, const char* last = " and ");

/// One id scope's named sets (node sets, element sets or surfaces) for export_names.
template <class V>
struct ScopedNames {
  std::string prefix;  ///< "" for the model/assembly level, else "INSTANCE." (upper case)
  const std::map<std::string, V>* names = nullptr;
  const std::set<std::string>* hidden = nullptr;  ///< names not exported (INTERNAL)
};

/// The names a Mesh stores: those of the model/assembly level as they are; those of an instance
/// both qualified ("INSTANCE.NAME") and bare when no other instance, and not the assembly level,
/// defines that name (Abaqus resolves a bare name at the assembly level first).
template <class V>
std::map<std::string, V> export_names(const std::vector<ScopedNames<V>>& scopes) {
  auto hidden = [](const ScopedNames<V>& s, const std::string& name) {
    return s.hidden && s.hidden->count(name) != 0;
  };
  std::map<std::string, V> out;
  std::map<std::string, int> instances_defining;  // bare name -> number of instances
  for (const ScopedNames<V>& s : scopes)
    for (const auto& [name, value] : *s.names)
      if (!hidden(s, name)) {
        out[s.prefix + name] = value;
        if (!s.prefix.empty()) ++instances_defining[name];
      }
  for (const ScopedNames<V>& s : scopes) {
    if (s.prefix.empty()) continue;
    for (const auto& [name, value] : *s.names)
      if (!hidden(s, name) && instances_defining[name] == 1) out.try_emplace(name, value);
  }
  return out;
}

}  // namespace pneufem::inp
