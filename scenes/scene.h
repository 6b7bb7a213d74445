#pragma once
// Scene files (TOML): the built-in default scene (scenes/data/default_scene.toml) merged with a
// user's file and with command-line overrides (--set key=value), validated key by key. The
// resolved scene is what every output records.
//
// Errors name the source: "<file>:<line>: key 'solver.metod': unknown key; did you mean
// 'solver.method'?" or "--set load.trials=x: ...".
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "core/errors.h"

namespace pneufem {

/// An InputError that already names its scene key and where the key was set (Scene::fail): code
/// that adds context to the errors of a law or an effect passes it on unchanged.
class SceneKeyError : public InputError {
 public:
  using InputError::InputError;
};

class Scene {
 public:
  /// Loads `path` ("" = built-in default only) and applies `overrides` ("key=value", value in
  /// TOML syntax; bare words are taken as strings).
  static Scene load(const std::string& path, const std::vector<std::string>& overrides = {});
  /// The same from scene text in memory (the fuzz target of fuzz/, tests): `source` names it in
  /// messages, as a file's path would ("" = the built-in default only, `text` unused); relative
  /// paths in it resolve from the current directory; path() is "".
  static Scene from_text(const std::string& text, const std::string& source,
                         const std::vector<std::string>& overrides = {});
  /// The built-in default scene text: scenes/data/default_scene.toml with the effect tables
  /// generated from the registry in place of its marker line (scenes/effect_tables.h).
  static const std::string& default_text();

  /// Typed access to a dotted key of the resolved scene. Throws InputError naming the key and
  /// where it was set when it is missing or has the wrong type. Every number read (number,
  /// numbers, vec3) must be finite, every integer a TOML integer that fits an int, and a key with a
  /// declared range (scenes/key_limits.h) must lie in it: the error gives the value and the range.
  double number(const std::string& key) const;
  int integer(const std::string& key) const;
  bool boolean(const std::string& key) const;
  std::string string(const std::string& key) const;
  Eigen::Vector3d vec3(const std::string& key) const;
  std::vector<double> numbers(const std::string& key) const;
  bool has(const std::string& key) const;
  /// Names of the sub-tables of `key` (e.g. the materials).
  std::vector<std::string> table_keys(const std::string& key) const;
  /// The string of entry `name` of table `table`, `name` taken literally: it may hold dots (a
  /// deck's "Actuator-1.Set-1" in mesh.regions), which string() would read as a path.
  std::string string_entry(const std::string& table, const std::string& name) const;
  /// Number of entries of an array of tables (e.g. "parts").
  int array_size(const std::string& key) const;
  /// Where a key was set: "scene.toml:12", "--set", or "default scene".
  std::string origin(const std::string& key) const;
  /// SceneKeyError (an InputError) prefixed with the key's origin.
  [[noreturn]] void fail(const std::string& key, const std::string& what) const;
  /// fail() for a key that is not in the scene, naming the table that lacks it.
  [[noreturn]] void fail_missing(const std::string& key) const;

  /// Resolves a path given in the scene relative to the scene file's directory.
  std::string resolve_path(const std::string& p) const;
  const std::string& path() const { return path_; }

  /// The fully resolved configuration.
  std::string to_toml() const;
  std::string to_json() const;
  /// to_toml() without the tables switched off (`enabled = false`, e.g. a disabled effect), whose
  /// other keys do not change the model: equal strings for scenes that build the same model, the
  /// key of caches (the ideal model of app/simulate/ideal_cache.h, diagnose's elastic curves).
  std::string model_toml() const;
  /// model_toml() without the named top-level tables (e.g. "load", "output"): the key of results
  /// that do not depend on them (the reduced model's basis, app/simulate/reduced.h).
  std::string model_toml_without(const std::vector<std::string>& tables) const;

  /// A copy with more overrides applied (used by sweeps and diagnosis).
  Scene with(const std::vector<std::string>& overrides) const;

  /// Notes on keys a run should say where they came from: the materials and parts taken from a deck
  /// (mesh.source = "inp", scenes/deck_materials.h), and which of the deck's keys the scene overrides.
  /// build_model adds them to its notes (simulate's summary.json "warnings"). Empty without a deck.
  const std::vector<std::string>& notes() const;

  struct Impl;  ///< (scene.cpp)

 private:
  /// `v`, read from `key` (`entry` names a list's element in the message), if it is finite and in
  /// the key's declared range; else a failure with the value and the range.
  double checked(const std::string& key, double v, const std::string& entry) const;
  /// The default scene merged with `text` (named `source`; "" = none), paths resolved from `dir`.
  static Scene parse(const std::string& text, const std::string& source, const std::string& dir);

  /// Builds the table again with the deck layer of its mesh keys when they name another deck than
  /// the one it has, and refreshes notes(). Only on a scene whose impl_ is its own (parse, with).
  void settle_deck();

  std::shared_ptr<const Impl> impl_;
  std::string path_;
};

}  // namespace pneufem
