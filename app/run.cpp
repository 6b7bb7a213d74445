#include "app/run.h"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>

#include <tbb/global_control.h>
#include <tbb/info.h>

#include "app/json.h"
#include "app/version.h"
#include "engine/angle.h"
#include "engine/assembly.h"
#include "engine/explicit.h"
#include "materials/errors.h"
#include "scenes/build_model.h"
#include "viz/vtk_output.h"

namespace pneufem {

namespace fs = std::filesystem;

std::string version_string() { return std::string(PNEUFEM_VERSION) + " (" + PNEUFEM_GIT + ")"; }

void write_file_atomic(const std::string& path, const std::string& text) {
  const std::string tmp = path + ".tmp";
  {
    std::ofstream out(tmp, std::ios::binary);
    if (!out) throw std::runtime_error("cannot write '" + tmp + "': check that the directory exists and is writable");
    out << text;
    out.flush();
    if (!out) {
      std::error_code ec;
      fs::remove(tmp, ec);
      throw std::runtime_error("failed writing '" + path + "' (disk full?)");
    }
  }
  std::error_code ec;
  fs::rename(tmp, path, ec);
  if (ec) {
    fs::remove(tmp, ec);
    throw std::runtime_error("cannot move '" + tmp + "' to '" + path + "': " + ec.message());
  }
}

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

class ProgressLine {
 public:
  explicit ProgressLine(bool on) : on_(on) {}
  void update(const StateRecord& r, int trials) {
    if (!on_) return;
    std::fprintf(stderr, "\r  trial %d/%d  t = %7.2f s  p = %6.2f kPa  angle = %8.2f deg   ", r.trial, trials, r.time_s,
                 r.pressure_Pa * 1e-3, r.angle_deg);
    std::fflush(stderr);
  }
  void done() {
    if (on_) std::fprintf(stderr, "\n");
  }

 private:
  bool on_;
};

}  // namespace

RunResult run_simulation(const Scene& scene, const RunOptions& opt) {
  const auto wall0 = std::chrono::steady_clock::now();
  const int threads = opt.threads > 0 ? opt.threads : tbb::info::default_concurrency();
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, threads);
  fs::create_directories(opt.out_dir);
  if (!fs::is_directory(opt.out_dir)) throw InputError("--out " + opt.out_dir + ": cannot create the directory");

  const auto t_build = std::chrono::steady_clock::now();
  std::unique_ptr<BuiltModel> bm = build_model(scene);
  const Assembler asmb(bm->model);
  const double build_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_build).count();
  write_file_atomic((fs::path(opt.out_dir) / "scene.toml").string(), scene.to_toml());

  RunResult result;
  std::ostringstream angles, states;
  angles << "trial,time_s,pressure_kPa,angle_deg\n";
  states << "trial,time_s,global_time_s,pressure_kPa,angle_deg,cavity_volume_mm3,tip_plane_rms_mm\n";
  const bool want_vtu = bm->output.vtu != "none";
  if (want_vtu) fs::create_directories(fs::path(opt.out_dir) / "vtu");
  PvdSeries pvd((fs::path(opt.out_dir) / "results.pvd").string());
  int vtu_count = 0;
  ProgressLine progress(opt.progress);
  const int ntrials = static_cast<int>(bm->load.trials.size());

  auto is_step_end = [&](const StateRecord& r) {
    const TrialLoad& tl = bm->load.trials[r.trial - 1];
    for (double e : tl.step_end_s)
      if (std::abs(e - r.time_s) < 1e-9) return true;
    return tl.step_end_s.empty();
  };
  auto observe = [&](const StateRecord& r, const Eigen::VectorXd& u, const std::vector<double>& state) {
    result.records.push_back(r);
    char line[256];
    std::snprintf(line, sizeof line, "%d,%.6f,%.6f,%.6f\n", r.trial, r.time_s, r.pressure_Pa * 1e-3, r.angle_deg);
    angles << line;
    std::snprintf(line, sizeof line, "%d,%.6f,%.6f,%.6f,%.6f,%.6f,%.6g\n", r.trial, r.time_s, r.global_time_s,
                  r.pressure_Pa * 1e-3, r.angle_deg, r.cavity_volume_m3 * 1e9, r.plane_rms_m * 1e3);
    states << line;
    if (want_vtu && (bm->output.vtu == "all" || is_step_end(r))) {
      char name[64];
      std::snprintf(name, sizeof name, "vtu/state_%04d.vtu", vtu_count++);
      write_vtu((fs::path(opt.out_dir) / name).string(), bm->model, compute_fields(asmb, u, state), r.global_time_s,
                r.trial, r.pressure_Pa * 1e-3, r.angle_deg);
      pvd.add(r.global_time_s, name);
    }
    progress.update(r, ntrials);
  };

  json::Object solver_stats;
  std::exception_ptr failure;
  const auto t_solve = std::chrono::steady_clock::now();
  try {
    if (bm->solver.mode == SolverSettings::Mode::QuasiStatic) {
      QuasiStaticRun run(asmb, bm->solver.quasi_static);
      try {
        run.run(bm->load, observe);
      } catch (...) {
        const StaticStats& st = run.static_solver().stats();
        solver_stats.add("increments", static_cast<double>(st.increments));
        throw;
      }
      const StaticStats& st = run.static_solver().stats();
      solver_stats.add_str("mode", "quasi_static")
          .add_str("method", bm->solver.quasi_static.method == EquilibriumMethod::Newton ? "newton" : "relaxation")
          .add("states", static_cast<double>(run.stats().states))
          .add("increments", static_cast<double>(st.increments))
          .add("cutbacks", static_cast<double>(st.cutbacks))
          .add("newton_iterations", static_cast<double>(st.iterations))
          .add("factorizations", static_cast<double>(st.factorizations))
          .add("krylov_iterations", static_cast<double>(st.krylov_iterations))
          .add("residual_evaluations", static_cast<double>(st.residual_evaluations))
          .add("relaxation_iterations", static_cast<double>(run.stats().relaxation_iterations))
          .add("assembly_s", st.assembly_s)
          .add("factor_solve_s", st.factor_s);
    } else {
      // Explicit dynamics through the concatenated trials; time_scale > 1 compresses the
      // protocol (quasi-static by time scaling) and the reported times are protocol times.
      ExplicitIntegrator ex(asmb, bm->solver.explicit_dynamics);
      const double ts = bm->solver.time_scale;
      double t0_protocol = 0.0;
      double last_angle = 0.0;
      for (int k = 0; k < ntrials; ++k) {
        const TrialLoad& tl = bm->load.trials[k];
        const double trial_start = t0_protocol;
        auto pressure = [&](double tau) { return tl.pressure(tau * ts - trial_start); };
        for (double t_out : tl.output_s) {
          ex.run((trial_start + t_out) / ts, pressure, 1 << 30, nullptr);
          StateRecord r;
          r.trial = k + 1;
          r.time_s = t_out;
          r.global_time_s = trial_start + t_out;
          r.pressure_Pa = tl.pressure(t_out);
          const AngleResult a = bending_angle(bm->model, ex.u());
          r.angle_deg = unwrap_deg(a.angle_deg, last_angle);
          last_angle = r.angle_deg;
          r.plane_rms_m = a.plane_rms_m;
          r.cavity_volume_m3 = asmb.cavity_volume(ex.u());
          observe(r, ex.u(), ex.state());
        }
        t0_protocol += tl.duration() + bm->load.rest_between_trials_s;
      }
      solver_stats.add_str("mode", "explicit")
          .add("steps", static_cast<double>(ex.stats().steps))
          .add("dt_s", ex.stats().dt_s)
          .add("dt_min_s", ex.stats().dt_min_s)
          .add("time_scale", ts)
          .add("physical_mass_kg", ex.stats().physical_mass_kg)
          .add("added_mass_kg", ex.stats().added_mass_kg)
          .add("added_mass_fraction", ex.stats().added_mass_kg / ex.stats().physical_mass_kg)
          .add("energy_kinetic_J", ex.energy().kinetic_J)
          .add("energy_internal_J", ex.energy().internal_J)
          .add("energy_external_work_J", ex.energy().external_work_J)
          .add("energy_damping_J", ex.energy().damping_J)
          .add("energy_balance_relative_error", ex.energy().relative_error());
    }
  } catch (const std::exception& e) {
    result.status = e.what();
    failure = std::current_exception();
  }
  progress.done();
  const double solve_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t_solve).count();
  result.wall_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall0).count();

  write_file_atomic((fs::path(opt.out_dir) / "angles.csv").string(), angles.str());
  write_file_atomic((fs::path(opt.out_dir) / "states.csv").string(), states.str());
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
      .add("timings", timings.str(2))
      .add("warnings", warnings)
      .add("states_reported", static_cast<double>(result.records.size()))
      .add("scene", scene.to_json());
  write_file_atomic((fs::path(opt.out_dir) / "summary.json").string(), summary.str() + "\n");
  if (failure) std::rethrow_exception(failure);
  return result;
}

}  // namespace pneufem
