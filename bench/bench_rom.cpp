// Reduced-order model benchmark (not run in CI; results in BENCHMARKS.md): the reduced model of
// engine/rom.h against the full quasi-static FEM on a scene's protocol.
//   bench_rom SCENE.toml [--set key=value ...] [--work DIR] [--fem] [--threads N]
//             [--model-set key=value ...] [--modes R] [--clusters C] [--mode-samples S] [--ecsw-tol T] [--ecsw-blocks N] [--no-hyper]
//             [--softened N] [--softened-max S] [--snap-trials N] [--snap-set key=value ...] [--check] [--corrected reports|tops] [--corrected-in-run reports|tops] [--dump-points]
//             [--dump-every] [--galerkin-theta] [--fabric-strain] [--rom-time-tol T] [--path-steps N]
//             [--root-test] [--root-trials N] [--exact-fabric | --sampled-fabric] [--release-modes]
//             [--enrich N] [--enrich-modes R] [--save-corrected FILE] [--extra-snapshots FILE]
// --softened N adds softened equilibria (N levels to --softened-max; 6 to 0.9 is the tested choice, off in the scenes' default,
// the bench's 0 so that A/B runs name what they add); --check replays the run and prints the
// adjoint and Newton-step indicators beside every report's error; --corrected reports|tops adds the
// corrected history's estimate (ReplayOptions), corrected at every loaded report or at the top
// level's reports only (as simulate's check); --dump-points runs the FEM beside
// the reduced model and compares damage and largest stretch at the kept points at every trial's end
// (--dump-every: also each region's viscous strain at every report);
// --galerkin-theta tests the theta row with the path tangent (RomBasisOptions::galerkin_theta_row);
// --fabric-strain prints, per report, the stiff parts' largest Green and small strain of the reduced
// state and of the FEM snapshot at the same report, and the reduced coordinates (theta, |q|, the
// gauge multiplier lambda).
// Prints the offline cost (elastic trace, basis), the online cost (states, Newton iterations,
// wall), and with --fem the FEM's record and the differences: every report angle, and the paper's
// NRMSE per trial against the ideal elastic model, for both. --work DIR keeps the elastic trace
// and the FEM record between invocations (keyed by the scene text), so basis options can be varied
// without re-running the FEM.
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <array>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <tbb/global_control.h>
#include <Eigen/Eigenvalues>
#include <Eigen/LU>
#include <tuple>

#include "analysis/paper_metrics.h"
#include "engine/angle.h"
#include "engine/assembly.h"
#include "engine/path_model.h"
#include "engine/quasi_static.h"
#include "engine/rom.h"
#include "engine/linear_solver.h"
#include "engine/static_solver.h"
#include "engine/tet_element.h"
#include "scenes/build_model.h"

using namespace pneufem;
using Clock = std::chrono::steady_clock;
namespace fs = std::filesystem;

namespace {

double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

std::uint64_t fnv(const std::string& s) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (unsigned char c : s) h = (h ^ c) * 0x100000001b3ULL;
  return h;
}

void write_doubles(const fs::path& p, const std::vector<double>& v) {
  std::ofstream f(p, std::ios::binary);
  const std::uint64_t n = v.size();
  f.write(reinterpret_cast<const char*>(&n), sizeof n);
  f.write(reinterpret_cast<const char*>(v.data()), static_cast<std::streamsize>(n * sizeof(double)));
}
bool read_doubles(const fs::path& p, std::vector<double>& v) {
  std::ifstream f(p, std::ios::binary);
  if (!f) return false;
  std::uint64_t n = 0;
  f.read(reinterpret_cast<char*>(&n), sizeof n);
  v.resize(n);
  f.read(reinterpret_cast<char*>(v.data()), static_cast<std::streamsize>(n * sizeof(double)));
  return static_cast<bool>(f);
}

struct Record {
  std::vector<int> trial;
  std::vector<double> t, p, angle;
};

/// Per trial: the paper's NRMSE of `a` against the ideal angles `ideal` (trial 1 of the ideal).
std::vector<double> nrmse_per_trial(const LoadHistory& load, const Record& a, const Record& ideal) {
  std::vector<double> out;
  auto steps = [&](const Record& r, int trial) {
    StepAngles s;
    s.trial = trial;
    const TrialLoad& tl = load.trials[static_cast<std::size_t>(trial - 1)];
    auto at = [&](double t) {
      for (std::size_t i = 0; i < r.t.size(); ++i)
        if (r.trial[i] == trial && std::abs(r.t[i] - t) < 1e-9) return r.angle[i];
      return std::nan("");
    };
    for (std::size_t k = 0; k < tl.step_start_s.size(); ++k) {
      s.level_kPa.push_back(tl.step_level_Pa[k] * 1e-3);
      s.at_mark_deg.push_back(at(tl.step_start_s[k] + tl.mark_s));
      s.at_end_deg.push_back(at(tl.step_end_s[k]));
    }
    return s;
  };
  const StepAngles ref = steps(ideal, 1);
  for (std::size_t k = 0; k < load.trials.size(); ++k) out.push_back(paper_metrics(steps(a, static_cast<int>(k) + 1), ref).nrmse);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  std::setvbuf(stdout, nullptr, _IOLBF, 0);
  std::string scene_path, work = "rom_work";
  std::vector<std::string> sets, model_sets, snap_sets;
  bool root_test = false;
  int root_trials = 1 << 30;
  bool fem = false, check = false, dump = false, dump_every = false, corrected = false, corrected_tops = false, fabric_strain = false;
  int snap_trials = 0, enrich = 0, enrich_modes = 0;
  double rom_time_tol = 0.0;
  int path_steps = 40;  // the elastic path's pressure step is p_max / path_steps (its samples' density)  // > 0: the reduced run's time_tol alone (the FEM judge keeps the scene's)
  std::string save_corrected, extra_snapshots, in_run;
  int threads = 0;
  RomBasisOptions ro;
  ro.verbose = true;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto next = [&] { return std::string(i + 1 < argc ? argv[++i] : ""); };
    if (a == "--set") sets.push_back(next());
    else if (a == "--model-set") model_sets.push_back(next());  // the run's model only, not the reference
    else if (a == "--work") work = next();
    else if (a == "--snap-trials") snap_trials = std::stoi(next());  // FEM snapshots of the first N trials enrich the basis
    else if (a == "--snap-set") snap_sets.push_back(next());          // the snapshot run's model (default: the run's)
    else if (a == "--fem") fem = true;
    else if (a == "--path-steps") path_steps = std::stoi(next());  // the path traced at p_max / N steps (default 40)
    else if (a == "--rom-time-tol") rom_time_tol = std::stod(next());  // the reduced run's time_tol only
    else if (a == "--save-corrected") save_corrected = next();   // the enrichment's corrected states, to a file
    else if (a == "--extra-snapshots") extra_snapshots = next(); // snapshots from such a file join the basis
    else if (a == "--enrich") enrich = std::stoi(next());
    else if (a == "--enrich-modes") enrich_modes = std::stoi(next());  // max_modes of the enriched bases (default: --modes)  // rounds: the corrected states join the basis, the run is repeated
    else if (a == "--check") check = true;
    else if (a == "--corrected") check = corrected = true, corrected_tops = next() == "tops";  // tops | reports
    else if (a == "--corrected-in-run") in_run = next();  // tops | reports: the corrected history fed back into the run
    else if (a == "--root-test") root_test = true;  // the FEM's loaded states with their history: roots of the reduced equations?
    else if (a == "--dump-points") dump = true;  // kept points, ROM vs FEM: damage, viscous strain and stretch at every trial's end
    else if (a == "--dump-every") dump = dump_every = true;  // as --dump-points, plus the per-region viscous strain at every report
    else if (a == "--fabric-strain") fabric_strain = true;  // largest Green strain of the stiff parts per report, ROM vs the snapshot
    else if (a == "--threads") threads = std::stoi(next());
    else if (a == "--modes") ro.max_modes = std::stoi(next());
    else if (a == "--clusters") ro.clusters = std::stoi(next());
    else if (a == "--mode-samples") ro.mode_samples = std::stoi(next());
    else if (a == "--ecsw-tol") ro.ecsw_tolerance = std::stod(next());
    else if (a == "--ecsw-blocks") ro.ecsw_blocks = std::stoi(next());
    else if (a == "--pod-tol") ro.pod_tolerance = std::stod(next());
    else if (a == "--no-hyper") ro.hyper_reduce = false;
    else if (a == "--galerkin-theta") ro.galerkin_theta_row = true;  // the theta row tested with the path tangent
    else if (a == "--tangent-free") ro.tangent_free_modes = true;  // modes orthogonal to every path tangent, no gauge
    else if (a == "--exact-fabric") ro.stiff_parts = RomBasisOptions::StiffParts::exact;  // every fabric element in the bracket (nonlinear in q)
    else if (a == "--sampled-fabric") ro.stiff_parts = RomBasisOptions::StiffParts::sampled;  // fabric elements by ECSW on their remainder
    else if (a == "--release-modes") ro.release_responses = true;  // responses of the unloaded body to the path's frozen stress
    else if (a == "--root-trials") root_trials = std::stoi(next());  // the root test stops after this trial
    else if (a == "--softened") ro.softened_levels = std::stoi(next());  // softened equilibria as snapshots (levels)
    else if (a == "--softened-max") ro.softened_max = std::stod(next());
    else if (a[0] != '-') scene_path = a;
    else {
      std::fprintf(stderr, "unknown option %s\n", a.c_str());
      return 2;
    }
  }
  if (!in_run.empty() && in_run != "tops" && in_run != "reports") {
    std::fprintf(stderr, "--corrected-in-run takes tops or reports, not '%s'\n", in_run.c_str());
    return 2;
  }
  std::unique_ptr<tbb::global_control> gc;
  if (threads > 0) gc = std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, threads);
  fs::create_directories(work);
  const Scene base = Scene::load(scene_path, sets);
  const Scene scene = base.with(model_sets);
  const Scene ref_scene = elastic_reference_scene(base).with({"load.trials=1"});
  auto bm = build_model(scene);
  auto ref = build_model(ref_scene);
  std::printf("model: %d nodes, %d elements, %d dof\n", bm->model.mesh.num_nodes(), bm->model.mesh.num_elements(),
              bm->model.num_dofs());
  double p_max = 0.0;
  for (const TrialLoad& tl : bm->load.trials)
    for (double p : tl.pressure_Pa) p_max = std::max(p_max, p);
  const std::string key = std::to_string(fnv(ref_scene.model_toml()));
  // The FEM judge's record file, named up front so that a record kept from an earlier build can be
  // linked to it when a new scene key changes the name but not the physics.
  std::printf("FEM record file: %s\n", (fs::path(work) / ("fem_" + std::to_string(fnv(scene.to_toml())) + ".csv")).c_str());

  // 1. Elastic path (cached).
  PathModelOptions po;
  po.p_top_Pa = 1.8 * p_max;
  po.dp_Pa = p_max / path_steps;
  po.newton = ref->solver.quasi_static.newton;
  ElasticPathTrace trace;
  {
    const fs::path f = fs::path(work) / ("trace_" + key + (path_steps == 40 ? "" : "_steps" + std::to_string(path_steps)) + ".bin");
    std::printf("elastic path file: %s\n", f.c_str());
    std::vector<double> d;
    const auto t0 = Clock::now();
    if (read_doubles(f, d)) {
      const std::size_t ns = static_cast<std::size_t>(d[0]), nd = static_cast<std::size_t>(ref->model.num_dofs());
      trace.p_Pa.assign(d.begin() + 1, d.begin() + 1 + static_cast<std::ptrdiff_t>(ns));
      for (std::size_t k = 0; k < ns; ++k)
        trace.u.push_back(Eigen::Map<const Eigen::VectorXd>(d.data() + 1 + ns + k * nd, static_cast<Eigen::Index>(nd)));
      std::printf("elastic path: %zu samples from %s\n", ns, f.c_str());
    } else {
      trace = trace_elastic_path(ref->model, po);
      d = {static_cast<double>(trace.p_Pa.size())};
      d.insert(d.end(), trace.p_Pa.begin(), trace.p_Pa.end());
      for (const auto& u : trace.u) d.insert(d.end(), u.data(), u.data() + u.size());
      write_doubles(f, d);
      std::printf("elastic path: %zu samples to %.2f kPa, traced in %.1f s\n", trace.p_Pa.size(), trace.p_Pa.back() * 1e-3,
                  since(t0));
    }
  }
  std::vector<Eigen::VectorXd> snapshots;
  if (snap_trials > 0) {
    const Scene snap_scene = scene.with(snap_sets).with({"load.trials=" + std::to_string(snap_trials)});
    auto sm = build_model(snap_scene);
    const auto t0 = Clock::now();
    // Cached in the work directory (keyed by the snapshot run's scene): an A/B of basis options
    // does not pay the FEM run again.
    const fs::path f = fs::path(work) / ("snapshots_" + std::to_string(fnv(snap_scene.model_toml())) + ".bin");
    std::printf("snapshots file: %s\n", f.c_str());
    std::vector<double> d;
    const long nd = sm->model.num_dofs();
    if (read_doubles(f, d) && d.size() % static_cast<std::size_t>(nd) == 0) {
      for (std::size_t k = 0; k < d.size() / static_cast<std::size_t>(nd); ++k)
        snapshots.push_back(Eigen::Map<const Eigen::VectorXd>(d.data() + k * nd, nd));
      std::printf("snapshots: %zu FEM reports from %s\n", snapshots.size(), f.c_str());
    } else {
      Assembler A(sm->model);
      QuasiStaticRun q(A, sm->solver.quasi_static);
      // The snapshot run's angles are also the FEM judge's record (step 4) of its own scene, so a
      // run with --fem --snap-trials N over N trials pays one FEM run, not two.
      const fs::path judge = fs::path(work) / ("fem_" + std::to_string(fnv(snap_scene.to_toml())) + ".csv");
      std::ostringstream rec;
      rec.precision(17);
      q.run(sm->load, [&](const StateRecord& r, const Eigen::VectorXd& u, const std::vector<double>&) {
        snapshots.push_back(u);
        rec << r.trial << " " << r.time_s << " " << r.pressure_Pa << " " << r.angle_deg << "\n";
      });
      if (!fs::exists(judge)) {
        std::ofstream(judge.string() + ".part") << rec.str();
        fs::rename(judge.string() + ".part", judge);
      }
      d.clear();
      for (const auto& u : snapshots) d.insert(d.end(), u.data(), u.data() + u.size());
      write_doubles(f, d);
      std::printf("snapshots: %zu FEM reports of %d trial(s) in %.1f s\n", snapshots.size(), snap_trials, since(t0));
    }
  }
  if (!extra_snapshots.empty()) {
    std::vector<double> d;
    const long nd = ref->model.num_dofs();
    if (!read_doubles(extra_snapshots, d) || d.size() % static_cast<std::size_t>(nd) != 0) {
      std::printf("cannot read snapshots from %s\n", extra_snapshots.c_str());
      return 1;
    }
    for (std::size_t k = 0; k < d.size() / static_cast<std::size_t>(nd); ++k)
      snapshots.push_back(Eigen::Map<const Eigen::VectorXd>(d.data() + k * nd, nd));
    std::printf("snapshots: %zu from %s\n", d.size() / static_cast<std::size_t>(nd), extra_snapshots.c_str());
  }
  const auto tb = Clock::now();
  // The basis is cached too (keyed by the reference, the options and the snapshot run), so that an
  // A/B of the online part does not pay the offline part again.
  const ReducedBasis basis = [&] {
    char opts[256];
    std::snprintf(opts, sizeof opts, "%d/%d/%d/%.6g/%.6g/%d/%d/%.6g/%d/%zu", ro.clusters, ro.mode_samples, ro.max_modes,
                  ro.pod_tolerance, ro.ecsw_tolerance, ro.hyper_reduce ? 1 : 0, ro.softened_levels, ro.softened_max, snap_trials,
                  snap_sets.size());
    std::string snap_key;
    for (const std::string& s : snap_sets) snap_key += s + ";";
    if (!extra_snapshots.empty()) snap_key += "extra:" + extra_snapshots;
    if (ro.galerkin_theta_row) snap_key += "galerkin-theta";
    if (ro.tangent_free_modes) snap_key += "tangent-free";
    if (ro.ecsw_blocks > 0) snap_key += "ecsw-blocks:" + std::to_string(ro.ecsw_blocks);
    if (ro.release_responses) snap_key += "release-modes-v2";  // v2: the whole body at every path sample, own POD
    if (ro.stiff_parts == RomBasisOptions::StiffParts::exact) snap_key += "exact-fabric";
    if (ro.stiff_parts == RomBasisOptions::StiffParts::sampled) snap_key += "sampled-fabric";
    if (path_steps != 40) snap_key += "path-steps:" + std::to_string(path_steps);  // the basis holds the path's operators
    const fs::path f = fs::path(work) / ("basis_" + std::to_string(fnv(ref_scene.model_toml() + opts + snap_key)) + ".bin");
    std::vector<double> d;
    if (read_doubles(f, d)) {
      try {
        ReducedBasis b = ReducedBasis::from_doubles(d);
        std::printf("basis: from %s\n", f.c_str());
        return b;
      } catch (const InputError& e) {
        std::printf("basis: %s: %s; rebuilt\n", f.c_str(), e.what());
      }
    }
    ReducedBasis b = build_reduced_basis(ref->model, trace, ro, snapshots);
    write_doubles(f, b.to_doubles());
    return b;
  }();
  std::printf("basis: %d modes, %zu sampled elements of %d soft (%d clusters), POD energy left %.2e, ECSW worst %.2e, %.1f s; path to %.2f deg\n",
              basis.num_modes(), basis.elements.size(), basis.info.soft_elements, basis.info.clusters, basis.info.pod_energy_left,
              basis.info.ecsw_worst_residual, since(tb), basis.theta.back());
  {  // the ECSW weights per region against the region's volume
    const ElementGeometry geom = compute_geometry(ref->model.mesh);
    std::map<int, double> vol, wvol;
    std::map<int, int> count;
    for (int e = 0; e < ref->model.mesh.num_elements(); ++e) vol[ref->model.mesh.region[e]] += geom.volume[e];
    for (std::size_t i = 0; i < basis.elements.size(); ++i) {
      const int e = basis.elements[i];
      wvol[ref->model.mesh.region[e]] += basis.weights[i] * geom.volume[e];
      ++count[ref->model.mesh.region[e]];
    }
    for (auto [r, v] : vol)
      std::printf("  region %-14s volume %.3e m3, weighted kept %.3e m3, %d elements\n", ref->model.mesh.region_names[r].c_str(), v,
                  wvol[r], count[r]);
  }
  // 3. Reduced runs: the ideal (reference) and the model.
  Record ideal, red;
  if (!root_test) {  // the root test needs no reduced run
    const ReducedOrderModel rom(ref->model, basis, ref->model);
    ReducedRun run(rom, ref->solver.quasi_static);
    run.run(ref->load, [&](const StateRecord& r, const ReducedCoordinates&, const Eigen::VectorXd&) {
      ideal.trial.push_back(r.trial);
      ideal.t.push_back(r.time_s);
      ideal.p.push_back(r.pressure_Pa);
      ideal.angle.push_back(r.angle_deg);
    });
  }
  const auto t_on = Clock::now();
  const ReducedOrderModel rom(ref->model, basis, bm->model);
  if (root_test) {
    // Are the FEM's states roots of the reduced equations when the kept points carry the FEM's own
    // history? At every loaded report of the FEM run (upper levels): project the state onto the
    // manifold (theta = its angle, q the mass-weighted least squares of the departure), give the kept
    // points the FEM's history, and solve the reduced equations with that history frozen (dt = 0).
    // The root's angle minus the FEM's is what the reduced equations alone make of the right history.
    Assembler A(bm->model);
    QuasiStaticRun q(A, bm->solver.quasi_static);
    const Eigen::VectorXd& mass = A.lumped_mass();
    const Eigen::MatrixXd& Phi = basis.Phi;
    const int r = basis.num_modes(), n = r + 2;
    Eigen::MatrixXd MPhi = Phi;
    for (Eigen::Index i = 0; i < MPhi.rows(); ++i) MPhi.row(i) *= mass[i / 3];
    const Eigen::MatrixXd G = Phi.transpose() * MPhi;
    const Eigen::LDLT<Eigen::MatrixXd> Gf(G);
    std::printf("root test (trial, t, p kPa, fem, projection - fem, root - fem, Newton its, RMS of the root's q in mm):\n");
    struct Stop {};
    try {
    q.run(bm->load, [&](const StateRecord& rec, const Eigen::VectorXd& u, const std::vector<double>& h) {
      if (rec.trial > root_trials) throw Stop{};
      if (rec.pressure_Pa < 0.6 * p_max) return;
      ReducedCoordinates z;
      z.theta = rec.angle_deg;
      z.q = Eigen::VectorXd::Zero(r);
      const Eigen::VectorXd du = u - rom.displacement(z);
      z.q = Gf.solve(MPhi.transpose() * du);
      const double a_proj = rom.angle_deg(z, rec.angle_deg);
      std::vector<double> kept, trial;
      rom.gather_history(A, h, kept);
      trial = kept;
      const TimeStep ts{rec.global_time_s, 0.0};
      int it = 0;
      bool ok = false;
      try {
        // Damped Newton: the step halved until the residual, rows scaled by the Jacobian's row norms,
        // falls (as ReducedRun::equilibrium), and at most 1 deg in theta.
        for (; it < 60; ++it) {
          Eigen::MatrixXd J;
          const Eigen::VectorXd R = rom.residual(z, rec.pressure_Pa, ts, kept, trial, &J);
          const Eigen::VectorXd scale = J.rowwise().norm().cwiseMax(1e-300).cwiseInverse();
          const Eigen::VectorXd dz = -J.partialPivLu().solve(R);
          if (!dz.allFinite()) break;
          if (std::abs(dz[0]) < 1e-7 && dz.segment(1, r).norm() < 1e-12) {
            ok = true;
            break;
          }
          const double f0 = R.cwiseProduct(scale).norm();
          double s = std::abs(dz[0]) > 1.0 ? 1.0 / std::abs(dz[0]) : 1.0;
          bool moved = false;
          for (int ls = 0; ls < 20 && !moved; ++ls, s *= 0.5) {
            ReducedCoordinates y = z;
            y.theta += s * dz[0];
            y.q += s * dz.segment(1, r);
            y.lambda += s * dz[n - 1];
            try {
              std::vector<double> tr = kept;
              if (rom.residual(y, rec.pressure_Pa, ts, kept, tr, nullptr).cwiseProduct(scale).norm() < f0) z = y, moved = true;
            } catch (const PhysicsError&) {
            }
          }
          if (!moved) break;
        }
      } catch (const std::exception& e) {
        std::printf("   (failed: %s)\n", e.what());
      }
      const double a_root = rom.angle_deg(z, rec.angle_deg);
      std::printf("  %2d %7.2f %6.2f %9.3f %+8.3f %+8.3f %3d%s %.3g\n", rec.trial, rec.time_s, rec.pressure_Pa * 1e-3, rec.angle_deg,
                  a_proj - rec.angle_deg, a_root - rec.angle_deg, it, ok ? "" : " NOT CONVERGED", 1e3 * std::sqrt(z.q.squaredNorm() / std::max(r, 1)));
    });
    } catch (const Stop&) {
      std::printf("root test: stopped after trial %d (--root-trials)\n", root_trials);
    }
    return 0;
  }
  QuasiStaticOptions rom_steps = bm->solver.quasi_static;
  if (rom_time_tol > 0.0) rom_steps.time_tol = rom_time_tol;
  ReducedRun run(rom, rom_steps);
  if (!in_run.empty()) {
    const double p_top = in_run == "tops" ? 0.99 * p_max : 0.0;
    run.set_history_corrector(corrected_history_in_run(
        rom, [p_top](const ReducedStep& s) { return s.report >= 0 && s.pressure_Pa > p_top; }, bm->solver.quasi_static.newton,
        [](const ReducedStep& s, bool ok) { std::printf("  in-run check at t %.2f s, %.1f kPa: %s\n", s.time_s, s.pressure_Pa * 1e-3, ok ? "corrected" : "NO EQUILIBRIUM"); }));
  }
  std::vector<Eigen::VectorXd> rom_u, strain_u;
  std::vector<double> strain_lambda, strain_q, strain_theta;
  std::vector<std::vector<double>> rom_h;
  try {
    run.run(bm->load, [&](const StateRecord& r, const ReducedCoordinates& z, const Eigen::VectorXd& u) {
      if (dump) rom_u.push_back(u), rom_h.push_back(rom.history_scalars(run.history()));
      if (fabric_strain) strain_u.push_back(u), strain_lambda.push_back(z.lambda), strain_q.push_back(z.q.norm()), strain_theta.push_back(z.theta);
      red.trial.push_back(r.trial);
      red.t.push_back(r.time_s);
      red.p.push_back(r.pressure_Pa);
      red.angle.push_back(r.angle_deg);
      (void)z;
    });
  } catch (const std::exception& e) {
    std::printf("reduced run failed: %s\n", e.what());
  }
  double qmax = 0.0;
  for (const ReducedStep& s : run.trajectory()) qmax = std::max(qmax, s.z.q.norm());
  std::printf("largest correction: RMS %.3g mm; path top RMS %.3g mm\n", qmax * 1e3,
              1e3 * basis.U.col(basis.num_samples() - 1).norm() / std::sqrt(basis.dofs() / 3.0));
  const ReducedRunStats& st = run.stats();
  std::printf("reduced run: %.2f s wall, %ld states (%ld rejected), %ld Newton its, %ld tangents (%ld iterations on a kept one), %ld residuals, %d points%s\n",
              since(t_on), st.states, st.rejected_steps, st.newton_iterations, st.tangents, st.reused_tangents, st.residuals, rom.num_points(),
              st.beyond_path ? ", BEYOND THE PATH" : "");
  // The a-posteriori indicators at every report: the adjoint-weighted residual and one full Newton step.
  std::vector<double> est_adj, est_newton, est_corr;
  if (check && enrich == 0) {
    const auto t0 = Clock::now();
    ReplayOptions replay_opt;
    replay_opt.newton_at = [](const ReducedStep& s) { return s.report >= 0 && s.pressure_Pa > 0.0; };
    if (corrected) replay_opt.corrected_at = replay_opt.newton_at;
    if (corrected_tops) replay_opt.corrected_at = [p_max](const ReducedStep& s) { return s.report >= 0 && s.pressure_Pa > 0.99 * p_max; };
    replay_opt.newton = bm->solver.quasi_static.newton;
    replay_reduced_run(
        rom, run.trajectory(),
        [&](const ReducedStep& s, const Eigen::VectorXd&, const std::vector<double>&, const ReducedCheck& c) {
          if (s.report < 0) return;
          const std::size_t i = static_cast<std::size_t>(s.report);
          if (est_adj.size() <= i)
            est_adj.resize(i + 1, std::nan("")), est_newton.resize(i + 1, std::nan("")), est_corr.resize(i + 1, std::nan(""));
          est_adj[i] = c.angle_error_deg;
          est_newton[i] = c.newton_angle_error_deg;
          est_corr[i] = c.corrected_angle_error_deg;
        },
        replay_opt);
    std::printf("replay with checks: %.1f s\n", since(t0));
  }
  // Enrichment rounds: the corrected states (full-model equilibria near the reduced ones, with the
  // history the full model would have built) join the snapshots; the basis is rebuilt and the run
  // repeated.
  std::vector<std::unique_ptr<ReducedBasis>> bases;
  std::vector<std::unique_ptr<ReducedOrderModel>> roms;
  std::vector<std::unique_ptr<ReducedRun>> runs;
  std::vector<Eigen::VectorXd> corrected_states;
  const ReducedOrderModel* rom_now = &rom;
  const ReducedRun* run_now = &run;
  for (int round = 0; round <= enrich && corrected; ++round) {
    if (round > 0) {
      std::vector<Eigen::VectorXd> snaps = snapshots;
      snaps.insert(snaps.end(), corrected_states.begin(), corrected_states.end());
      const auto t0 = Clock::now();
      RomBasisOptions ro_e = ro;
      if (enrich_modes > 0) ro_e.max_modes = enrich_modes;
      bases.push_back(std::make_unique<ReducedBasis>(build_reduced_basis(ref->model, trace, ro_e, snaps)));
      std::printf("enrich %d: %zu snapshots, %d modes, %zu sampled elements, basis %.1f s\n", round, snaps.size(),
                  bases.back()->num_modes(), bases.back()->elements.size(), since(t0));
      roms.push_back(std::make_unique<ReducedOrderModel>(ref->model, *bases.back(), bm->model));
      runs.push_back(std::make_unique<ReducedRun>(*roms.back(), bm->solver.quasi_static));
      rom_now = roms.back().get();
      run_now = runs.back().get();
      red = Record{};
      const auto t1 = Clock::now();
      try {
        runs.back()->run(bm->load, [&](const StateRecord& r, const ReducedCoordinates&, const Eigen::VectorXd&) {
          red.trial.push_back(r.trial), red.t.push_back(r.time_s), red.p.push_back(r.pressure_Pa), red.angle.push_back(r.angle_deg);
        });
      } catch (const std::exception& e) {
        std::printf("enrich %d: reduced run failed: %s\n", round, e.what());
      }
      std::printf("enrich %d: reduced run %.1f s, %ld states\n", round, since(t1), runs.back()->stats().states);
    }
    if (round == enrich) break;
    ReplayOptions replay_opt;
    replay_opt.corrected_at = [p_max, corrected_tops](const ReducedStep& s) {
      return s.report >= 0 && s.pressure_Pa > (corrected_tops ? 0.99 * p_max : 0.0);
    };
    replay_opt.newton = bm->solver.quasi_static.newton;
    const auto t2 = Clock::now();
    double worst = 0.0;
    int added = 0;
    replay_reduced_run(
        *rom_now, run_now->trajectory(),
        [&](const ReducedStep& s, const Eigen::VectorXd&, const std::vector<double>&, const ReducedCheck& c) {
          if (s.report < 0) return;
          if (std::isfinite(c.corrected_angle_error_deg)) worst = std::max(worst, std::abs(c.corrected_angle_error_deg));
          if (c.corrected_u.size() > 0) corrected_states.push_back(c.corrected_u), ++added;
          const std::size_t i = static_cast<std::size_t>(s.report);
          if (i < est_corr.size()) est_corr[i] = c.corrected_angle_error_deg;
        },
        replay_opt);
    std::printf("enrich %d: replay %.1f s, worst corrected estimate %.3f deg, %d corrected states\n", round, since(t2), worst, added);
  }
  if (!save_corrected.empty()) {
    std::vector<double> d;
    for (const auto& u : corrected_states) d.insert(d.end(), u.data(), u.data() + u.size());
    write_doubles(save_corrected, d);
    std::printf("corrected states: %zu to %s\n", corrected_states.size(), save_corrected.c_str());
  }
  // Kept points, ROM against FEM, at the last report of every trial: damage and largest stretch.
  if (dump) {
    Assembler A(bm->model);
    QuasiStaticRun q(A, bm->solver.quasi_static);
    std::vector<Eigen::VectorXd> fu;
    std::vector<std::vector<double>> fh;
    std::vector<int> ftrial;
    q.run(bm->load, [&](const StateRecord& r, const Eigen::VectorXd& u, const std::vector<double>& h) {
      fu.push_back(u), fh.push_back(A.history_scalars(h)), ftrial.push_back(r.trial);
    });
    const ElementGeometry& geom = A.geometry();
    auto stretch = [&](const Eigen::VectorXd& u, int e, int qp) {
      Mat3 F = Mat3::Identity();
      const int* n = bm->model.mesh.element(e);
      const double* g = geom.grad(e, qp);
      for (int a = 0; a < geom.npe; ++a) F += u.segment<3>(3 * n[a]) * Eigen::Map<const Eigen::RowVector3d>(g + 3 * a);
      return std::sqrt(Eigen::SelfAdjointEigenSolver<Mat3>(F.transpose() * F).eigenvalues().maxCoeff());
    };
    // Per region: sums over the kept points of the damage and the viscous strain (ROM, FEM, |ROM - FEM|) at report i.
    auto region_sums = [&](std::size_t i) {
      std::map<int, std::array<double, 6>> by_region;
      for (int k = 0; k < rom.num_points(); ++k) {
        const int e = rom.element_of_point(k), qp = k % geom.nqp;
        const double dr = rom_h[i][2 * k], df = fh[i][2 * (e * geom.nqp + qp)];
        const double vr = rom_h[i][2 * k + 1], vf = fh[i][2 * (e * geom.nqp + qp) + 1];
        std::array<double, 6>& reg = by_region[bm->model.mesh.region[e]];
        reg[0] += dr, reg[1] += df, reg[2] += std::abs(dr - df), reg[3] += vr, reg[4] += vf, reg[5] += std::abs(vr - vf);
      }
      return by_region;
    };
    // ROM / FEM - 1 in %; 0 where both sums are 0 (no such history), NaN where only the FEM's is.
    auto percent_off = [](double rom_sum, double fem_sum) {
      return fem_sum != 0.0 ? 100.0 * (rom_sum / fem_sum - 1.0) : rom_sum == 0.0 ? 0.0 : std::nan("");
    };
    if (dump_every) {
      // Where the reduced history parts from the FEM's: per region, the kept points' viscous strain sum,
      // ROM / FEM - 1 in %, at every report (climb, hold end, release), then the damage sum's.
      std::printf("viscous strain per region at every report, ROM/FEM - 1 %% (trial, p kPa, then region: %%):\n");
      for (std::size_t i = 0; i < fu.size() && i < rom_u.size(); ++i) {
        double dr_sum = 0, df_sum = 0;
        std::printf("  %2d %6.2f", ftrial[i], red.p[i] * 1e-3);
        for (const auto& [r, v] : region_sums(i)) {
          std::printf("  %s %+6.1f (%.2e)", bm->model.mesh.region_names[r].substr(0, 6).c_str(), percent_off(v[3], v[4]), v[4]);
          dr_sum += v[0], df_sum += v[1];
        }
        std::printf("  damage %+5.1f\n", percent_off(dr_sum, df_sum));
      }
    }
    for (std::size_t i = 0; i < fu.size() && i < rom_u.size(); ++i) {
      if (i + 1 < fu.size() && ftrial[i + 1] == ftrial[i]) continue;  // last report of a trial
      // the loaded top: the report before the last (the last one is at the hold end, same p)
      double sd_rom = 0, sd_fem = 0, n = 0, sl_rom = 0, sl_fem = 0;
      std::vector<std::tuple<double, int, int, double, double, double, double>> rows;
      const std::map<int, std::array<double, 6>> by_region = region_sums(i);
      for (int k = 0; k < rom.num_points(); ++k) {
        const int e = rom.element_of_point(k), qp = k % geom.nqp;
        const double dr = rom_h[i][2 * k], df = fh[i][2 * (e * geom.nqp + qp)];
        const double lr = stretch(rom_u[i], e, qp), lf = stretch(fu[i], e, qp);
        sd_rom += dr, sd_fem += df;
        if (df > 0.01) n += 1, sl_rom += lr - 1, sl_fem += lf - 1;
        rows.emplace_back(dr - df, e, qp, dr, df, lr, lf);
      }
      std::printf("trial %d: kept points' damage sum ROM %.3f FEM %.3f (%+.1f %%); over %g points with FEM damage > 0.01: mean stretch-1 ROM %.4f FEM %.4f\n",
                  ftrial[i], sd_rom, sd_fem, percent_off(sd_rom, sd_fem), n, sl_rom / std::max(n, 1.0), sl_fem / std::max(n, 1.0));
      for (const auto& [r, v] : by_region)
        std::printf("   region %-14s damage ROM %.4f FEM %.4f |diff| %.4f   viscous strain ROM %.4e FEM %.4e |diff| %.4e\n",
                    bm->model.mesh.region_names[r].c_str(), v[0], v[1], v[2], v[3], v[4], v[5]);
      std::sort(rows.begin(), rows.end());
      for (int j = 0; j < 8 && j < static_cast<int>(rows.size()); ++j) {
        auto [dd, e, qp, dr, df, lr, lf] = rows[static_cast<std::size_t>(j)];
        std::printf("   element %5d qp %d region %-14s damage ROM %.4f FEM %.4f  stretch ROM %.4f FEM %.4f\n", e, qp,
                    bm->model.mesh.region_names[bm->model.mesh.region[e]].c_str(), dr, df, lr, lf);
      }
    }
  }
  // 4. FEM (cached).
  Record full;
  if (fem) {
    const fs::path f = fs::path(work) / ("fem_" + std::to_string(fnv(scene.to_toml())) + ".csv");
    if (fs::exists(f)) {
      std::ifstream in(f);
      Record r;
      int tr;
      double t, p, a;
      while (in >> tr >> t >> p >> a) {
        r.trial.push_back(tr), r.t.push_back(t), r.p.push_back(p), r.angle.push_back(a);
      }
      full = r;
      std::printf("FEM record from %s\n", f.c_str());
    } else {
      const auto t0 = Clock::now();
      Assembler A(bm->model);
      QuasiStaticRun q(A, bm->solver.quasi_static);
      std::ofstream out(f.string() + ".part");
      out.precision(17);
      try {
        q.run(bm->load, [&](const StateRecord& r, const Eigen::VectorXd&, const std::vector<double>&) {
          full.trial.push_back(r.trial), full.t.push_back(r.time_s), full.p.push_back(r.pressure_Pa), full.angle.push_back(r.angle_deg);
          out << r.trial << " " << r.time_s << " " << r.pressure_Pa << " " << r.angle_deg << "\n";
          out.flush();
        });
        out.close();
        fs::rename(f.string() + ".part", f);
      } catch (const std::exception& e) {
        std::printf("FEM failed: %s\n", e.what());
      }
      std::printf("FEM: %.1f s wall, %ld states\n", since(t0), q.stats().states);
    }
  }
  if (fabric_strain) {
    // The stiff parts' (fabric's) largest Green strain, from each element's corner nodes (the linear
    // part of its F): where the reduced model keeps the fabric linear in q, a state that stretches it
    // is not charged for the stretch's second order.
    const Mesh& mesh = bm->model.mesh;
    auto largest = [&](const Eigen::VectorXd& u, bool linear) {
      double worst = 0.0;
      for (int e = 0; e < mesh.num_elements(); ++e) {
        if (!basis.stiff_part.empty() && !basis.stiff_part[static_cast<std::size_t>(bm->model.element_part[static_cast<std::size_t>(e)])]) continue;
        const int* n = mesh.element(e);
        Eigen::Matrix3d dX, dx;
        for (int c = 0; c < 3; ++c) {
          dX.col(c) = mesh.X[n[c + 1]] - mesh.X[n[0]];
          dx.col(c) = dX.col(c) + u.segment<3>(3 * n[c + 1]) - u.segment<3>(3 * n[0]);
        }
        const Eigen::Matrix3d F = dx * dX.inverse();
        const Eigen::Matrix3d H = F - Eigen::Matrix3d::Identity();
        const Eigen::Matrix3d E = linear ? Eigen::Matrix3d(0.5 * (H + H.transpose())) : Eigen::Matrix3d(0.5 * (F.transpose() * F - Eigen::Matrix3d::Identity()));
        worst = std::max(worst, Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(E).eigenvalues().cwiseAbs().maxCoeff());
      }
      return worst;
    };
    std::printf("stiff parts' largest Green strain per report (trial, t, rom, snapshot; then the small strain's, rom, snapshot):\n");
    for (std::size_t i = 0; i < strain_u.size(); ++i)
      std::printf("  %d %7.2f %.3e %.3e   %.3e %.3e   theta %8.3f |q| %.3e lambda %+.3e\n", red.trial[i], red.t[i], largest(strain_u[i], false),
                  i < snapshots.size() ? largest(snapshots[i], false) : std::nan(""), largest(strain_u[i], true),
                  i < snapshots.size() ? largest(snapshots[i], true) : std::nan(""), strain_theta[i], strain_q[i], strain_lambda[i]);
  }
  // 5. Comparison.
  const std::size_t n = std::min(red.angle.size(), full.angle.size());
  if (fem && n > 0) {
    std::map<int, double> worst;
    for (std::size_t i = 0; i < n; ++i) worst[full.trial[i]] = std::max(worst[full.trial[i]], std::abs(red.angle[i] - full.angle[i]));
    const bool complete = red.angle.size() == full.angle.size();
    std::vector<double> nr = complete ? nrmse_per_trial(bm->load, red, ideal) : std::vector<double>();
    std::vector<double> nf = complete ? nrmse_per_trial(bm->load, full, ideal) : std::vector<double>();
    std::printf("trial  max|rom-fem| deg   NRMSE fem %%   NRMSE rom %%   diff points\n");
    for (auto [tr, w] : worst) {
      if (complete)
        std::printf("%5d  %14.3f  %12.2f  %12.2f  %+10.2f\n", tr, w, 100 * nf[tr - 1], 100 * nr[tr - 1], 100 * (nr[tr - 1] - nf[tr - 1]));
      else
        std::printf("%5d  %14.3f\n", tr, w);
    }
    std::printf("reports (trial, t, p kPa, fem, rom, diff%s):\n", check ? ", adjoint estimate, Newton estimate, corrected-history estimate" : "");
    for (std::size_t i = 0; i < n; ++i) {
      std::printf("  %d %7.2f %6.2f %9.3f %9.3f %+7.3f", full.trial[i], full.t[i], full.p[i] * 1e-3, full.angle[i], red.angle[i],
                  red.angle[i] - full.angle[i]);
      if (check && i < est_adj.size()) std::printf(" %+8.3f %+8.3f %+8.3f", est_adj[i], est_newton[i], est_corr[i]);
      std::printf("\n");
    }
  } else {
    for (std::size_t i = 0; i < red.angle.size(); ++i)
    {
      std::printf("  %d %7.2f %6.2f %9.3f (ideal %9.3f)", red.trial[i], red.t[i], red.p[i] * 1e-3, red.angle[i],
                  i < ideal.angle.size() ? ideal.angle[i] : std::nan(""));
      if (check && i < est_adj.size()) std::printf(" %+8.3f %+8.3f %+8.3f", est_adj[i], est_newton[i], est_corr[i]);
      std::printf("\n");
    }
  }
  return 0;
}
