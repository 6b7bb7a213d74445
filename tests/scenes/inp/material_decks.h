#pragma once
// The fixture of the deck-material tests (tests/scenes/inp/test_materials.cpp, the reader;
// tests/scenes/test_deck_materials.cpp, the scene's layer): decks written to a temporary folder, read
// directly or as a scene's mesh.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/errors.h"
#include "scenes/inp/materials.h"
#include "scenes/scene.h"

namespace pneufem::test {

namespace fs = std::filesystem;

class DeckMaterials : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / ("pneufem_deck_materials_" + std::to_string(::getpid()));
    fs::create_directories(dir_);
  }
  void TearDown() override { fs::remove_all(dir_); }

  std::string write(const std::string& name, const std::string& text) const {
    const fs::path p = dir_ / name;
    std::ofstream(p) << text;
    return p.string();
  }
  /// A scene reading the deck `text` (written as `name`), with `sets`.
  Scene scene(const std::string& name, const std::string& text, std::vector<std::string> sets = {}) const {
    sets.insert(sets.begin(), {"mesh.source=\"inp\"", "mesh.file=\"" + write(name, text) + "\""});
    return Scene::load("", sets);
  }
  std::string error_of(const std::string& name, const std::string& text) const {
    try {
      (void)read_inp_materials(write(name, text), "mm");
    } catch (const InputError& e) {
      return e.what();
    }
    return "(no error)";
  }
  fs::path dir_;
};

/// The error of loading a scene (or "(no error)").
inline std::string scene_error(const std::function<Scene()>& load) {
  try {
    (void)load();
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

}  // namespace pneufem::test
