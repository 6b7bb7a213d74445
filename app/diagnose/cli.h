#pragma once
// CLI registration of `pneufem diagnose` (kept out of main.cpp so each command reads in one place).
#include <memory>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>

#include "app/diagnose/command.h"

namespace pneufem {

struct DiagnoseCommand {
  CLI::App* cmd = nullptr;
  std::string scene_path;
  std::vector<std::string> sets;
  std::string candidates;  ///< comma-separated
  bool progress = false;   ///< --progress: report on stderr even when it is not a terminal
  DiagnoseOptions options;
};

std::unique_ptr<DiagnoseCommand> add_diagnose_command(CLI::App& app);

/// Runs the parsed command; returns the exit code (2 bad input, 3 physics) after printing errors.
int run_diagnose_command(DiagnoseCommand& c, const std::string& command_line);

}  // namespace pneufem
