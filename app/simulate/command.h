#pragma once
// One simulation run as the CLI performs it: build the model from a scene, march through the
// load history (quasi-static or explicit), and write the outputs of a run directory:
//   angles.csv        trial,time_s,pressure_kPa,angle_deg
//   states.csv        the same plus global time, cavity volume and tip-plane fit residual
//   metrics.json      the paper's metrics per trial against the ideal elastic model (same scene,
//                     inelastic effects off), when the scene has effects and a staircase load
//   ideal_angles.csv  the ideal model's angles (one trial: it is elastic, so all trials agree)
//   summary.json      version, status, resolved scene, mesh and solver statistics, timings
//   scene.toml        the fully resolved scene (re-runnable as is; --resume reads it)
//   results.pvd + vtu/state_NNNN.vtu   fields for ParaView
//   checkpoint.bin    the full state at the last checkpoint (quasi-static runs of the full FEM),
//                     with the hashes of the run it belongs to and a checksum
//                     (app/simulate/checkpoint_file.h); a fresh run removes an earlier one
//   reduced_check.csv solver.model = "reduced": each report's estimated angle error (the full
//                     residual of the reconstructed state, weighted by the angle's adjoint)
// Every file is written atomically (temporary file + rename).
#include <functional>
#include <string>
#include <vector>

#include "engine/quasi_static.h"
#include "scenes/scene.h"

namespace pneufem {

struct RunOptions {
  std::string out_dir;
  int threads = 0;                     ///< 0 = all cores
  bool progress = false;               ///< a progress line redrawn in place, and the stages (a terminal)
  /// Not on a terminal: a progress line (share done, elapsed, estimate left) every this many
  /// seconds of wall time, and the stages; 0 = none (core/progress.h).
  double progress_log_every_s = 0.0;
  std::string command_line;
  bool resume = false;                 ///< continue the run in out_dir from its checkpoint
  double checkpoint_every_s = 30.0;    ///< wall-clock seconds between checkpoints (0 = every segment)
  int abort_after_checkpoints = -1;    ///< testing aid: die (as if killed) after this many checkpoints
  bool compare_ideal = true;           ///< also run the ideal elastic model and write metrics.json
  /// Share the ideal model between runs through this directory (app/simulate/ideal_cache.h); "" = compute.
  std::string ideal_cache_dir;
  /// The reduced model's offline part (solver.model = "reduced"; app/simulate/reduced.h) is stored
  /// and reused here; "" = computed every run.
  std::string cache_dir;
};

struct RunResult {
  std::vector<StateRecord> records;
  std::string status = "ok";  ///< "ok" or the error message
  double wall_s = 0.0;
  std::vector<std::string> warnings;  ///< summary.json's, to print at the end
};

/// Runs the scene and writes the run directory. Physics failures are recorded in summary.json
/// (status) and rethrown after the outputs so far are safely on disk. With options.resume the
/// scene argument is ignored and out_dir/scene.toml is used; a missing, damaged or foreign
/// checkpoint (another scene, mesh, protocol or build) is an InputError before any work.
RunResult run_simulation(const Scene& scene, const RunOptions& options);

/// What a run found, in one line for the console: the angle at the largest reported pressure (its
/// last report there in each trial: the end of the top hold on a staircase), per trial, with
/// trials a cycle jump extrapolated marked "*". "" when nothing was reported.
std::string top_angles_text(const std::vector<StateRecord>& records);

}  // namespace pneufem
