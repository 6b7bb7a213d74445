#include "scenes/scene.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>

#include <toml++/toml.h>

#include "core/errors.h"
#include "core/message_text.h"
#include "core/number_text.h"
#include "scenes/deck_materials.h"
#include "scenes/default_scene_text.h"
#include "scenes/effect_tables.h"
#include "scenes/key_limits.h"

namespace pneufem {

namespace {

constexpr const char* kDefaultOrigin = "default scene";

std::size_t edit_distance(const std::string& a, const std::string& b) {
  std::vector<std::size_t> prev(b.size() + 1), cur(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j) prev[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    cur[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j)
      cur[j] = std::min({prev[j] + 1, cur[j - 1] + 1, prev[j - 1] + (a[i - 1] == b[j - 1] ? 0 : 1)});
    std::swap(prev, cur);
  }
  return prev[b.size()];
}

std::string origin_of(const toml::node& n) {
  const auto& src = n.source();
  if (!src.path || *src.path == kDefaultOrigin) return kDefaultOrigin;
  if (src.path->rfind("--set", 0) == 0) return *src.path;
  return *src.path + ":" + std::to_string(src.begin.line);
}

// Keys whose sub-keys are free-form names (checked elsewhere, e.g. by the material factory).
bool free_form(const std::string& path) {
  return path == "materials" || path == "mesh.regions" || path == "regions" || path.rfind("materials.", 0) == 0;
}

// Arrays of tables ([[parts]], [[mesh.region_boxes]]): every entry's keys are checked against the
// ones it may have. Also for a --set of the whole array, which check_known lets through because the
// key exists.
void check_entries(const std::string& key, const toml::node& v) {
  static const std::map<std::string, std::vector<std::string>> entry_keys = {
      {"parts", {"elset", "material"}}, {"mesh.region_boxes", {"region", "min_mm", "max_mm"}}};
  const auto keys = entry_keys.find(key);
  if (keys == entry_keys.end() || !v.is_array()) return;
  std::string list;
  for (const std::string& k : keys->second) list += (list.empty() ? "'" : ", '") + k + "'";
  for (auto&& item : *v.as_array()) {
    if (!item.is_table()) throw InputError(origin_of(item) + ": '" + key + "' must be an array of tables ([[" + key + "]])");
    for (auto&& [pk, pv] : *item.as_table())
      if (std::find(keys->second.begin(), keys->second.end(), std::string(pk.str())) == keys->second.end())
        throw InputError(printable(origin_of(pv) + ": key '" + key + "." + std::string(pk.str()) + "': unknown key; an entry of '" +
                                   key + "' has " + list));
  }
}

// Rejects keys of `user` that the default scene does not have.
void check_known(const toml::table& user, const toml::table& defaults, const std::string& prefix) {
  for (auto&& [k, v] : user) {
    const std::string key = prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
    if (free_form(prefix)) continue;
    const toml::node* d = defaults.get(k.str());
    if (!d) {
      std::string best;
      std::size_t best_d = 4;
      for (auto&& [dk, dv] : defaults) {
        const std::size_t dist = edit_distance(std::string(k.str()), std::string(dk.str()));
        if (dist < best_d) {
          best_d = dist;
          best = std::string(dk.str());
        }
      }
      std::string msg = origin_of(v) + ": key '" + key + "': unknown key";
      if (!best.empty()) msg += "; did you mean '" + (prefix.empty() ? best : prefix + "." + best) + "'?";
      msg += " (`pneufem scene --defaults` lists every key)";
      throw InputError(printable(msg));
    }
    if (v.is_table() && d->is_table() && !free_form(key)) check_known(*v.as_table(), *d->as_table(), key);
    check_entries(key, v);
  }
}

using Origins = std::map<std::string, std::string>;

// Deep merge of `src` into `dst`. Tables merge recursively, everything else is replaced; a
// material whose 'model' changes starts from an empty table (its old constants do not apply).
// The origin (file:line or --set) of every replaced value is recorded, since copies of toml++
// nodes do not keep their source position.
void record(Origins& origins, const std::string& key, const toml::node& v) {
  if (v.is_table()) {
    for (auto&& [k, c] : *v.as_table()) record(origins, key + "." + std::string(k.str()), c);
    if (!v.as_table()->empty()) return;
  }
  origins[key] = origin_of(v);
}

void merge(toml::table& dst, const toml::table& src, const std::string& prefix, Origins& origins) {
  for (auto&& [k, v] : src) {
    const std::string key = prefix.empty() ? std::string(k.str()) : prefix + "." + std::string(k.str());
    toml::node* d = dst.get(k.str());
    if (v.is_table() && d && d->is_table()) {
      toml::table& dt = *d->as_table();
      const toml::table& st = *v.as_table();
      if (prefix == "materials" && st.contains("model") && dt.contains("model") &&
          st.get("model")->value<std::string>() != dt.get("model")->value<std::string>()) {
        dst.insert_or_assign(k.str(), st);
        record(origins, key, v);
        continue;
      }
      merge(dt, st, key, origins);
    } else {
      const std::string_view name = k.str();  // a named copy: clang 14 cannot capture a structured binding
      v.visit([&](auto&& node) { dst.insert_or_assign(name, node); });
      record(origins, key, v);
    }
  }
}

toml::table parse_text(const std::string& text, const std::string& origin) {
  try {
    return toml::parse(text, origin);
  } catch (const toml::parse_error& e) {
    std::ostringstream s;
    s << origin << ":" << e.source().begin.line << ":" << e.source().begin.column << ": " << e.description()
      << " (TOML syntax error); fix the text there: one key = value per line, strings in double quotes, "
         "tables as [name] (https://toml.io)";
    throw InputError(printable(s.str()));
  }
}

}  // namespace

// A scene is built from layers, later ones winning key by key: the default scene, a deck's materials
// (mesh.source = "inp": scenes/deck_materials.h), the scene file, the overrides. The layers are kept
// so that the table can be built again when an override changes which deck it is (Scene::with).
struct Scene::Impl {
  toml::table table;
  std::string dir;
  Origins origins;  ///< where non-default values came from
  std::string user_text, user_source;  ///< the scene file's text and name ("" = none)
  std::vector<std::string> overrides;  ///< every override applied, in order
  std::string deck_id;                 ///< the deck whose materials are a layer: "<path>|<unit>", "" = none
  std::shared_ptr<const DeckInfo> deck;
  std::vector<std::string> notes;      ///< deck_notes of the merged scene
};

namespace {

const toml::table& default_table() {
  static const toml::table t = parse_text(Scene::default_text(), kDefaultOrigin);
  return t;
}

/// Applies one "key=value" override to `impl` (its table and origins).
void apply_override(Scene::Impl& impl, const std::string& ov) {
  const auto eq = ov.find('=');
  if (eq == std::string::npos || eq == 0)
    throw InputError(printable("--set " + ov + ": expected key=value, e.g. --set load.trials=10"));
  const std::string key = ov.substr(0, eq), value = ov.substr(eq + 1);
  const std::string origin = "--set " + key;
  toml::table parsed;
  try {
    parsed = toml::parse("v = " + value, origin);
  } catch (const toml::parse_error&) {
    toml::table t;
    t.insert("v", value);  // bare word: a string
    parsed = t;
  }
  // Build {a = {b = {c = v}}} and merge it, after checking the key against the defaults.
  std::vector<std::string> parts;
  std::stringstream ks(key);
  for (std::string p; std::getline(ks, p, '.');) parts.push_back(p);
  toml::table nested;
  parsed.get("v")->visit([&](auto&& node) { nested.insert_or_assign(parts.back(), node); });
  for (int i = static_cast<int>(parts.size()) - 2; i >= 0; --i) {
    toml::table outer;
    outer.insert(parts[i], nested);
    nested = outer;
  }
  try {
    check_known(nested, default_table(), "");
  } catch (const InputError&) {
    // A key that exists in the current scene (e.g. a user-defined material) is fine too.
    if (!impl.table.at_path(key)) throw;
  }
  if (const toml::node* n = nested.at_path(key).node()) check_entries(key, *n);
  Origins ignored;  // the nested copy lost its source; record the override itself
  merge(impl.table, nested, "", ignored);
  for (auto it = impl.origins.lower_bound(key + "."); it != impl.origins.end() && it->first.rfind(key + ".", 0) == 0;)
    it = impl.origins.erase(it);
  impl.origins[key] = origin;
}

/// The table of `impl`'s layers: the default scene, `deck` (or none), the scene file, the overrides.
void build_table(Scene::Impl& impl, const DeckLayer* deck) {
  impl.table = default_table();
  impl.origins.clear();
  if (deck) {
    merge(impl.table, deck->table, "", impl.origins);
    for (const auto& [key, where] : deck->info.origins) impl.origins[key] = where;
  }
  if (!impl.user_source.empty()) {
    const toml::table user = parse_text(impl.user_text, impl.user_source);
    check_known(user, default_table(), "");
    merge(impl.table, user, "", impl.origins);
  }
  for (const std::string& ov : impl.overrides) apply_override(impl, ov);
}

/// "<path>|<unit>" of the deck whose materials the table's mesh keys ask for, or "" (no deck, or one
/// build_model will report: a source other than "inp", no file, a file that is not there, an unknown
/// unit).
std::string deck_identity(const Scene::Impl& impl, std::string& path, std::string& unit) {
  const toml::table& t = impl.table;
  if (t.at_path("mesh.source").value<std::string>().value_or("") != "inp") return "";
  const std::string file = t.at_path("mesh.file").value<std::string>().value_or("");
  unit = t.at_path("mesh.length_unit").value<std::string>().value_or("");
  if (file.empty() || (unit != "mm" && unit != "m")) return "";
  std::filesystem::path p(file);
  if (!p.is_absolute()) p = (std::filesystem::path(impl.dir) / p).lexically_normal();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(p, ec)) return "";
  path = p.string();
  return path + "|" + unit;
}

}  // namespace

void Scene::settle_deck() {
  Impl& impl = const_cast<Impl&>(*impl_);  // impl_ is this scene's own, not yet shared
  std::string path, unit;
  const std::string id = deck_identity(impl, path, unit);
  if (id != impl.deck_id) {
    if (id.empty()) {
      build_table(impl, nullptr);
      impl.deck.reset();
    } else {
      DeckDefaults defaults;
      defaults.K_over_mu = *default_table().at_path("materials.silicone.K_over_mu").value<double>();
      defaults.density_kg_m3 = *default_table().at_path("materials.silicone.density_kg_m3").value<double>();
      const DeckLayer layer = deck_layer(path, unit, defaults);
      build_table(impl, &layer);
      impl.deck = std::make_shared<const DeckInfo>(layer.info);
    }
    impl.deck_id = id;
  }
  impl.notes.clear();
  if (impl.deck) {
    MergedScene merged;
    merged.has = [this](const std::string& key) { return has(key); };
    merged.array_size = [this](const std::string& key) { return array_size(key); };
    merged.string = [this](const std::string& key) { return string(key); };
    merged.number = [this](const std::string& key) { return number(key); };
    merged.origin = [this](const std::string& key) { return origin(key); };
    merged.origin_of = [&impl](const std::string& key) {
      const auto it = impl.origins.find(key);
      return it == impl.origins.end() ? std::string() : it->second;
    };
    impl.notes = deck_notes(*impl.deck, merged);
  }
}

const std::vector<std::string>& Scene::notes() const { return impl_->notes; }

const std::string& Scene::default_text() {
  static const std::string text = expand_effect_tables(kDefaultSceneText);  // the registry's effect tables
  return text;
}

Scene Scene::load(const std::string& path, const std::vector<std::string>& overrides) {
  if (path.empty()) return from_text("", "", overrides);
  std::ifstream in(path);
  if (!in) throw InputError("cannot open scene file '" + path + "': check the path");
  std::stringstream buf;
  buf << in.rdbuf();
  Scene s = parse(buf.str(), path, std::filesystem::absolute(path).parent_path().string());
  s.path_ = path;
  return s.with(overrides);
}

Scene Scene::from_text(const std::string& text, const std::string& source, const std::vector<std::string>& overrides) {
  Scene s = parse(text, source, std::filesystem::current_path().string());
  return s.with(overrides);
}

Scene Scene::parse(const std::string& text, const std::string& source, const std::string& dir) {
  auto impl = std::make_shared<Impl>();
  impl->user_text = source.empty() ? std::string() : text;
  impl->user_source = source;
  impl->dir = dir;
  build_table(*impl, nullptr);
  Scene s;
  s.impl_ = impl;
  s.settle_deck();
  return s;
}

Scene Scene::with(const std::vector<std::string>& overrides) const {
  if (overrides.empty()) return *this;
  auto impl = std::make_shared<Impl>(*impl_);
  for (const std::string& ov : overrides) {
    apply_override(*impl, ov);
    impl->overrides.push_back(ov);
  }
  Scene s;
  s.impl_ = impl;
  s.path_ = path_;
  s.settle_deck();  // an override may name another deck, or override a deck's key
  return s;
}

bool Scene::has(const std::string& key) const { return static_cast<bool>(impl_->table.at_path(key)); }

std::string Scene::origin(const std::string& key) const {
  // Exact key, else the closest enclosing key that was set (e.g. a whole table), else any key
  // below it that was set (e.g. one constant of a material).
  for (std::string k = key;;) {
    auto it = impl_->origins.find(k);
    if (it != impl_->origins.end()) return it->second;
    const auto dot = k.find_last_of(".[");
    if (dot == std::string::npos) break;
    k = k.substr(0, dot);
  }
  auto it = impl_->origins.lower_bound(key + ".");
  if (it != impl_->origins.end() && it->first.rfind(key + ".", 0) == 0) return it->second;
  return kDefaultOrigin;
}

void Scene::fail(const std::string& key, const std::string& what) const {
  throw SceneKeyError(printable(origin(key) + ": key '" + key + "': " + what));
}

void Scene::fail_missing(const std::string& key) const {
  // A key the default scene has is never missing: the user's own table lacks it (a material of
  // their own without `model`), or replaced the table by a value (--set load=3). Name where that
  // table was set: the key's origin, else where a key beside it in its table (not a top-level
  // table, whose other keys say nothing about this one) was set.
  std::string where = origin(key);
  for (std::string k = key; where == kDefaultOrigin;) {
    const auto dot = k.find_last_of('.');
    if (dot == std::string::npos || k.find('.') == dot) break;
    k = k.substr(0, dot);
    const auto it = impl_->origins.lower_bound(k + ".");
    if (it != impl_->origins.end() && it->first.rfind(k + ".", 0) == 0) where = it->second;
  }
  throw SceneKeyError(printable(where + ": key '" + key + "': missing; add it (`pneufem scene --defaults` lists every key)"));
}

double Scene::checked(const std::string& key, double v, const std::string& entry) const {
  if (!std::isfinite(v)) fail(key, "got " + short_num(v) + entry + "; a value must be a finite number");
  const KeyLimit* limit = find_key_limit(key);
  if (limit && !limit->contains(v))
    fail(key, "got " + short_num(v) + entry + "; allowed: " + limit->range_text() + " (" + limit->why + ")");
  return v;
}

double Scene::number(const std::string& key) const {
  const toml::node* n = impl_->table.at_path(key).node();
  if (!n) fail_missing(key);
  const std::optional<double> v = n->value<double>();
  if (!v || !(n->is_floating_point() || n->is_integer())) fail(key, "expected a number");
  return checked(key, *v, "");
}

int Scene::integer(const std::string& key) const {
  const toml::node* n = impl_->table.at_path(key).node();
  if (!n) fail_missing(key);
  if (!n->is_integer()) {
    const std::optional<double> v = n->value<double>();
    fail(key, "expected an integer (no decimal point or exponent)" + (v ? ", got " + short_num(*v) : std::string()));
  }
  const std::int64_t v = *n->value<std::int64_t>();
  const KeyLimit* limit = find_key_limit(key);
  // Without a declared range an integer key must still fit the int it is read into (a wider value
  // would wrap: 4294967299 read as 3).
  const double lo = limit ? limit->lo : std::numeric_limits<int>::min();
  const double hi = limit ? limit->hi : std::numeric_limits<int>::max();
  if (static_cast<double>(v) < lo || static_cast<double>(v) > hi)
    fail(key, "got " + std::to_string(v) + "; allowed: integers " + (limit ? limit->range_text() : "that fit in 32 bits") +
                  (limit ? " (" + limit->why + ")" : std::string()));
  return static_cast<int>(v);
}

bool Scene::boolean(const std::string& key) const {
  const toml::node* n = impl_->table.at_path(key).node();
  if (!n) fail_missing(key);
  if (!n->is_boolean()) fail(key, "expected true or false");
  return *n->value<bool>();
}

std::string Scene::string(const std::string& key) const {
  const toml::node* n = impl_->table.at_path(key).node();
  if (!n) fail_missing(key);
  if (!n->is_string()) fail(key, "expected a string (in quotes)");
  return *n->value<std::string>();
}

std::vector<double> Scene::numbers(const std::string& key) const {
  const toml::node* n = impl_->table.at_path(key).node();
  if (!n) fail_missing(key);
  const toml::array* a = n->as_array();
  if (!a) fail(key, "expected an array of numbers, e.g. [1.0, 2.0]");
  std::vector<double> out;
  for (auto&& e : *a) {
    auto v = e.value<double>();
    if (!v || !(e.is_floating_point() || e.is_integer())) fail(key, "expected an array of numbers");
    out.push_back(checked(key, *v, " (entry " + std::to_string(out.size() + 1) + ")"));
  }
  return out;
}

Eigen::Vector3d Scene::vec3(const std::string& key) const {
  const std::vector<double> v = numbers(key);
  if (v.size() != 3) fail(key, "expected 3 numbers [x, y, z]");
  return {v[0], v[1], v[2]};
}

std::vector<std::string> Scene::table_keys(const std::string& key) const {
  std::vector<std::string> out;
  const toml::node* n = key.empty() ? &impl_->table : impl_->table.at_path(key).node();
  if (!n || !n->is_table()) return out;
  for (auto&& [k, v] : *n->as_table()) out.emplace_back(k.str());
  return out;
}

std::string Scene::string_entry(const std::string& table, const std::string& name) const {
  const std::string key = table + "." + name;
  const toml::node* t = impl_->table.at_path(table).node();
  const toml::node* n = t && t->is_table() ? t->as_table()->get(name) : nullptr;
  if (!n) fail_missing(key);
  if (!n->is_string()) fail(key, "expected a string (in quotes)");
  return *n->value<std::string>();
}

int Scene::array_size(const std::string& key) const {
  const toml::node* n = impl_->table.at_path(key).node();
  if (!n || !n->is_array()) return 0;
  return static_cast<int>(n->as_array()->size());
}

std::string Scene::resolve_path(const std::string& p) const {
  if (p.empty()) return p;
  std::filesystem::path q(p);
  if (q.is_absolute()) return p;
  return (std::filesystem::path(impl_->dir) / q).lexically_normal().string();
}

std::string Scene::to_toml() const {
  std::ostringstream s;
  s << impl_->table;
  return s.str();
}

namespace {
void drop_disabled_tables(toml::table& t) {
  std::vector<std::string> off;
  for (auto&& [key, node] : t)
    if (toml::table* sub = node.as_table()) {
      const std::optional<bool> enabled = (*sub)["enabled"].value<bool>();
      if (enabled && !*enabled)
        off.emplace_back(key.str());
      else
        drop_disabled_tables(*sub);
    }
  for (const std::string& key : off) t.erase(key);
}
}  // namespace

std::string Scene::model_toml() const { return model_toml_without({}); }

std::string Scene::model_toml_without(const std::vector<std::string>& tables) const {
  toml::table t = impl_->table;
  drop_disabled_tables(t);
  for (const std::string& name : tables) t.erase(name);
  std::ostringstream s;
  s << t;
  return s.str();
}

std::string Scene::to_json() const {
  std::ostringstream s;
  s << toml::json_formatter{impl_->table};
  return s.str();
}

}  // namespace pneufem
