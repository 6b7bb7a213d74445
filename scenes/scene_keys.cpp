// The scene-key checks of scenes/scene_keys.h that are not templates.
#include "scenes/scene_keys.h"

namespace pneufem::detail {

void require_keys(const Scene& scene, const std::string& table, const std::set<std::string>& allowed,
                  const std::string& what) {
  for (const std::string& k : scene.table_keys(table))
    if (!allowed.count(k)) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      scene.fail(table + "." + k, "unknown key for " + what + "; allowed: " + list);
    }
}

double positive(const Scene& scene, const std::string& key) {
  const double v = scene.number(key);
  if (!(v > 0.0)) scene.fail(key, "must be > 0");
  return v;
}

const std::vector<int>& node_set(const Scene& s, const Mesh& m, const std::string& key) {
  std::string name = s.string(key);
  std::string upper = name;
  std::transform(upper.begin(), upper.end(), upper.begin(), ::toupper);
  for (const std::string& n : {name, upper}) {
    auto it = m.node_sets.find(n);
    if (it != m.node_sets.end()) {
      if (it->second.empty()) s.fail(key, "node set '" + name + "' is empty");
      return it->second;
    }
  }
  reject_ambiguous(s, key, m.node_sets, name, "node set");
  std::string avail;
  for (const auto& [k, v] : m.node_sets) avail += (avail.empty() ? "" : ", ") + k;
  s.fail(key, "node set '" + name + "' not found in the mesh; available: " + (avail.empty() ? "(none)" : avail));
}

}  // namespace pneufem::detail
