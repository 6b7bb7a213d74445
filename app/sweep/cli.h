#pragma once
// CLI registration of `pneufem sweep` (app/sweep/command.h). Exit codes: 0 every point ran, 1 some
// point failed (its error is in sweep.csv), 2 bad input (main's handler).
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "app/sweep/command.h"

namespace pneufem {

struct SweepCommand {
  CLI::App* cmd = nullptr;
  SweepOptions options;
};

/// Adds `sweep [SCENE.toml] --param KEY=LO:HI:N[:log] ... --out DIR [--lhs N] [--seed S] [--jobs N]
/// [--threads-per-job N] [--model auto|full|reduced] [--fem-points LIST] [--set k=v ...] [--dry-run]
/// [--scheduler local|slurm] [--partition P] [--time T] [--mem M] [--account A] [--max-parallel N]`
/// to `app`; --param and --model are validated at parse time.
std::unique_ptr<SweepCommand> add_sweep_command(CLI::App& app);

/// Runs a parsed sweep command and prints a one-line summary; returns the exit code. Its workers
/// (local processes or SLURM tasks) run `exe`, by default this executable; the Python package
/// gives the pneufem binary (its own executable is the interpreter). Throws InputError when `exe`
/// does not exist.
int run_sweep_command(SweepCommand& c, const std::string& command_line, const std::string& exe = "");

}  // namespace pneufem
