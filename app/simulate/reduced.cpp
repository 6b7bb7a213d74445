#include "app/simulate/reduced.h"

#include <chrono>
#include <cmath>
#include <map>
#include <set>

#include "app/simulate/result_cache.h"
#include "core/errors.h"
#include "engine/path_model.h"

namespace pneufem {

namespace {

using Clock = std::chrono::steady_clock;
double seconds_since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

/// A trace stored flat: the sample count, the pressures, then each sample's displacement.
std::vector<double> flatten_trace(const ElasticPathTrace& t) {
  std::vector<double> f = {static_cast<double>(t.p_Pa.size())};
  f.insert(f.end(), t.p_Pa.begin(), t.p_Pa.end());
  for (const Eigen::VectorXd& u : t.u) f.insert(f.end(), u.data(), u.data() + u.size());
  return f;
}

ElasticPathTrace unflatten_trace(const std::vector<double>& f, Eigen::Index dofs, const std::string& source) {
  const std::size_t ns = f.empty() ? 0 : static_cast<std::size_t>(f[0]);
  if (f.empty() || f.size() != 1 + ns + ns * static_cast<std::size_t>(dofs))
    throw InputError("reduced model: the stored elastic path (" + source + ") does not fit the model; delete it");
  ElasticPathTrace t;
  t.p_Pa.assign(f.begin() + 1, f.begin() + 1 + static_cast<std::ptrdiff_t>(ns));
  for (std::size_t k = 0; k < ns; ++k)
    t.u.push_back(Eigen::Map<const Eigen::VectorXd>(f.data() + 1 + ns + k * static_cast<std::size_t>(dofs), dofs));
  return t;
}

/// Per trial: the first report at the trial's largest pressure and the report of largest angle.
std::set<std::size_t> trial_tops(const std::vector<StateRecord>& records) {
  std::map<int, std::size_t> top_p, top_angle;
  for (std::size_t k = 0; k < records.size(); ++k) {
    auto [p, new_p] = top_p.emplace(records[k].trial, k);
    if (!new_p && records[k].pressure_Pa > records[p->second].pressure_Pa) p->second = k;
    auto [a, new_a] = top_angle.emplace(records[k].trial, k);
    if (!new_a && records[k].angle_deg > records[a->second].angle_deg) a->second = k;
  }
  std::set<std::size_t> tops;
  for (auto [trial, k] : top_p) tops.insert(k);
  for (auto [trial, k] : top_angle) tops.insert(k);
  return tops;
}

}  // namespace

std::string reduced_check_failure(const ReducedRunResult& run, double tol_deg) {
  if (run.unchecked_report >= 0) {
    const StateRecord& u = run.reports[static_cast<std::size_t>(run.unchecked_report)].record;
    char why[320];
    std::snprintf(why, sizeof why,
                  "the full model found no equilibrium near the reduced state at trial %d, t = %.2f s (%.1f kPa), so the "
                  "reduced model could not be checked there (the actuator is near its limit point)",
                  u.trial, u.time_s, u.pressure_Pa * 1e-3);
    return why;
  }
  if (!(run.worst_check_deg > tol_deg)) return "";
  const StateRecord& w = run.reports[static_cast<std::size_t>(run.worst_report)].record;
  char why[320];
  std::snprintf(why, sizeof why,
                "the reduced model's estimated angle error %.3g deg at trial %d, t = %.2f s (%.1f kPa) exceeds "
                "solver.reduced_check_deg = %.3g",
                run.worst_check_deg, w.trial, w.time_s, w.pressure_Pa * 1e-3, tol_deg);
  return why;
}

double peak_pressure(const LoadHistory& load) {
  double p = 0.0;
  for (const TrialLoad& tl : load.trials)
    for (double x : tl.pressure_Pa) p = std::max(p, x);
  return p;
}

std::unique_ptr<ReducedSetup> reduced_setup(const Scene& scene, double p_max_Pa, const RomBasisOptions& options,
                                            const std::string& cache_dir) {
  const auto t0 = Clock::now();
  auto out = std::make_unique<ReducedSetup>();
  const Scene ref_scene = elastic_reference_scene(scene).with({"load.trials=1"});
  out->reference = build_model(ref_scene);
  const Model& ref = out->reference->model;
  PathModelOptions po;
  po.p_top_Pa = 1.8 * std::max(p_max_Pa, 1e3);
  po.dp_Pa = std::max(p_max_Pa, 1e3) / 40.0;
  po.newton = out->reference->solver.quasi_static.newton;
  Fnv1a h;
  h.str(executable_fingerprint());
  h.str(ref_scene.model_toml_without({"load", "output", "solver"}));
  hash_mesh(h, ref);
  h.num(po.newton.rel_tol);
  h.num(po.p_top_Pa);
  h.num(po.dp_Pa);
  const std::string path_key = h.hex();
  auto trace = [&] { return flatten_trace(trace_elastic_path(ref, po)); };
  out->path = unflatten_trace(cache_dir.empty() ? (out->path_source = "computed", trace())
                                               : cached_doubles(cache_dir, "rom_path", path_key, trace, &out->path_source),
                             ref.num_dofs(), out->path_source);
  const ElasticPathTrace& path = out->path;
  out->options = options;
  h.str("basis");
  h.num(options.clusters);
  h.num(options.mode_samples);
  h.num(options.max_modes);
  h.num(options.pod_tolerance);
  h.num(options.ecsw_tolerance);
  h.num(options.training_fields);
  h.num(options.training_softening);
  h.num(options.training_amplitude);
  h.num(options.stiff_modulus_ratio);
  h.num(options.hyper_reduce ? 1.0 : 0.0);
  h.num(options.softened_levels);
  h.num(options.softened_max);
  if (options.galerkin_theta_row) h.str("galerkin theta row");  // absent from older keys: they stay valid
  if (options.tangent_free_modes) h.str("tangent-free modes");  // likewise
  if (options.stiff_parts == RomBasisOptions::StiffParts::exact) h.str("stiff parts exact");      // likewise
  if (options.stiff_parts == RomBasisOptions::StiffParts::sampled) h.str("stiff parts sampled");  // likewise
  if (options.release_responses) h.str("release responses");  // likewise
  if (options.ecsw_blocks > 0) {  // likewise
    h.str("ecsw blocks");
    h.num(options.ecsw_blocks);
  }
  auto build = [&] { return build_reduced_basis(ref, path, options).to_doubles(); };
  out->basis = ReducedBasis::from_doubles(cache_dir.empty() ? (out->basis_source = "computed", build())
                                                            : cached_doubles(cache_dir, "rom_basis", h.hex(), build, &out->basis_source));
  out->offline_s = seconds_since(t0);
  return out;
}

namespace {

/// One reduced run with `basis` and, with `check`, its replay and check; the converged corrected
/// states go to `corrected` (may be null).
ReducedRunResult run_and_check(const ReducedSetup& setup, const ReducedBasis& basis, const BuiltModel& bm,
                               const std::function<void(const StateRecord&, const Eigen::VectorXd&, const std::vector<double>&)>& at_report,
                               bool check, std::vector<Eigen::VectorXd>* corrected) {
  ReducedRunResult res;
  res.modes = basis.num_modes();
  const ReducedOrderModel rom(setup.reference->model, basis, bm.model);
  ReducedRun run(rom, bm.solver.quasi_static);
  std::vector<StateRecord> records;
  // Unchecked, each report goes to at_report as it is solved (without fields), so a run that fails
  // part-way has shown the reports before the failure.
  const Eigen::VectorXd no_field;
  const auto t_run = Clock::now();
  try {
    run.run(bm.load, [&](const StateRecord& r, const ReducedCoordinates&, const Eigen::VectorXd&) {
      records.push_back(r);
      if (!check && at_report) at_report(r, no_field, {});
    });
  } catch (const PhysicsError& e) {
    ReducedRunStats stats = run.stats();
    stats.wall_s = seconds_since(t_run);
    throw ReducedRunFailed(e, stats, basis.num_modes());
  }
  res.stats = run.stats();
  if (!check) {
    for (const StateRecord& r : records) res.reports.push_back({r, ReducedCheck{}});
    return res;
  }
  const auto t0 = Clock::now();
  // The corrected history (engine/rom.h, ReplayOptions) is corrected at each trial's top: its
  // first report at the trial's largest pressure and its report of largest angle (the top hold's
  // start and end on a staircase), where the actuator is most sensitive and the history effects
  // have acted longest. Between them the history follows the reduced trajectory with the held
  // correction, so the estimate at the tops includes the drift of the history over the trials.
  // With solver.reduced_check_at = "reports", at every loaded report instead (the corrected states
  // then follow the full model's closely away from the limit point, at ~10x the cost).
  const std::set<std::size_t> tops = trial_tops(records);
  const bool every_report = bm.solver.reduced_check_at == SolverSettings::CheckAt::Reports;
  std::size_t i = 0;
  ReplayOptions replay;
  replay.corrected_at = [&](const ReducedStep& s) {
    return every_report ? s.pressure_Pa > 0.0 : tops.count(static_cast<std::size_t>(s.report)) > 0;
  };
  replay.newton = bm.solver.quasi_static.newton;
  replay_reduced_run(rom, run.trajectory(), [&](const ReducedStep&, const Eigen::VectorXd& u, const std::vector<double>& state,
                                                const ReducedCheck& estimate) {
    if (i >= records.size()) throw PhysicsError("reduced model: the replay found more reports than the run made (internal error)");
    ReducedCheck kept = estimate;
    if (corrected && kept.corrected_u.size() > 0) corrected->push_back(std::move(kept.corrected_u));
    kept.corrected_u = Eigen::VectorXd();
    res.reports.push_back({records[i], kept});
    double e = std::isnan(estimate.angle_error_deg) ? 0.0 : std::abs(estimate.angle_error_deg);
    if (!std::isnan(estimate.corrected_angle_error_deg)) e = std::max(e, std::abs(estimate.corrected_angle_error_deg));
    if (e > res.worst_check_deg || res.worst_report < 0) res.worst_check_deg = e, res.worst_report = static_cast<int>(i);
    if (estimate.corrected_failed && res.unchecked_report < 0) res.unchecked_report = static_cast<int>(i);
    if (at_report) at_report(records[i], u, state);
    ++i;
  }, replay);
  if (i != records.size()) throw PhysicsError("reduced model: the replay found fewer reports than the run made (internal error)");
  res.replay_s = seconds_since(t0);
  return res;
}

}  // namespace

ReducedRunResult run_reduced(const ReducedSetup& setup, const BuiltModel& bm,
                             const std::function<void(const StateRecord&, const Eigen::VectorXd&, const std::vector<double>&)>& at_report,
                             bool check, const std::function<void(const ReducedRunResult::Enrichment&)>& restart) {
  const int rounds = check && restart ? bm.solver.reduced_enrich_rounds : 0;
  std::vector<Eigen::VectorXd> snapshots;
  std::unique_ptr<ReducedBasis> enriched;  // the basis of the last round (null: the setup's)
  std::vector<ReducedRunResult::Enrichment> done;
  ReducedRunResult last;  // the last round that ran to its end
  for (int round = 0;; ++round) {
    const ReducedBasis& basis = enriched ? *enriched : setup.basis;
    ReducedRunResult res;
    try {
      res = run_and_check(setup, basis, bm, at_report, check, round < rounds ? &snapshots : nullptr);
    } catch (const PhysicsError& e) {
      if (round == 0) throw;
      // A richer basis can lose the equilibrium an earlier one found (measured: the zero-time
      // release after 45 kPa with damaged shapes from other constants). The earlier round's result
      // stands, with its failed check, so the caller falls back; the enrichment says why.
      done.back().failed = e.what();
      last.enrichments = done;
      return last;
    }
    res.enrichments = done;
    if (round >= rounds || snapshots.empty()) return res;
    const std::string why = reduced_check_failure(res, bm.solver.reduced_check_deg);
    if (why.empty()) return res;
    last = std::move(res);
    // Enrich: the corrected states of every round so far join the basis (each round's states are
    // nearer the full model's, and the earlier ones keep the shapes they added).
    const auto t0 = Clock::now();
    enriched = std::make_unique<ReducedBasis>(build_reduced_basis(setup.reference->model, setup.path, setup.options, snapshots));
    done.push_back({why, static_cast<int>(snapshots.size()), enriched->num_modes(), seconds_since(t0), ""});
    restart(done.back());
  }
}

}  // namespace pneufem
