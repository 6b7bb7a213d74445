#pragma once
// CLI registration of `pneufem fit-material` (app/fit_material/command.h). Exit codes follow main:
// 2 bad input (a file and line, or an option, and what to do).
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "app/fit_material/command.h"

namespace pneufem {

struct FitMaterialCommand {
  CLI::App* cmd = nullptr;
  FitMaterialOptions options;
  std::string stability_range = "-0.9:9";
};

/// Adds `fit-material DATA... --model LAW --out DIR [options]` to `app`.
std::unique_ptr<FitMaterialCommand> add_fit_material_command(CLI::App& app);

/// Runs a parsed fit-material command and prints the constants, the fit per test, notes and
/// warnings; returns the exit code.
int run_fit_material_command(FitMaterialCommand& c);

}  // namespace pneufem
