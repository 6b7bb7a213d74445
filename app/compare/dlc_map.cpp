#include "app/compare/dlc_map.h"

#include <algorithm>
#include <filesystem>
#include <set>

#include <toml++/toml.h>

#include "analysis/deeplabcut.h"
#include "core/errors.h"

namespace pneufem {

namespace {

/// "<file>:<line>:<column>: " of a node (or just "<file>: " when it has no source).
std::string where(const std::string& file, const toml::node* n) {
  if (!n || !n->source().begin) return file + ": ";
  return file + ":" + std::to_string(n->source().begin.line) + ":" + std::to_string(n->source().begin.column) + ": ";
}

[[noreturn]] void fail(const std::string& file, const toml::node* n, const std::string& key, const std::string& what) {
  throw InputError(where(file, n) + "key '" + key + "': " + what);
}

void check_keys(const std::string& file, const toml::table& t, const std::set<std::string>& known,
                const std::string& prefix) {
  for (const auto& [k, v] : t)
    if (!known.count(std::string(k.str()))) {
      const auto& src = k.source();  // the key's own position (the value may sit further right)
      throw InputError((src.begin ? file + ":" + std::to_string(src.begin.line) + ":" + std::to_string(src.begin.column) + ": "
                                  : where(file, &v)) +
                       "key '" + prefix + std::string(k.str()) +
                       "': unknown key; the DeepLabCut map knows: fixed_parts, tip_parts, likelihood_cut, fps, "
                       "positive, zero_raw_deg, zero_frames, [[trials]] with trial, file, t0_s");
    }
}

double number(const std::string& file, const toml::table& t, const std::string& key, double fallback) {
  const toml::node* n = t.get(key);
  if (!n) return fallback;
  if (auto v = n->value<double>()) return *v;
  fail(file, n, key, "must be a number");
}

std::vector<std::string> parts(const std::string& file, const toml::table& t, const std::string& key) {
  const toml::node* n = t.get(key);
  if (!n) throw InputError(file + ": key '" + key + "' is missing; list >= 2 DeepLabCut body parts, e.g. " + key +
                           " = [\"a\", \"b\"]");
  const toml::array* a = n->as_array();
  if (!a) fail(file, n, key, "must be an array of body-part names");
  std::vector<std::string> out;
  for (const toml::node& e : *a) {
    if (auto s = e.value<std::string>()) {
      out.push_back(*s);
    } else {
      fail(file, &e, key, "every entry must be a body-part name (string)");
    }
  }
  return out;
}

}  // namespace

Recording merge_deeplabcut(const Recording& pressure, const std::string& map_path) {
  toml::table root;
  try {
    root = toml::parse_file(map_path);
  } catch (const toml::parse_error& e) {
    throw InputError(map_path + ":" + std::to_string(e.source().begin.line) + ":" +
                     std::to_string(e.source().begin.column) + ": " + std::string(e.description()) +
                     " (TOML syntax error)");
  }
  check_keys(map_path, root,
             {"fixed_parts", "tip_parts", "likelihood_cut", "fps", "positive", "zero_raw_deg", "zero_frames", "trials"}, "");
  DlcMapping base;
  base.fixed_parts = parts(map_path, root, "fixed_parts");
  base.tip_parts = parts(map_path, root, "tip_parts");
  base.likelihood_cut = number(map_path, root, "likelihood_cut", base.likelihood_cut);
  base.fps = number(map_path, root, "fps", base.fps);
  if (const toml::node* n = root.get("positive")) {
    const std::optional<std::string> s = n->value<std::string>();
    if (s == "counterclockwise") {
      base.positive = AngleSense::counterclockwise;
    } else if (s == "clockwise") {
      base.positive = AngleSense::clockwise;
    } else {
      fail(map_path, n, "positive", "must be \"counterclockwise\" or \"clockwise\" (the sense of bending on screen)");
    }
  }
  if (root.get("zero_raw_deg")) base.zero_raw_deg = number(map_path, root, "zero_raw_deg", 0.0);
  if (const toml::node* n = root.get("zero_frames")) {
    const std::optional<int64_t> v = n->value<int64_t>();
    if (!v || *v < 1) fail(map_path, n, "zero_frames", "must be an integer >= 1");
    base.zero_frames = static_cast<int>(*v);
  }
  const toml::array* trials = root.get("trials") ? root.get("trials")->as_array() : nullptr;
  if (!trials || trials->empty())
    throw InputError(map_path + ": no [[trials]] tables; add one per DeepLabCut file with trial = N and file = \"...\"");

  Recording out = pressure;
  const std::filesystem::path dir = std::filesystem::path(map_path).parent_path();
  for (const toml::node& tn : *trials) {
    const toml::table* t = tn.as_table();
    if (!t) fail(map_path, &tn, "trials", "must be an array of tables ([[trials]])");
    check_keys(map_path, *t, {"trial", "file", "t0_s"}, "trials.");
    DlcMapping map = base;
    const toml::node* trial = t->get("trial");
    const toml::node* file = t->get("file");
    if (!trial || !trial->value<int64_t>()) fail(map_path, &tn, "trials.trial", "each [[trials]] needs trial = N (integer)");
    if (!file || !file->value<std::string>())
      fail(map_path, &tn, "trials.file", "each [[trials]] needs file = \"<DeepLabCut CSV>\"");
    map.trial = static_cast<int>(*trial->value<int64_t>());
    map.t0_s = number(map_path, *t, "t0_s", 0.0);
    const auto it = std::find_if(out.trials.begin(), out.trials.end(),
                                 [&](const TrialRecording& r) { return r.trial == map.trial; });
    if (it == out.trials.end())
      fail(map_path, trial, "trials.trial",
           "trial " + std::to_string(map.trial) + " has no pressure in " + pressure.source + "; the model needs it");
    std::filesystem::path f(*file->value<std::string>());
    if (f.is_relative()) f = dir / f;
    const Recording dlc = read_deeplabcut_csv(f.string(), map);
    it->angle_deg = dlc.trials.front().angle_deg;
    out.warnings.insert(out.warnings.end(), dlc.warnings.begin(), dlc.warnings.end());
  }
  out.source = pressure.source + " + " + map_path;
  return out;
}

}  // namespace pneufem
