#pragma once
// The `compare` subcommand of the pneufem CLI (kept out of main.cpp): registration with CLI11
// and its action. Exit codes follow main: 2 bad input, 3 physics failure (main's handlers).
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "app/compare/command.h"

namespace pneufem {

struct CompareCommand {
  CLI::App* cmd = nullptr;
  std::string scene_path;
  std::vector<std::string> sets;
  std::string model;  ///< --model: "" = the scene's solver.model, else "full" or "reduced"
  CompareRunOptions options;
};

/// Adds `compare [SCENE.toml] --data FILE --out DIR [--set k=v ...] [--threads N] [--regions]
/// [--label TEXT] [--dlc-map MAP.toml]` to `app`; the returned object receives the parsed values.
std::unique_ptr<CompareCommand> add_compare_command(CLI::App& app);

/// Runs a parsed compare command and prints a one-line summary; returns the exit code.
int run_compare_command(CompareCommand& c, const std::string& command_line);

}  // namespace pneufem
