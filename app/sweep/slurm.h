#pragma once
// Sweeps on a SLURM cluster (`pneufem sweep ... --scheduler slurm`): the points as one job array.
//
//   array      one task per point; the task id is the point number (points/NNNN), so `squeue`,
//              `sacct` and `scancel JOB_7` speak of points. Each task runs the same `pneufem
//              simulate` command as a local worker (app/sweep/command.cpp, WorkerSetup::argv): the
//              script holds the command once and a `case` of the points' values, selected by
//              $SLURM_ARRAY_TASK_ID. A reduced sweep whose offline part is not built yet submits
//              its builders first and the other points as a second array that starts after it
//              (--dependency=afterany), so no task holds an allocation waiting for a cache lock.
//   caches     DIR/ideal_cache and DIR/rom_cache live in the sweep directory, which must be on the
//              cluster's shared file system. Each entry is computed under flock() on its .lock file
//              and written atomically (a temporary file renamed into place); readers take the lock
//              too. Linux maps flock() on NFS onto POSIX byte-range locks, which the NFS lock
//              manager (v3) or the protocol itself (v4) keeps across nodes; GPFS and BeeGFS (global
//              file locks on) lock across nodes; Lustre does with the `flock` mount option, only
//              node-locally with `localflock`, and refuses it without either. The controller's own
//              flock() of DIR/.sweep.lock refuses a file system without locks before submitting;
//              for node-local locks docs/commands.md gives the alternative (the caches built by
//              one point first).
//   controller the `pneufem sweep` command itself: it records each submitted job in
//              DIR/slurm/jobs.tsv, and every invocation collects the finished points (the local
//              sweep's resume check), asks squeue which points are still queued or running,
//              resubmits the others that failed or have no result, and writes sweep.csv, the
//              plots and sweep.json of what has finished.
#include <set>
#include <string>
#include <vector>

namespace pneufem {

/// --partition, --time, --mem, --account, --max-parallel: passed to sbatch as given ("" / 0 = the
/// cluster's default).
struct SlurmOptions {
  std::string partition, time, mem, account;
  int max_parallel = 0;  ///< tasks running at once (the array's %N); 0 = no limit
};

/// Throws InputError naming the option for a value sbatch would misread (spaces, newlines, a
/// --time or --mem not in SLURM's form).
void check_slurm_options(const SlurmOptions& s);

/// `s` as one bash word in single quotes.
std::string shell_quote(const std::string& s);

/// The --array value of `points` (sorted, each once): ranges where consecutive ("1-4,7,9-10"),
/// with "%N" for max_parallel > 0.
std::string array_spec(const std::vector<int>& points, int max_parallel);

/// One job array of a sweep: which points, and the command each runs.
struct SweepArray {
  std::string job_name;
  std::vector<int> points;                       ///< task ids = point numbers
  std::vector<std::vector<std::string>> values;  ///< per point, its parameters' values as scene text
  std::vector<std::string> keys;                 ///< the swept scene keys
  /// The worker's command, with kDirWord for its run directory and kPointWord where the point's
  /// `--set KEY=VALUE` arguments go.
  std::vector<std::string> command;
  std::string points_dir;  ///< absolute DIR/points
  std::string log_dir;     ///< absolute DIR/slurm (SLURM's own output of each task)
  int cpus_per_task = 1;
  std::string dependency;  ///< "" or a job id the array starts after (afterany)
  std::string header;      ///< comment lines (the command line, the version)
};
inline constexpr const char* kDirWord = "@POINT_DIR@";
inline constexpr const char* kPointWord = "@POINT_SETS@";

/// The sbatch script of `a` with the options `s`.
std::string slurm_array_script(const SweepArray& a, const SlurmOptions& s);

/// Submits the script file with `sbatch --parsable`; returns the job id. Throws std::runtime_error
/// with sbatch's message when it fails or is not installed.
std::string sbatch_submit(const std::string& script_path);

/// The tasks (point numbers) of `job_ids` that SLURM still has queued or running (squeue).
/// Throws std::runtime_error when squeue fails.
std::set<int> active_array_tasks(const std::vector<std::string>& job_ids);

/// The cluster's MaxArraySize (scontrol show config): task ids must stay below it; 0 when unknown.
long max_array_size();

}  // namespace pneufem
