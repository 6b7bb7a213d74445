#pragma once
// The reduced-order model of a scene (engine/rom.h) as the commands use it: the offline part
// (elastic reference, its traced path, the basis) built once per actuator and stored in a cache
// directory, and reduced runs whose reports are checked against the full model.
//
// Offline part. The reference is the scene's elastic reference (scenes/build_model.h
// elastic_reference_scene: effects off, no gravity, no lag). Its path is traced to 1.8 x the
// largest pressure of the load (softened models reach angles the elastic one reaches only above
// it), in 40 samples up to that pressure. Cache key (app/simulate/result_cache.h): the executable,
// the reference's scene without its [load], [output] and [solver] tables, the mesh and its sets,
// the Newton tolerance, the traced range and the basis options: any effect, constant, gravity or
// protocol reuses the basis of the same actuator; a change of mesh, material or build does not.
//
// Online part. run_reduced marches the load (ReducedRun), then replays the whole mesh's history
// along the reduced trajectory (replay_reduced_run): VTU fields at the reports and the indicator,
// the adjoint-weighted full residual, at every report; and at each trial's top (its first report
// at its largest pressure and its report of largest angle) the corrected history's estimate
// (engine/rom.h ReplayOptions: the full model's history built along the corrected states, one
// Newton solve per top), which also sees the drift of the reduced run's history. The caller
// decides what a report above solver.reduced_check_deg means (simulate falls back to the full FEM).
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "core/errors.h"
#include "engine/rom.h"
#include "scenes/build_model.h"

namespace pneufem {

struct ReducedSetup {
  std::unique_ptr<BuiltModel> reference;  ///< the elastic reference model
  ElasticPathTrace path;                  ///< its traced elastic path (an enrichment rebuilds the basis on it)
  RomBasisOptions options;                ///< the basis options
  ReducedBasis basis;
  std::string path_source, basis_source;  ///< "computed", "cache <file>", "recomputed (...)"
  double offline_s = 0.0;                 ///< wall time of this setup (trace + basis, or reading them)
};

/// The reduced model's offline part for `scene` with loads up to `p_max_Pa`, cached in `cache_dir`
/// ("" = always computed). Throws InputError for a scene the reduced model cannot run (non-local
/// damage, a mesh without a stiff layer is fine), PhysicsError when the path cannot be traced.
std::unique_ptr<ReducedSetup> reduced_setup(const Scene& scene, double p_max_Pa, const RomBasisOptions& options,
                                            const std::string& cache_dir);

/// One report of a reduced run with its check.
struct ReducedReport {
  StateRecord record;
  ReducedCheck check;
};

struct ReducedRunResult {
  std::vector<ReducedReport> reports;
  ReducedRunStats stats;
  double replay_s = 0.0;       ///< wall time of the full-mesh replay
  double worst_check_deg = 0.0;  ///< largest |estimated angle error| over the reports (either estimate)
  int worst_report = -1;       ///< its index in `reports`
  int unchecked_report = -1;   ///< the first report whose corrected solve found no equilibrium, or -1
  /// The basis enrichments made (solver.reduced_enrich_rounds): why each was made (the check of the
  /// run before it), what it added and what the run with it cost. The reports above are the last run's.
  struct Enrichment {
    std::string why;             ///< reduced_check_failure of the run before
    int snapshots = 0, modes = 0;  ///< corrected states in the basis so far; modes of the new basis
    double basis_s = 0.0;        ///< wall time of the basis build
    std::string failed;          ///< why the run with this basis failed ("" = it ran; then the run before stands)
  };
  std::vector<Enrichment> enrichments;
  int modes = 0;               ///< modes of the basis of the last run
  std::string failed;          ///< why the run stopped part-way (ReducedRunFailed), "" = it ran to its end
};

/// A reduced run that stopped part-way (its Newton or its step control gave up), with what it had
/// done by then: a checked run's caller falls back to the full FEM and reports these statistics.
class ReducedRunFailed : public PhysicsError {
 public:
  ReducedRunFailed(const PhysicsError& e, const ReducedRunStats& s, int basis_modes)
      : PhysicsError(e.what(), e.element(), e.time_s()), stats(s), modes(basis_modes) {}
  ReducedRunStats stats;
  int modes = 0;  ///< of the basis that failed
};

/// Runs `bm` (the scene's model, same mesh as the setup's reference) through its load with the
/// reduced model, replays the history and checks every report. `at_report` (optional) sees each
/// report's record, full displacement and whole-mesh history, in order, after the replay.
/// `check` = false: no replay and no indicator: the reports of the run alone, each passed to
/// `at_report` as it is solved, with empty displacement and history.
/// Enrichment (with `restart` and bm.solver.reduced_enrich_rounds > 0): when the check fails
/// (reduced_check_failure with bm.solver.reduced_check_deg), the converged corrected states of the
/// replay (full-model equilibria near the reduced ones, with the history the full model would have
/// built) join the basis as snapshots (build_reduced_basis on the setup's path and options), the
/// run and its check are repeated, and `restart` is called first (with what the enrichment did) so
/// the caller can drop the reports it has seen. At most reduced_enrich_rounds times; the result is the last run's.
/// A run that stops part-way throws ReducedRunFailed (in the first round; a later round's failure
/// leaves the round before standing, see reduced.cpp).
/// Why: the snapshots carry the damaged shapes the softening responses hold only to first order
/// (measured on the 15-chamber story at h = 6: max error over three trials 0.90 -> 0.24 deg after
/// two rounds; bench/results/rom_h6_pressure_order).
ReducedRunResult run_reduced(const ReducedSetup& setup, const BuiltModel& bm,
                             const std::function<void(const StateRecord&, const Eigen::VectorXd&, const std::vector<double>&)>&
                                 at_report = nullptr,
                             bool check = true, const std::function<void(const ReducedRunResult::Enrichment&)>& restart = nullptr);

/// Why a checked reduced run must not stand ("" = it may): the full model found no equilibrium
/// near a top's reduced state (it could not be checked), or the worst estimated angle error exceeds
/// `tol_deg` (solver.reduced_check_deg); with the report where.
std::string reduced_check_failure(const ReducedRunResult& run, double tol_deg);

/// The largest pressure of a load history (Pa).
double peak_pressure(const LoadHistory& load);

}  // namespace pneufem
