#pragma once
// CLI registration of the commands that build and run one scene: `pneufem simulate` (a run
// directory, app/simulate/command.h), `pneufem mesh` (the scene's mesh as .vtu or a CalculiX deck)
// and `pneufem scene` (the built-in default scene). Exit codes follow main: 2 bad input, 3 physics
// failure (main's handlers).
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

namespace pneufem {

struct SimulateCommand {
  CLI::App* cmd = nullptr;
  std::string scene_path;
  std::string out_dir;
  std::vector<std::string> sets;
  int threads = 0;
  std::string resume_dir;
  double checkpoint_every_s = 30.0;
  int abort_after_checkpoints = -1;
  std::string ideal_cache_dir;
  std::string cache_dir;
};

/// Adds `simulate [SCENE.toml] --out DIR [--set k=v ...] [--threads N] [--resume DIR]
/// [--checkpoint-every S] [--ideal-cache DIR]` to `app`; the returned object receives the values.
std::unique_ptr<SimulateCommand> add_simulate_command(CLI::App& app);

/// Runs a parsed simulate command and prints a one-line summary; returns the exit code.
int run_simulate_command(SimulateCommand& c, const std::string& command_line);

struct MeshCommand {
  CLI::App* cmd = nullptr;
  std::string scene_path;
  std::string out;
  std::vector<std::string> sets;
};

/// Adds `mesh [SCENE.toml] --out FILE.vtu|FILE.inp [--set k=v ...]` to `app`.
std::unique_ptr<MeshCommand> add_mesh_command(CLI::App& app);

/// Writes the mesh file of a parsed mesh command; returns the exit code.
int run_mesh_command(const MeshCommand& c);

struct SceneCommand {
  CLI::App* cmd = nullptr;
  bool defaults = false;
  bool reference = false;
};

/// Adds `scene [--defaults | --reference]` to `app`.
std::unique_ptr<SceneCommand> add_scene_command(CLI::App& app);

/// Prints the built-in default scene, or the scene reference (Markdown); returns the exit code.
int run_scene_command(const SceneCommand& c);

}  // namespace pneufem
