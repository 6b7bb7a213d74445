#include "app/simulate/command.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <tbb/global_control.h>
#include <tbb/info.h>

#include "analysis/paper_metrics.h"
#include "app/simulate/checkpoint_file.h"
#include "app/simulate/ideal_cache.h"
#include "app/simulate/reduced.h"
#include "core/atomic_file.h"
#include "core/errors.h"
#include "core/output_dir.h"
#include "core/progress.h"
#include "core/json_writer.h"
#include "core/version.h"
#include "damage/registry.h"
#include "engine/angle.h"
#include "engine/assembly.h"
#include "engine/explicit.h"
#include "scenes/build_model.h"
#include "scenes/scene_settings.h"
#include "viz/vtk_output.h"

namespace pneufem {

namespace fs = std::filesystem;

namespace {

std::string mesh_stats_json(const MeshStats& s) {
  json::Object regions;
  for (const auto& [name, n] : s.elements_per_region) regions.add(name, static_cast<double>(n));
  json::Object o;
  o.add("nodes", static_cast<double>(s.nodes))
      .add("elements", static_cast<double>(s.elements))
      .add_str("element_type", s.element_type)
      .add("dofs", 3.0 * s.nodes)
      .add("volume_m3", s.volume_m3)
      .add("min_edge_m", s.min_edge_m)
      .add("max_edge_m", s.max_edge_m)
      .add("min_quality_radius_ratio", s.min_quality)
      .add("mean_quality_radius_ratio", s.mean_quality)
      .add("bbox_min_m", json::array({s.bbox_min.x(), s.bbox_min.y(), s.bbox_min.z()}))
      .add("bbox_max_m", json::array({s.bbox_max.x(), s.bbox_max.y(), s.bbox_max.z()}))
      .add("elements_per_region", regions.str(4));
  return o.str(2);
}

/// With trials skipped by cycle jumping, a last column `extrapolated` (1: not solved, see angles_csv).
std::string states_csv(const std::vector<StateRecord>& recs) {
  const bool jumped = std::any_of(recs.begin(), recs.end(), [](const StateRecord& r) { return r.extrapolated; });
  std::string s = "trial,time_s,global_time_s,pressure_kPa,angle_deg,cavity_volume_mm3,tip_plane_rms_mm";
  s += jumped ? ",extrapolated\n" : "\n";
  char line[256];
  for (const StateRecord& r : recs) {
    std::snprintf(line, sizeof line, "%d,%.6f,%.6f,%.6f,%.6f,%.6f,%.6g", r.trial, r.time_s, r.global_time_s,
                  r.pressure_Pa * 1e-3, r.angle_deg, r.cavity_volume_m3 * 1e9, r.plane_rms_m * 1e3);
    s += line;
    s += jumped ? (r.extrapolated ? ",1\n" : ",0\n") : "\n";
  }
  return s;
}

/// Angles of one trial at each step's mark and end (records at those exact report times).
StepAngles step_angles(const TrialLoad& tl, int trial, const std::vector<StateRecord>& recs) {
  StepAngles s;
  s.trial = trial;
  auto at = [&](double t) {
    for (const StateRecord& r : recs)
      if (r.trial == trial && std::abs(r.time_s - t) < 1e-9) return r.angle_deg;
    throw InputError("metrics: no report at t = " + std::to_string(t) + " s of trial " + std::to_string(trial));
  };
  for (std::size_t k = 0; k < tl.step_start_s.size(); ++k) {
    s.level_kPa.push_back(tl.step_level_Pa[k] * 1e-3);
    s.at_mark_deg.push_back(at(tl.step_start_s[k] + tl.mark_s));
    s.at_end_deg.push_back(at(tl.step_end_s[k]));
  }
  return s;
}

/// Scene keys that switch off every inelastic effect (the "ideal" elastic model of the paper).
std::vector<std::string> ideal_overrides(const Scene& scene, bool& any_effect) {
  std::vector<std::string> sets;
  any_effect = false;
  for (const std::string& m : scene.table_keys("materials"))
    for (const MaterialEffect* fx : material_effects()) {  // built-in and registered (damage/registry.h)
      const std::string key = "materials." + m + "." + fx->name + ".enabled";
      if (scene.has(key) && scene.boolean(key)) {
        any_effect = true;
        sets.push_back(key + "=false");
      }
    }
  return sets;
}

/// The run's progress on stderr (core/progress.h): the share of the load's physical time reported
/// so far, with the trial, pressure and angle of the last report.
class ProgressLine {
 public:
  ProgressLine(const RunOptions& opt, const LoadHistory& load)
      : meter_("simulate", opt.progress                     ? ProgressMeter::Mode::Terminal
                           : opt.progress_log_every_s > 0.0 ? ProgressMeter::Mode::Log
                                                            : ProgressMeter::Mode::Off,
               opt.progress_log_every_s),
        trials_(static_cast<int>(load.trials.size())) {
    for (const TrialLoad& t : load.trials) total_s_ += t.duration();
    if (trials_ > 1) total_s_ += (trials_ - 1) * load.rest_between_trials_s;
  }
  void update(const StateRecord& r) {
    char d[160];
    std::snprintf(d, sizeof d, "trial %d/%d, t = %.1f s, %.1f kPa, %.2f deg", r.trial, trials_, r.time_s, r.pressure_Pa * 1e-3,
                  r.angle_deg);
    meter_.update(total_s_ > 0.0 ? r.global_time_s / total_s_ : 0.0, d);
  }
  /// A line of its own (a stage, a fallback), in both the terminal's and the log's mode.
  void message(const std::string& text) { meter_.message(text); }
  void done() { meter_.done(); }

 private:
  ProgressMeter meter_;
  int trials_ = 0;
  double total_s_ = 0.0;
};

// Application part of a checkpoint: the reports so far and the VTU series.
struct AppCheckpoint {
  std::vector<StateRecord> records;
  std::vector<std::pair<double, std::string>> vtu;
};

void write_app_section(std::ostream& os, const AppCheckpoint& a) {
  const std::uint64_t nr = a.records.size(), nv = a.vtu.size();
  os.write(reinterpret_cast<const char*>(&nr), sizeof nr);
  for (const StateRecord& r : a.records) os.write(reinterpret_cast<const char*>(&r), sizeof r);
  os.write(reinterpret_cast<const char*>(&nv), sizeof nv);
  for (const auto& [t, f] : a.vtu) {
    const std::uint64_t len = f.size();
    os.write(reinterpret_cast<const char*>(&t), sizeof t);
    os.write(reinterpret_cast<const char*>(&len), sizeof len);
    os.write(f.data(), static_cast<std::streamsize>(len));
  }
}

AppCheckpoint read_app_section(std::istream& is) {
  AppCheckpoint a;
  std::uint64_t nr = 0, nv = 0;
  auto check = [&] {
    if (!is) throw InputError("checkpoint: file is truncated; the run cannot be resumed (start it again)");
  };
  is.read(reinterpret_cast<char*>(&nr), sizeof nr);
  check();
  a.records.resize(nr);
  for (auto& r : a.records) is.read(reinterpret_cast<char*>(&r), sizeof r);
  is.read(reinterpret_cast<char*>(&nv), sizeof nv);
  check();
  for (std::uint64_t i = 0; i < nv; ++i) {
    double t = 0;
    std::uint64_t len = 0;
    is.read(reinterpret_cast<char*>(&t), sizeof t);
    is.read(reinterpret_cast<char*>(&len), sizeof len);
    check();
    std::string f(len, '\0');
    is.read(f.data(), static_cast<std::streamsize>(len));
    a.vtu.emplace_back(t, f);
  }
  check();
  return a;
}

/// For --resume DIR: DIR must hold a run with a checkpoint; else an InputError saying why there is
/// nothing to resume and what to do.
void require_checkpoint(const fs::path& dir, const std::string& name) {
  if (fs::exists(dir / "checkpoint.bin")) return;
  if (!fs::exists(dir / "scene.toml"))
    throw InputError("--resume " + name + ": not a run directory (no scene.toml and no checkpoint.bin); give the --out "
                     "directory of the run to continue");
  throw InputError("--resume " + name + ": nothing to resume: no checkpoint.bin (the run stopped or ended before its "
                   "first checkpoint); run it again: pneufem simulate " + name + "/scene.toml --out " + name);
}

/// Quasi-static run of a scene with no outputs (the ideal model of the metrics).
std::vector<StateRecord> records_of(const Scene& scene) {
  std::unique_ptr<BuiltModel> bm = build_model(scene);
  for (const std::string& n : scene.notes()) std::fprintf(stderr, "note: %s\n", n.c_str());  // a deck's materials
  const Assembler asmb(bm->model);
  QuasiStaticRun run(asmb, bm->solver.quasi_static);
  std::vector<StateRecord> recs;
  run.run(bm->load, [&](const StateRecord& r, const Eigen::VectorXd&, const std::vector<double>&) { recs.push_back(r); });
  return recs;
}

/// Per report of a reduced run: its indicator (reduced_check.csv).
std::string reduced_check_csv(const std::vector<ReducedReport>& reports) {
  std::string s = "trial,time_s,pressure_kPa,angle_deg,estimated_angle_error_deg,corrected_history_angle_error_deg,residual_rel\n";
  char line[256];
  for (const ReducedReport& r : reports) {
    std::snprintf(line, sizeof line, "%d,%.6f,%.6f,%.6f,%.6g,%.6g,%.6g\n", r.record.trial, r.record.time_s, r.record.pressure_Pa * 1e-3,
                  r.record.angle_deg, r.check.angle_error_deg, r.check.corrected_angle_error_deg, r.check.residual_rel);
    s += line;
  }
  return s;
}

/// What summary.json says about a reduced run: the offline part, the online cost, the check and
/// whether the run fell back to the full FEM, where and why.
std::string reduced_summary(const ReducedSetup& setup, const ReducedRunResult& res, double tol_deg, const std::string& fallback) {
  const ReducedBasis& B = setup.basis;
  json::Object offline;
  offline.add_str("path", setup.path_source)
      .add_str("basis", setup.basis_source)
      .add("offline_s", setup.offline_s)
      .add("path_samples", static_cast<double>(B.num_samples()))
      .add("modes", static_cast<double>(B.num_modes()))
      .add("sampled_elements", static_cast<double>(B.elements.size()))
      .add("soft_elements", static_cast<double>(B.info.soft_elements))
      .add("pod_energy_left", B.info.pod_energy_left)
      .add("ecsw_worst_residual", B.info.ecsw_worst_residual);
  json::Object online;
  online.add("modes", static_cast<double>(res.modes))
      .add("states", static_cast<double>(res.stats.states))
      .add("rejected_time_steps", static_cast<double>(res.stats.rejected_steps))
      .add("newton_iterations", static_cast<double>(res.stats.newton_iterations))
      .add("solve_s", res.stats.wall_s)
      .add("replay_s", res.replay_s)
      .add("beyond_traced_path", res.stats.beyond_path ? 1.0 : 0.0);
  if (!res.failed.empty()) online.add_str("failed", res.failed);
  json::Object check;
  check.add("tolerance_deg", tol_deg).add("worst_estimated_error_deg", res.failed.empty() ? json::num(res.worst_check_deg) : "null");
  if (res.worst_report >= 0) {
    const StateRecord& w = res.reports[static_cast<std::size_t>(res.worst_report)].record;
    check.add("worst_trial", static_cast<double>(w.trial)).add("worst_time_s", w.time_s).add("worst_pressure_kPa", w.pressure_Pa * 1e-3);
  }
  check.add_str("per_report", "reduced_check.csv");
  std::string enrichments = "[";
  for (std::size_t k = 0; k < res.enrichments.size(); ++k) {
    const ReducedRunResult::Enrichment& e = res.enrichments[k];
    json::Object j;
    j.add_str("why", e.why).add("corrected_states", static_cast<double>(e.snapshots)).add("modes", static_cast<double>(e.modes)).add("basis_s", e.basis_s);
    if (!e.failed.empty()) j.add_str("run_failed", e.failed);
    enrichments += (k ? ", " : "") + j.str(6);
  }
  enrichments += "]";
  json::Object o;
  o.add("offline", offline.str(4))
      .add("enrichments", enrichments)
      .add("online", online.str(4))
      .add("check", check.str(4))
      .add_str("fallback", fallback);
  return o.str(2);
}

/// A fresh run starts over: an earlier run's checkpoint goes before this run's scene.toml
/// replaces that run's, so no later --resume can pair them.
void start_fresh_run(const fs::path& dir, const RunOptions& opt, const Scene& scene, BuiltModel& bm) {
  if (fs::exists(dir / "checkpoint.bin")) {
    fs::remove(dir / "checkpoint.bin");
    const std::string note = "removed checkpoint.bin of an earlier run in " + opt.out_dir +
                             " (a fresh run starts over; simulate --resume DIR continues a killed run)";
    std::fprintf(stderr, "note: %s\n", note.c_str());
    bm.warnings.push_back(note);
  }
  write_file_atomic((dir / "scene.toml").string(), scene.to_toml());
}

/// The ideal elastic model (effects off, one trial) of the paper's metrics, and where it came from.
struct IdealModel {
  std::vector<StateRecord> records;  ///< empty when not run
  std::string source = "computed";
};

/// The ideal model of a quasi-static staircase with effects (else none): read back from a resumed
/// run, computed (by the reduced model when `rsetup` is given) or taken from the ideal cache; written
/// to ideal_angles.csv.
IdealModel ideal_model(const Scene& scene, const RunOptions& opt, const fs::path& dir, BuiltModel& bm,
                       const ReducedSetup* rsetup) {
  IdealModel ideal;
  const bool reduced = rsetup != nullptr;
  bool any_effect = false;
  const std::vector<std::string> ideal_sets = ideal_overrides(scene, any_effect);
  const bool staircase = load_settings(scene).protocol == LoadSettings::Protocol::Staircase;
  if (!(opt.compare_ideal && any_effect && staircase && bm.solver.mode == SolverSettings::Mode::QuasiStatic)) return ideal;
  if (opt.resume && fs::exists(dir / "ideal_angles.csv")) {
    ideal.records = read_angles_csv((dir / "ideal_angles.csv").string());
    ideal.source = "ideal_angles.csv of the resumed run";
    return ideal;
  }
  std::vector<std::string> sets = ideal_sets;
  sets.push_back("load.trials=1");
  const Scene ideal_scene = scene.with(sets);
  auto compute = [&] {
    if (opt.progress) std::fprintf(stderr, "  ideal elastic model (effects off) ...\n");
    if (!reduced) return records_of(ideal_scene);
    std::vector<StateRecord> recs;
    for (const ReducedReport& r : run_reduced(*rsetup, *build_model(ideal_scene), nullptr, false).reports) recs.push_back(r.record);
    return recs;
  };
  if (opt.ideal_cache_dir.empty()) {
    ideal.records = compute();
    if (reduced) ideal.source = "computed by the reduced model";
  } else if (reduced) {
    ideal.records = compute();  // seconds; the ideal cache holds full-FEM results only
    ideal.source = "computed by the reduced model";
  } else {
    IdealResult r = cached_ideal(opt.ideal_cache_dir, ideal_cache_key(ideal_scene, bm.model, version_string()),
                                 ideal_scene, bm.load.trials[0].output_s, compute, bm.warnings);
    ideal.records = std::move(r.records);
    ideal.source = r.source;
  }
  write_file_atomic((dir / "ideal_angles.csv").string(), angles_csv(ideal.records, true));
  return ideal;
}

/// What a run keeps as it goes: the reports, the VTU files and their .pvd series (the solvers'
/// observer), and the checkpoints (their sink); on --resume, read back from the checkpoint.
class RunRecorder {
 public:
  RunRecorder(const fs::path& dir, const BuiltModel& bm, const Assembler& asmb, const RunOptions& opt,
              const RunIdentity& identity, ProgressLine& progress, const std::string& resume_body)
      : dir_(dir), bm_(bm), asmb_(asmb), opt_(opt), identity_(identity), progress_(progress),
        want_vtu_(bm.output.vtu != "none"),
        pvd_((dir / "results.pvd").string()) {
    if (want_vtu_) fs::create_directories(dir / "vtu");
    if (opt.resume) {
      std::istringstream in(resume_body, std::ios::binary);
      resume_from_ = std::make_unique<QuasiStaticCheckpoint>(
          QuasiStaticCheckpoint::read(in, static_cast<std::size_t>(asmb.num_dofs()), asmb.state_size()));
      app_ = read_app_section(in);
      for (const auto& [t, f] : app_.vtu) pvd_.add(t, f);
    }
    last_ckpt_ = std::chrono::steady_clock::now();
  }

  std::vector<StateRecord>& records() { return app_.records; }
  /// The solver state to resume from (null for a fresh run).
  const QuasiStaticCheckpoint* resume_from() const { return resume_from_.get(); }

  QuasiStaticRun::Observer observer() {
    return [this](const StateRecord& r, const Eigen::VectorXd& u, const std::vector<double>& state) { observe(r, u, state); };
  }
  QuasiStaticRun::CheckpointSink sink() {
    return [this](const QuasiStaticCheckpoint& c) { checkpoint(c); };
  }

  /// Drops the reports and VTU files so far (another model's run replaces them).
  void restart() {
    app_.records.clear();
    app_.vtu.clear();
    pvd_ = PvdSeries((dir_ / "results.pvd").string());
  }

 private:
  bool is_step_end(const StateRecord& r) const {
    const TrialLoad& tl = bm_.load.trials[r.trial - 1];
    for (double e : tl.step_end_s)
      if (std::abs(e - r.time_s) < 1e-9) return true;
    return tl.step_end_s.empty();
  }

  void observe(const StateRecord& r, const Eigen::VectorXd& u, const std::vector<double>& state) {
    app_.records.push_back(r);
    // A trial skipped by a cycle jump has no fields, only its extrapolated angles.
    if (want_vtu_ && !r.extrapolated && (bm_.output.vtu == "all" || is_step_end(r))) {
      char name[64];
      std::snprintf(name, sizeof name, "vtu/state_%04zu.vtu", app_.vtu.size());
      write_vtu((dir_ / name).string(), bm_.model, compute_fields(asmb_, u, state), r.global_time_s, r.trial,
                r.pressure_Pa * 1e-3, r.angle_deg);
      pvd_.add(r.global_time_s, name);
      app_.vtu.emplace_back(r.global_time_s, name);
    }
    progress_.update(r);
  }

  void checkpoint(const QuasiStaticCheckpoint& c) {
    const double since = std::chrono::duration<double>(std::chrono::steady_clock::now() - last_ckpt_).count();
    if (since < opt_.checkpoint_every_s) return;
    std::ostringstream os(std::ios::binary);
    c.write(os);
    write_app_section(os, app_);
    write_file_atomic((dir_ / "checkpoint.bin").string(), checkpoint_file_text(identity_, os.str()));
    write_file_atomic((dir_ / "angles.csv").string(), angles_csv(app_.records));
    last_ckpt_ = std::chrono::steady_clock::now();
    if (opt_.abort_after_checkpoints >= 0 && ++checkpoints_ >= opt_.abort_after_checkpoints) std::_Exit(137);
  }

  const fs::path& dir_;
  const BuiltModel& bm_;
  const Assembler& asmb_;
  const RunOptions& opt_;
  const RunIdentity& identity_;
  ProgressLine& progress_;
  const bool want_vtu_;
  PvdSeries pvd_;
  AppCheckpoint app_;
  std::unique_ptr<QuasiStaticCheckpoint> resume_from_;
  int checkpoints_ = 0;
  std::chrono::steady_clock::time_point last_ckpt_;
};

/// solver.model = "reduced": runs the reduced model and checks it (reduced_check.csv). When the
/// check fails, or the reduced run stops part-way (ReducedRunFailed), the run falls back to the full FEM: its reports are dropped and true returned; else
/// the solver statistics go to `solver_stats`. `reduced_json` gets summary.json's reduced_model part.
bool run_reduced_model(const ReducedSetup& setup, BuiltModel& bm, RunRecorder& rec, ProgressLine& progress,
                       const RunOptions& opt, const fs::path& dir, json::Object& solver_stats, std::string& reduced_json) {
  const double tol = bm.solver.reduced_check_deg;
  ReducedRunResult rr;
  try {
    rr = run_reduced(setup, bm, rec.observer(), true, [&](const ReducedRunResult::Enrichment& e) {
      progress.message("  reduced model: " + e.why + "; the basis takes the " + std::to_string(e.snapshots) +
                       " corrected states (" + std::to_string(e.modes) + " modes) and runs again");
      rec.restart();  // the next run's reports and VTU files replace these
    });
  } catch (const ReducedRunFailed& e) {
    // The FEM, not the reduction, judges whether the actuator can follow the load (as the
    // recording drive does): fall back, and keep what the reduced run did in summary.json.
    rr.failed = e.what();
    rr.stats = e.stats;
    rr.modes = e.modes;
  }
  std::string fallback = "none";
  bool full = true;
  if (const std::string why = rr.failed.empty() ? reduced_check_failure(rr, tol) : "the reduced model failed: " + rr.failed;
      !why.empty()) {
    fallback = "full FEM: " + why;
    bm.warnings.push_back(fallback);
    progress.message("  " + fallback);
    rec.restart();  // the FEM's reports and VTU files replace the reduced ones
  } else {
    full = false;
    solver_stats.add_str("mode", "quasi_static")
        .add_str("model", "reduced")
        .add("states", static_cast<double>(rr.stats.states))
        .add("rejected_time_steps", static_cast<double>(rr.stats.rejected_steps))
        .add("newton_iterations", static_cast<double>(rr.stats.newton_iterations));
  }
  write_file_atomic((dir / "reduced_check.csv").string(), reduced_check_csv(rr.reports));
  reduced_json = reduced_summary(setup, rr, tol, fallback);
  return full;
}

void full_fem_stats(const QuasiStaticRun& run, const BuiltModel& bm, const RunOptions& opt,
                    json::Object& solver_stats);

/// The quasi-static march of the full FEM (from the checkpoint on --resume); its statistics to
/// `solver_stats`, also when it fails.
void run_full_fem(const Assembler& asmb, const BuiltModel& bm, RunRecorder& rec, const RunOptions& opt,
                  json::Object& solver_stats) {
  QuasiStaticRun run(asmb, bm.solver.quasi_static);
  try {
    run.run(bm.load, rec.observer(), rec.sink(), rec.resume_from());
  } catch (...) {
    full_fem_stats(run, bm, opt, solver_stats);  // a failed run's summary keeps what ran
    throw;
  }
  full_fem_stats(run, bm, opt, solver_stats);
}

/// The statistics of a full-FEM run (finished or failed) into `solver_stats`.
void full_fem_stats(const QuasiStaticRun& run, const BuiltModel& bm, const RunOptions& opt,
                    json::Object& solver_stats) {
  const StaticStats& st = run.static_solver().stats();
  solver_stats.add_str("mode", "quasi_static")
      .add_str("model", "full")
      .add_str("method", bm.solver.quasi_static.method == EquilibriumMethod::Newton ? "newton" : "relaxation")
      .add("states", static_cast<double>(run.stats().states))
      .add("rejected_time_steps", static_cast<double>(run.stats().rejected_steps))
      .add("increments", static_cast<double>(st.increments))
      .add("cutbacks", static_cast<double>(st.cutbacks))
      .add("newton_iterations", static_cast<double>(st.iterations))
      .add("chord_steps", static_cast<double>(st.chord_steps))
      .add("factorizations", static_cast<double>(st.factorizations))
      .add("krylov_iterations", static_cast<double>(st.krylov_iterations))
      .add("stiff_layer_relaxations", static_cast<double>(st.stiff_relaxations))
      .add("stiff_layer_factorizations", static_cast<double>(st.stiff_factorizations))
      .add("last_factor_steps", static_cast<double>(st.last_factor_steps))
      .add("energy_line_search_cuts", static_cast<double>(st.energy_cuts))
      .add("release_attempts", static_cast<double>(st.release_attempts))
      .add("direct_releases", static_cast<double>(st.direct_releases))
      .add("residual_evaluations", static_cast<double>(st.residual_evaluations))
      .add("relaxation_iterations", static_cast<double>(run.stats().relaxation_iterations))
      .add("assembly_s", st.assembly_s)
      .add("factor_solve_s", st.factor_s)
      .add("resumed", opt.resume ? 1.0 : 0.0);
  if (bm.solver.quasi_static.cycle_jump.on)
    solver_stats.add("cycle_jumps", static_cast<double>(run.stats().cycle_jumps))
        .add("trials_extrapolated", static_cast<double>(run.stats().trials_extrapolated));
}

/// Explicit dynamics through the concatenated trials; time_scale > 1 compresses the protocol
/// (quasi-static by time scaling) and the reported times are protocol times. Selective mass scaling
/// (solver.target_dt_s) is reported (console, summary.json), warned about above
/// kAddedMassWarnFraction of the model's mass, and refused where it changes the answer: at a report
/// where the added mass takes more than kAddedMassForceShare of the loads
/// (ExplicitIntegrator::added_mass_force_share says why that measures the answer's error), unless
/// solver.force_mass_scaling. The statistics go to `solver_stats` also when the run fails.
constexpr double kAddedMassWarnFraction = 0.05;
constexpr double kAddedMassForceShare = 0.02;

/// The added mass of selective mass scaling through an explicit run: reported (console, and a
/// warning into the summary the first time it passes kAddedMassWarnFraction of the model's mass),
/// its largest share of the loads at a report tracked, and the run refused where that share
/// passes kAddedMassForceShare (unless solver.force_mass_scaling).
struct AddedMassMonitor {
  double target_dt = 0.0;       ///< solver.target_dt_s (0: no scaling, nothing reported)
  bool warned = false;          ///< the warning was given
  double max_share = 0.0;       ///< largest share of the loads taken by the added mass at a report
  double max_share_t = 0.0;     ///< its protocol time

  /// The added mass so far ("adds", "has added", "added"), printed when `print`; the warning the
  /// first time it passes the limit.
  void report(const ExplicitIntegrator& ex, const char* when, bool print, std::vector<std::string>& warnings) {
    const double added = ex.stats().added_mass_kg, phys = ex.stats().physical_mass_kg;
    if (target_dt <= 0.0 || phys <= 0.0) return;
    char line[400];
    std::snprintf(line, sizeof line,
                  added >= phys ? "explicit: selective mass scaling (solver.target_dt_s = %g s) %s %.4g kg to the model's "
                                  "%.4g kg (%.4g times it)"
                                : "explicit: selective mass scaling (solver.target_dt_s = %g s) %s %.4g kg to the model's "
                                  "%.4g kg (%.4g %% of it)",
                  target_dt, when, added, phys, added >= phys ? added / phys : 100.0 * added / phys);
    if (print) std::fprintf(stderr, "%s\n", line);
    if (!warned && added > kAddedMassWarnFraction * phys) {
      warned = true;
      const std::string w = std::string(line) + ", more than " + json::num(100.0 * kAddedMassWarnFraction) +
                            " %: the run is refused where that mass takes more than " +
                            json::num(100.0 * kAddedMassForceShare) +
                            " % of the loads (it would change the answer) unless solver.force_mass_scaling = true; "
                            "a smaller solver.target_dt_s adds less";
      std::fprintf(stderr, "warning: %s\n", w.c_str());
      warnings.push_back(w);
    }
  }

  /// At report `r`: the added mass's share of the loads, tracked, and an InputError above the limit.
  void check(const ExplicitIntegrator& ex, const StateRecord& r, bool force_mass_scaling) {
    const double share = ex.added_mass_force_share();
    if (share > max_share) {
      max_share = share;
      max_share_t = r.global_time_s;
    }
    if (share > kAddedMassForceShare && !force_mass_scaling) {
      char m[900];
      std::snprintf(m, sizeof m,
                    "solver.target_dt_s = %g: selective mass scaling added %.4g kg to the model's %.4g kg (%.4g times "
                    "it), and at trial %d, t = %g s (%.4g kPa) that mass takes %.3g %% of the loads (limit %.3g %%): "
                    "the angles would be those of a heavier actuator, not of this one. Lower solver.target_dt_s (0 = "
                    "no scaling), or set solver.time_scale lower so the load is slower, or use solver.mode = "
                    "\"quasi_static\"; solver.force_mass_scaling = true runs it anyway",
                    target_dt, ex.stats().added_mass_kg, ex.stats().physical_mass_kg,
                    ex.stats().added_mass_kg / ex.stats().physical_mass_kg, r.trial, r.time_s, r.pressure_Pa * 1e-3,
                    100.0 * share, 100.0 * kAddedMassForceShare);
      throw InputError(m);
    }
  }
};

/// The statistics of an explicit run (finished or failed) into `solver_stats`.
void explicit_stats(const ExplicitIntegrator& ex, const BuiltModel& bm, const AddedMassMonitor& mass,
                    json::Object& solver_stats) {
  solver_stats.add_str("mode", "explicit")
      .add("steps", static_cast<double>(ex.stats().steps))
      .add("dt_s", ex.stats().dt_s)
      .add("dt_min_s", ex.stats().dt_min_s)
      .add("time_scale", bm.solver.time_scale)
      .add("physical_mass_kg", ex.stats().physical_mass_kg)
      .add("added_mass_kg", ex.stats().added_mass_kg)
      .add("added_mass_fraction", ex.stats().added_mass_kg / ex.stats().physical_mass_kg)
      .add("added_mass_max_force_share", mass.max_share)
      .add("added_mass_max_force_share_time_s", mass.max_share_t)
      .add("mass_scaling_forced", bm.solver.force_mass_scaling ? "true" : "false")
      .add("stability_estimates", static_cast<double>(ex.stats().stability_estimates))
      .add("energy_kinetic_J", ex.energy().kinetic_J)
      .add("energy_internal_J", ex.energy().internal_J)
      .add("energy_external_work_J", ex.energy().external_work_J)
      .add("energy_damping_J", ex.energy().damping_J)
      .add("energy_balance_relative_error", ex.energy().relative_error());
}

void run_explicit(const Assembler& asmb, BuiltModel& bm, RunRecorder& rec, const RunOptions& opt,
                  json::Object& solver_stats) {
  if (opt.resume) throw InputError("--resume: explicit-mode runs have no checkpoints; start the run again");
  const QuasiStaticRun::Observer observe = rec.observer();
  const int ntrials = static_cast<int>(bm.load.trials.size());
  ExplicitIntegrator ex(asmb, bm.solver.explicit_dynamics);
  const double ts = bm.solver.time_scale;
  AddedMassMonitor mass;
  mass.target_dt = bm.solver.explicit_dynamics.target_dt_s;
  try {
    if (mass.target_dt > 0.0) {
      (void)ex.estimate_stable_dt();  // the mass added at the start, reported before the work
      mass.report(ex, "adds", true, bm.warnings);
    }
    double t0_protocol = 0.0, last_angle = 0.0;
    for (int k = 0; k < ntrials; ++k) {
      const TrialLoad& tl = bm.load.trials[k];
      const double trial_start = t0_protocol;
      auto pressure = [&](double tau) { return tl.pressure(tau * ts - trial_start); };
      for (double t_out : tl.output_s) {
        ex.run((trial_start + t_out) / ts, pressure, 1 << 30, nullptr);
        StateRecord r;
        r.trial = k + 1;
        r.time_s = t_out;
        r.global_time_s = trial_start + t_out;
        r.pressure_Pa = tl.pressure(t_out);
        const AngleResult a = bending_angle(bm.model, ex.u());
        r.angle_deg = unwrap_deg(a.angle_deg, last_angle);
        last_angle = r.angle_deg;
        r.plane_rms_m = a.plane_rms_m;
        r.cavity_volume_m3 = asmb.cavity_volume(ex.u());
        if (!mass.warned) mass.report(ex, "has added", false, bm.warnings);
        mass.check(ex, r, bm.solver.force_mass_scaling);
        observe(r, ex.u(), ex.state());
      }
      t0_protocol += tl.duration() + bm.load.rest_between_trials_s;
    }
  } catch (...) {
    explicit_stats(ex, bm, mass, solver_stats);
    throw;
  }
  mass.report(ex, "added", true, bm.warnings);
  explicit_stats(ex, bm, mass, solver_stats);
}

/// metrics.json (the paper's metrics of every trial against the ideal model); its summary.json
/// entry ("null" when there is no ideal model).
std::string write_metrics(const fs::path& dir, const BuiltModel& bm, const std::vector<StateRecord>& ideal,
                          const std::vector<StateRecord>& records) {
  const int ntrials = static_cast<int>(bm.load.trials.size());
  const StepAngles ref = step_angles(bm.load.trials[0], 1, ideal);
  std::vector<TrialMetrics> per_trial;
  for (int k = 0; k < ntrials; ++k) {
    per_trial.push_back(paper_metrics(step_angles(bm.load.trials[k], k + 1, records), ref));
    per_trial.back().extrapolated = std::any_of(records.begin(), records.end(),
                                                [&](const StateRecord& r) { return r.trial == k + 1 && r.extrapolated; });
  }
  write_file_atomic((dir / "metrics.json").string(), metrics_json(per_trial, ref.level_kPa));
  return json::quote("metrics.json");
}

}  // namespace

std::string top_angles_text(const std::vector<StateRecord>& records) {
  double p_top = -1.0;
  for (const StateRecord& r : records) p_top = std::max(p_top, r.pressure_Pa);
  if (records.empty()) return "";
  std::vector<const StateRecord*> last;  // per trial, its last report at p_top
  for (const StateRecord& r : records) {
    if (r.pressure_Pa != p_top) continue;
    if (!last.empty() && last.back()->trial == r.trial) last.back() = &r;
    else last.push_back(&r);
  }
  char b[96];
  std::snprintf(b, sizeof b, "angle at the top pressure, %.1f kPa (the last report there):", p_top * 1e-3);
  std::string s = b;
  bool any_extrapolated = false;
  for (std::size_t i = 0; i < last.size(); ++i) {
    std::snprintf(b, sizeof b, "%s trial %d %.2f deg%s", i ? "," : "", last[i]->trial, last[i]->angle_deg,
                  last[i]->extrapolated ? "*" : "");
    s += b;
    any_extrapolated = any_extrapolated || last[i]->extrapolated;
  }
  if (any_extrapolated) s += " (* extrapolated by a cycle jump)";
  return s + "\n";
}

RunResult run_simulation(const Scene& scene_arg, const RunOptions& opt) {
  const auto wall0 = std::chrono::steady_clock::now();
  const int threads = opt.threads > 0 ? opt.threads : tbb::info::default_concurrency();
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, threads);
  const fs::path dir(opt.out_dir);
  if (opt.resume) require_checkpoint(dir, opt.out_dir);
  const Scene scene = opt.resume ? Scene::load((dir / "scene.toml").string()) : scene_arg;
  prepare_output_dir(opt.out_dir, "--out");  // before the model is built: a bad --out fails now

  const auto t_build = std::chrono::steady_clock::now();
  std::unique_ptr<BuiltModel> bm = build_model(scene);
  for (const std::string& n : scene.notes()) std::fprintf(stderr, "note: %s\n", n.c_str());  // a deck's materials
  const Assembler asmb(bm->model);
  const double build_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_build).count();
  if (!opt.resume) start_fresh_run(dir, opt, scene, *bm);
  const RunIdentity identity = run_identity(scene, bm->model, bm->load);
  const std::string resume_body =  // checked now, before any work
      opt.resume ? read_checkpoint_body(dir / "checkpoint.bin", identity, opt.out_dir) : std::string();

  const bool reduced = bm->solver.mode == SolverSettings::Mode::QuasiStatic && bm->solver.model == SolverSettings::Model::Reduced;
  if (reduced && opt.resume) throw InputError("--resume: reduced-model runs have no checkpoints; start the run again");
  std::unique_ptr<ReducedSetup> rsetup;
  if (reduced) {
    if (opt.progress) std::fprintf(stderr, "  reduced model: elastic path and basis ...\n");
    rsetup = reduced_setup(scene, peak_pressure(bm->load), bm->solver.reduced, opt.cache_dir);
  }

  RunResult result;
  ProgressLine progress(opt, bm->load);
  std::exception_ptr failure;
  const IdealModel ideal = ideal_model(scene, opt, dir, *bm, rsetup.get());
  RunRecorder recorder(dir, *bm, asmb, opt, identity, progress, resume_body);

  const auto t_solve = std::chrono::steady_clock::now();
  json::Object solver_stats;
  std::string reduced_json = "null";
  try {
    bool full = bm->solver.mode == SolverSettings::Mode::QuasiStatic;
    if (reduced) full = run_reduced_model(*rsetup, *bm, recorder, progress, opt, dir, solver_stats, reduced_json);
    if (full)
      run_full_fem(asmb, *bm, recorder, opt, solver_stats);
    else if (bm->solver.mode == SolverSettings::Mode::Explicit)
      run_explicit(asmb, *bm, recorder, opt, solver_stats);
  } catch (const std::exception& e) {
    result.status = e.what();
    failure = std::current_exception();
  }
  progress.done();
  const double solve_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_solve).count();
  result.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();
  const std::vector<StateRecord>& records = recorder.records();
  result.records = records;

  write_file_atomic((dir / "angles.csv").string(), angles_csv(records));
  write_file_atomic((dir / "states.csv").string(), states_csv(records));
  const std::string metrics_note = !ideal.records.empty() && !failure ? write_metrics(dir, *bm, ideal.records, records) : "null";
  std::string warnings = "[";
  for (std::size_t i = 0; i < bm->warnings.size(); ++i) warnings += (i ? ", " : "") + json::quote(bm->warnings[i]);
  warnings += "]";
  json::Object timings;
  timings.add("build_s", build_s).add("solve_s", solve_s).add("total_s", result.wall_s);
  json::Object summary;
  summary.add_str("pneufem_version", version_string())
      .add_str("status", result.status)
      .add_str("command_line", opt.command_line)
      .add("threads", static_cast<double>(threads))
      .add_str("load", bm->load.description)
      .add("mesh", mesh_stats_json(bm->stats))
      .add("solver", solver_stats.str(2))
      .add("reduced_model", reduced_json)
      .add("timings", timings.str(2))
      .add("warnings", warnings)
      .add("metrics", metrics_note)
      .add_str("ideal_model", ideal.records.empty() ? "none" : ideal.source)
      .add("states_reported", static_cast<double>(records.size()))
      .add("scene", scene.to_json());
  write_file_atomic((dir / "summary.json").string(), summary.str() + "\n");
  result.warnings = bm->warnings;
  if (failure) std::rethrow_exception(failure);
  return result;
}

}  // namespace pneufem
