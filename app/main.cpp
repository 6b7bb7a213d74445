// pneufem command-line interface (CLI11). Each subcommand is registered next to its command, in
// app/<command>/cli.h, and validates its options at parse time; main wires them and maps what they
// throw to exit codes: bad input is reported as "error: ..." with the file/line/key and what to do
// (exit code 2); physics failures (inversion, limit point) exit with code 3 after writing what was
// computed.
#include <cstdio>
#include <memory>
#include <string>

#include <CLI/CLI.hpp>

#include "app/compare/cli.h"
#include "app/diagnose/cli.h"
#include "app/fit_material/cli.h"
#include "app/simulate/cli.h"
#include "app/sweep/cli.h"
#include "app/synth/cli.h"
#include "core/errors.h"
#include "core/version.h"

using namespace pneufem;

namespace {

std::string join_args(int argc, char** argv) {
  std::string s;
  for (int i = 0; i < argc; ++i) s += (i ? " " : "") + std::string(argv[i]);
  return s;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"pneufem: simulate pneumatic soft actuators (pneu-nets), their fatigue, and why a model "
               "disagrees with measurements.\nUnits: SI inside; scene keys carry their unit in the name."};
  app.set_version_flag("--version", version_string());
  app.require_subcommand(1);

  // In the order `pneufem --help` lists them.
  std::unique_ptr<SimulateCommand> sim = add_simulate_command(app);
  std::unique_ptr<MeshCommand> mesh = add_mesh_command(app);
  std::unique_ptr<SceneCommand> sc = add_scene_command(app);
  std::unique_ptr<SweepCommand> sw = add_sweep_command(app);
  std::unique_ptr<SynthCommand> sy = add_synth_command(app);
  std::unique_ptr<CompareCommand> cmp = add_compare_command(app);
  std::unique_ptr<DiagnoseCommand> dia = add_diagnose_command(app);
  std::unique_ptr<FitMaterialCommand> fm = add_fit_material_command(app);

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help / --version print and exit 0; a malformed command line is bad input: exit 2 like every
    // other input error (README, exit codes), not CLI11's own codes (105, 106, ...).
    const int rc = app.exit(e);
    return rc == 0 ? 0 : 2;
  }
  try {
    if (sim->cmd->parsed()) return run_simulate_command(*sim, join_args(argc, argv));
    if (cmp->cmd->parsed()) return run_compare_command(*cmp, join_args(argc, argv));
    if (dia->cmd->parsed()) return run_diagnose_command(*dia, join_args(argc, argv));
    if (sw->cmd->parsed()) return run_sweep_command(*sw, join_args(argc, argv));
    if (sy->cmd->parsed()) return run_synth_command(*sy, join_args(argc, argv));
    if (mesh->cmd->parsed()) return run_mesh_command(*mesh);
    if (sc->cmd->parsed()) return run_scene_command(*sc);
    if (fm->cmd->parsed()) return run_fit_material_command(*fm);
  } catch (const InputError& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 2;
  } catch (const PhysicsError& e) {
    std::fprintf(stderr, "\nsimulation failed: %s\n", e.what());
    return 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "error: %s\n", e.what());
    return 1;
  }
  return 0;
}
