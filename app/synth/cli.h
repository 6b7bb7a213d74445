#pragma once
// CLI registration of `pneufem synth` (app/synth/command.h). Exit codes follow main: 2 bad input,
// 3 physics failure (main's handlers).
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "app/synth/command.h"

namespace pneufem {

struct SynthCommand {
  CLI::App* cmd = nullptr;
  std::string hidden;  ///< --hidden EFFECT[,EFFECT...] or none
  SynthOptions options;
};

/// Adds `synth [SCENE.toml] --hidden EFFECTS --out OUT.csv [--set k=v ...] [rig options]` to `app`.
std::unique_ptr<SynthCommand> add_synth_command(CLI::App& app);

/// Runs a parsed synth command and prints a one-line summary; returns the exit code.
int run_synth_command(SynthCommand& c, const std::string& command_line);

}  // namespace pneufem
