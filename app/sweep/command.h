#pragma once
// Parameter sweeps (`pneufem sweep`): run one scene at many values of any numeric scene keys
// (damage constants first of all) and tabulate the paper's metrics per point.
//
//   points     the cartesian product of each --param's N values (linear or log spacing), or
//              --lhs N Latin-hypercube samples over the ranges (log ranges sampled in log space)
//   workers    shared nothing: each point is a separate `pneufem simulate` process (fork/exec of
//              the pneufem binary) writing DIR/points/NNNN/; J processes at a time with T threads
//              each. A point's result does not depend on J or T.
//   resume     a point is skipped when its directory holds summary.json with "status": "ok" and a
//              scene.toml equal to the point's resolved scene (same scene file, --set and
//              parameter values); anything else (failed, interrupted, changed) is run again from a
//              clean directory. Re-running the same command after a kill continues the sweep.
//   model      --model auto (default) runs the reduced-order model (app/simulate/reduced.h) when
//              every point has the same elastic reference, i.e. the swept keys are effect
//              constants, gravity or protocol; else the full FEM. The offline part of the reduced
//              model (elastic path and basis, ~25 min on the default mesh) is built in
//              DIR/rom_cache by the first point that needs it, before any other point, and read by
//              the others. Each point records which model ran (a reduced run may fall back to the
//              full FEM).
//              --fem-points re-runs chosen points with the full FEM into DIR/points/NNNN/fem/ and
//              records the FEM's NRMSE and the largest |reduced - FEM| angle.
//   outputs    DIR/sweep.csv (one row per point, rewritten atomically after every point),
//              DIR/sweep_<key>.svg (final-trial NRMSE against each parameter), DIR/sweep.json.
// A failed point is recorded with its error and does not stop the sweep.
//   slurm      --scheduler slurm submits the points as a job array instead of running them here;
//              the same command again collects, resubmits failed or missing points and writes the
//              outputs (app/sweep/slurm.h).
#include <cstdint>
#include <cstdio>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "app/sweep/point.h"
#include "app/sweep/slurm.h"

namespace pneufem {

/// Parses a --param spec; throws InputError quoting the spec and the expected form.
ParamSpec parse_param_spec(const std::string& text);

/// The values of one grid axis: n values from lo to hi inclusive, evenly spaced (in log10 when
/// log); n = 1 gives lo. Integer keys are rounded and repeated values dropped.
std::vector<double> grid_values(const ParamSpec& p);
/// Cartesian product of the grid axes, one row per point, the last parameter varying fastest.
std::vector<std::vector<double>> grid_points(const std::vector<ParamSpec>& params);
/// n Latin-hypercube samples: each parameter's range split into n equal strata (in log space for
/// log ranges), each stratum sampled exactly once at a uniformly random position, strata paired
/// by independent random permutations (McKay, Beckman & Conover 1979). Deterministic for a seed
/// on every platform (mt19937_64's output is fixed by the C++ standard; the conversions are ours).
std::vector<std::vector<double>> lhs_points(const std::vector<ParamSpec>& params, int n, std::uint64_t seed);

/// A value as scene (TOML) text: integers as integers, floats in the shortest form that reads back
/// to the same double, always with a '.' or an exponent (100.0, 316.22776601683796, 1e-05).
std::string format_value(double v, bool integer);

struct SweepOptions {
  std::string scene_path;           ///< "" = the built-in default scene
  std::vector<std::string> params;  ///< --param specs
  std::vector<std::string> sets;    ///< --set key=value, applied before the parameters
  int lhs = 0;                      ///< > 0: that many Latin-hypercube samples instead of the grid
  std::uint64_t seed = 1;           ///< LHS seed
  std::string out_dir;
  int jobs = 0;             ///< worker processes (0 = number of cores)
  int threads_per_job = 1;  ///< --threads of each worker
  std::string exe;          ///< the pneufem binary the workers run
  std::string model = "auto";   ///< "auto", "full" or "reduced": the model of the workers (solver.model)
  std::vector<int> fem_points;  ///< points (1-based) re-run with the full FEM after the sweep
  bool dry_run = false;     ///< print the points (with SLURM: the sbatch script), run nothing, write nothing
  std::string scheduler = "local";  ///< "local" (worker processes here) or "slurm" (a job array, app/sweep/slurm.h)
  SlurmOptions slurm;               ///< sbatch options of --scheduler slurm
  std::string command_line;
  std::FILE* log = stdout;  ///< one line per point; nullptr = quiet
};

struct SweepResult {
  std::vector<SweepPoint> points;
  std::string model;         ///< "reduced" or "full": what the workers were asked to run
  std::string model_reason;  ///< why (the --model choice, or what auto saw)
  int offline_parts = 0;     ///< distinct offline parts of a reduced sweep (0 with the full FEM)
  int ok = 0, failed = 0, skipped = 0;
  int fem_failed = 0;        ///< --fem-points whose FEM run failed
  int pending = 0;           ///< --scheduler slurm: points queued or running, or submitted now
  std::vector<std::string> submitted_jobs;  ///< --scheduler slurm: the job ids submitted by this call
  std::vector<int> submitted_points;        ///< --scheduler slurm: the points they run
  double wall_s = 0.0;
};

/// Runs (or, with dry_run, plans) the sweep. Bad options throw InputError naming the option
/// (--param, --lhs, --jobs, --fem-points, ...); failed points are recorded, not thrown.
SweepResult run_sweep(const SweepOptions& options);

}  // namespace pneufem
