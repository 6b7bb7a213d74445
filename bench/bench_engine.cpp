// Engine benchmarks (not run in CI): prints figures recorded in BENCHMARKS.md.
//   * force kernel: element updates per second (internal force only) for Tet4 and Tet10 on the
//     default pneu-net mesh, 1 and N threads;
//   * tangent assembly and one Newton iteration (assembly + CHOLMOD factorisation + solve);
//   * one staircase trial (10 levels, 0-45 kPa) of the default scene, quasi-static Newton.
//   * --protocol FILE: the scene's whole quasi-static protocol (e.g. the ten-trial story with its
//     inelastic effects, issue 3's performance target) with the breakdown the issue asks for: states
//     solved, Newton iterations per state, time per iteration, and the wall time of every trial.
// Usage: bench_engine [--h-mm 2.0] [--threads N] [--blas-threads N] [--blas-ab] [--skip-trial] [--kernel-only] [--element tet4|tet10] [--reps 7]
//                     [--checksum] [--scene-force FILE] [--protocol FILE [--trials N] [--set KEY=VALUE]... [--angles CSV]
//                     [--save-after-first-trial CKPT | --save-each-trial PREFIX | --resume CKPT]]
// --checksum prints a hash of the bits of f_int, of K's values and of the energy (1 and N threads),
// so two builds of the kernel can be compared bit for bit (A/B of an optimisation).
// --scene-force FILE times the force-only kernel of a scene with history (e.g. the story's
// viscoelastic(fatigue(mullins(yeoh))), scenes/examples/paper_story.toml) at h = --h-mm, from the
// virgin state and from a loaded one, and hashes f_int and the trial state of both (A/B as above).
// --blas-threads N runs every factorisation with N OpenBLAS threads (engine/linear_solver.h; 1 as
// pneufem runs it). --blas-ab times the numeric factorisation of the default mesh's tangent at h
// with 1 and 2 BLAS threads alternately in one process (--reps pairs) and says whether the two
// solutions agree to the bit.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <cstdlib>
#include <fstream>
#include <string>
#include <vector>

#include <tbb/global_control.h>
#include <tbb/info.h>

#include <Eigen/CholmodSupport>

#include "engine/assembly.h"
#include "engine/factorisation_threads.h"
#include "engine/linear_solver.h"
#include "engine/quasi_static.h"
#include "scenes/build_model.h"

using namespace pneufem;
using Clock = std::chrono::steady_clock;

namespace {

template <class F>
double median_seconds(int reps, F&& f) {
  std::vector<double> t;
  for (int i = 0; i < reps; ++i) {
    const auto t0 = Clock::now();
    f();
    t.push_back(std::chrono::duration<double>(Clock::now() - t0).count());
  }
  std::sort(t.begin(), t.end());
  return t[t.size() / 2];
}

/// FNV-1a over the bytes of n doubles.
std::uint64_t hash_bits(const double* v, std::size_t n, std::uint64_t h = 0xcbf29ce484222325ULL) {
  const auto* b = reinterpret_cast<const unsigned char*>(v);
  for (std::size_t i = 0; i < n * sizeof(double); ++i) h = (h ^ b[i]) * 0x100000001b3ULL;
  return h;
}

void kernel_checksum(const std::string& element, double h_mm, int threads) {
  const Scene scene = Scene::load("", {"mesh.element=\"" + element + "\"", "mesh.h_mm=" + std::to_string(h_mm)});
  auto bm = build_model(scene);
  const Assembler A(bm->model);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(bm->model.num_dofs());
  for (int i = 0; i < u.size(); ++i) u[i] = 2e-5 * std::sin(0.37 * i);  // a generic small deformation (the fabric is 0.4 mm thin)
  for (int t : {1, threads}) {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, t);
    Eigen::VectorXd f, fk;
    SparseMatrix K;
    double W = 0.0, Wk = 0.0;
    A.internal(u, {}, {}, {}, &f, nullptr, &W);
    A.internal(u, {}, {}, {}, &fk, &K, &Wk);
    std::printf("  %-5s threads=%d  force %016llx  energy %016llx  force(tangent call) %016llx  K %016llx  energy %.17g\n",
                element.c_str(), t, static_cast<unsigned long long>(hash_bits(f.data(), f.size())),
                static_cast<unsigned long long>(hash_bits(&W, 1)),
                static_cast<unsigned long long>(hash_bits(fk.data(), fk.size(), hash_bits(&Wk, 1))),
                static_cast<unsigned long long>(hash_bits(K.valuePtr(), K.nonZeros())), W);
  }
}

void kernel_rates(const std::string& element, double h_mm, int threads, int reps) {
  const Scene scene = Scene::load("", {"mesh.element=\"" + element + "\"", "mesh.h_mm=" + std::to_string(h_mm)});
  auto bm = build_model(scene);
  const Assembler A(bm->model);
  const int ne = bm->model.mesh.num_elements();
  Eigen::VectorXd u = Eigen::VectorXd::Zero(bm->model.num_dofs());
  for (int i = 0; i < u.size(); ++i) u[i] = 1e-5 * std::sin(0.37 * i);  // a generic small deformation
  Eigen::VectorXd f;
  SparseMatrix K;
  for (int t : {1, threads}) {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, t);
    const double tf = median_seconds(reps, [&] { A.internal(u, {}, {}, {}, &f, nullptr, nullptr); });
    const double tk = median_seconds(3, [&] { A.internal(u, {}, {}, {}, &f, &K, nullptr); });
    std::printf("  %-5s h=%.2f mm  %6d elements  %7d dofs  %3d colours  threads=%d  force: %8.2f ms  %.3g element-updates/s"
                "  (%.3g qp/s)   force+tangent: %8.2f ms\n",
                element.c_str(), h_mm, ne, bm->model.num_dofs(), A.num_colours(), t, tf * 1e3, ne / tf,
                ne * double(A.geometry().nqp) / tf, tk * 1e3);
  }
}

/// Force only, with the material history of `file`'s scene. Virgin: from the initial state at the
/// generic small u1. Loaded: from the trial state of a large smooth deformation u_big (principal
/// stretches 0.1-1.9, period L/3 along each axis) at u2 = 0.7 u_big + u1, where points unload (Mullins
/// softening), some stay above a fatigue stretch threshold of 1.6 (damage grows) and every point has
/// an overstress (viscoelastic): the branches of a loaded state, not just the virgin ones.
void scene_force(const std::string& file, double h_mm, int threads, int reps) {
  const Scene scene = Scene::load(file, {"mesh.h_mm=" + std::to_string(h_mm)});
  auto bm = build_model(scene);
  const Assembler A(bm->model);
  const Mesh& mesh = bm->model.mesh;
  const int n = bm->model.num_dofs();
  Eigen::Vector3d lo = mesh.X[0], hi = mesh.X[0];
  for (const auto& x : mesh.X) {
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  Eigen::VectorXd u1(n), u_big = Eigen::VectorXd::Zero(n), u2(n), f;
  for (int i = 0; i < n; ++i) u1[i] = 2e-5 * std::sin(0.37 * i);
  for (int a = 0; a < mesh.num_nodes(); ++a)
    for (int d = 0; d < 3; ++d) {  // d u_d / d X_d = 0.9 cos(...)
      const double L = hi[d] - lo[d], k = 2.0 * 3.14159265358979 * 3.0 / L;
      u_big[3 * a + d] = 0.9 / k * std::sin(k * (mesh.X[a][d] - lo[d]));
    }
  u2 = 0.7 * u_big + u1;
  const std::vector<double> s0 = A.initial_state();
  std::vector<double> s_big(s0.size()), s1(s0.size()), s2(s0.size());
  A.internal(u_big, TimeStep{1.0, 1.0}, s0, s_big, &f, nullptr, nullptr);
  std::printf("  %s, h=%.2f mm, %d elements, %zu state doubles\n", file.c_str(), h_mm, mesh.num_elements(), s0.size());
  for (int t : {1, threads}) {
    tbb::global_control gc(tbb::global_control::max_allowed_parallelism, t);
    for (const bool loaded : {false, true}) {
      const Eigen::VectorXd& u = loaded ? u2 : u1;
      const std::vector<double>& s_old = loaded ? s_big : s0;
      std::vector<double>& s_new = loaded ? s2 : s1;
      const TimeStep ts = loaded ? TimeStep{1.1, 0.1} : TimeStep{1.0, 0.1};
      const double tf = median_seconds(reps, [&] { A.internal(u, ts, s_old, s_new, &f, nullptr, nullptr); });
      std::printf("    threads=%d  %-7s force: %7.2f ms  f_int %016llx  trial state %016llx\n", t,
                  loaded ? "loaded" : "virgin", tf * 1e3, static_cast<unsigned long long>(hash_bits(f.data(), f.size())),
                  static_cast<unsigned long long>(hash_bits(s_new.data(), s_new.size())));
    }
  }
  // The other paths of a law with history at the loaded state: force + tangent, and energy only
  // without a trial state (an empty state_new).
  SparseMatrix K;
  double W = 0.0, W_only = 0.0;
  Eigen::VectorXd fk;
  A.internal(u2, TimeStep{1.1, 0.1}, s_big, s2, &fk, &K, &W);
  A.internal(u2, TimeStep{1.1, 0.1}, s_big, {}, nullptr, nullptr, &W_only);
  std::printf("    loaded, tangent call: f_int %016llx  K %016llx  energy %016llx  trial state %016llx;"
              "  energy without trial state %016llx\n",
              static_cast<unsigned long long>(hash_bits(fk.data(), fk.size())),
              static_cast<unsigned long long>(hash_bits(K.valuePtr(), K.nonZeros())),
              static_cast<unsigned long long>(hash_bits(&W, 1)),
              static_cast<unsigned long long>(hash_bits(s2.data(), s2.size())),
              static_cast<unsigned long long>(hash_bits(&W_only, 1)));
}

void newton_iteration(double h_mm, int threads) {
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, threads);
  const Scene scene = Scene::load("", {"mesh.h_mm=" + std::to_string(h_mm)});
  auto bm = build_model(scene);
  const Assembler A(bm->model);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(bm->model.num_dofs()), f;
  SparseMatrix K = A.tangent_pattern();
  LinearSolver ls;
  const double ta = median_seconds(3, [&] {
    A.internal(u, {}, {}, {}, &f, &K, nullptr);
    Eigen::VectorXd fe = Eigen::VectorXd::Zero(u.size());
    A.add_pressure(u, 2e4, fe, &K);
  });
  A.apply_constraints(K, 1.0);
  ls.factorize(K);  // symbolic analysis + first numeric factorisation
  const double tf = median_seconds(3, [&] { ls.factorize(K); });
  Eigen::VectorXd b = Eigen::VectorXd::Ones(u.size());
  const double ts = median_seconds(5, [&] { b = ls.solve(b); });
  std::printf("  Newton iteration (Tet10, h=%.2f mm, %d dofs, %d threads): assembly %.3f s, factorisation %.3f s, "
              "solve %.3f s, nnz(K) = %ld\n",
              h_mm, bm->model.num_dofs(), threads, ta, tf, ts, static_cast<long>(K.nonZeros()));
}

void one_trial(double h_mm, int threads) {
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, threads);
  const Scene scene = Scene::load("", {"mesh.h_mm=" + std::to_string(h_mm)});
  auto bm = build_model(scene);
  const Assembler A(bm->model);
  QuasiStaticRun run(A, bm->solver.quasi_static);
  std::vector<StateRecord> recs;
  const auto t0 = Clock::now();
  run.run(bm->load, [&](const StateRecord& r, const Eigen::VectorXd&, const std::vector<double>&) { recs.push_back(r); });
  const double wall = std::chrono::duration<double>(Clock::now() - t0).count();
  const StaticStats& st = run.static_solver().stats();
  std::printf("  one staircase trial (Tet10, h=%.2f mm, %d dofs, %d threads): %.2f s wall; %ld increments, %ld cutbacks, "
              "%ld Newton iterations, assembly %.2f s, factor+solve %.2f s\n",
              h_mm, bm->model.num_dofs(), threads, wall, st.increments, st.cutbacks, st.iterations, st.assembly_s,
              st.factor_s);
  std::printf("    p_kPa  angle_deg\n");
  for (const auto& r : recs)
    if (std::abs(r.time_s - std::round(r.time_s / 16.0) * 16.0) < 1e-6)
      std::printf("    %5.1f  %9.3f\n", r.pressure_Pa * 1e-3, r.angle_deg);
}

/// The Newton tangent of the default mesh at h, unloaded (u = 0, no pressure), constraints applied.
SparseMatrix unloaded_tangent(double h_mm) {
  auto bm = build_model(Scene::load("", {"mesh.h_mm=" + std::to_string(h_mm)}));
  const Assembler A(bm->model);
  Eigen::VectorXd u = Eigen::VectorXd::Zero(bm->model.num_dofs()), f;
  SparseMatrix K = A.tangent_pattern();
  A.internal(u, {}, {}, {}, &f, &K, nullptr);
  A.apply_constraints(K, 1.0);
  return K;
}

/// Fill-reducing orderings of the Newton tangent (default mesh at h, unloaded: u = 0, no pressure):
/// for CHOLMOD's default choice and each single method, the analysis time, nnz(L), the flop count
/// and the median numeric factorisation time (serial BLAS, as LinearSolver runs it).
void orderings(double h_mm, int threads, int reps) {
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, threads);
  const SparseMatrix K = unloaded_tangent(h_mm);
  { LinearSolver warm; warm.factorize(K); }  // process settings (serial BLAS / OpenMP) as in a run
  struct Try { const char* name; int nmethods; int ordering; };
  const Try tries[] = {{"default (CHOLMOD's choice)", 0, -1}, {"AMD", 1, CHOLMOD_AMD}, {"METIS", 1, CHOLMOD_METIS},
                       {"NESDIS", 1, CHOLMOD_NESDIS}};
  std::printf("  tangent: %d dofs, nnz(K) = %ld\n", static_cast<int>(K.rows()), static_cast<long>(K.nonZeros()));
  for (const Try& t : tries) {
    Eigen::CholmodSupernodalLLT<SparseMatrix, Eigen::Lower> llt;
    llt.cholmod().print = 0;
    if (t.nmethods > 0) {
      llt.cholmod().nmethods = 1;
      llt.cholmod().method[0].ordering = t.ordering;
    }
    const auto t0 = Clock::now();
    llt.analyzePattern(K);
    const double ta = std::chrono::duration<double>(Clock::now() - t0).count();
    const double tf = median_seconds(reps, [&] { llt.factorize(K); });
    const auto& c = llt.cholmod();
    std::printf("  %-28s analysis %6.2f s  selected ordering %d  nnz(L) %.3g  flops %.3g  factorisation %.3f s  (%s)\n",
                t.name, ta, c.method[c.selected].ordering, c.lnz, c.fl, tf,
                llt.info() == Eigen::Success ? "ok" : "not positive definite");
  }
}

/// Numeric factorisation of the unloaded tangent (default mesh at h) with 1 and 2 BLAS threads,
/// alternately, `reps` pairs: the medians, their ratio and whether the solutions agree to the bit.
void blas_threads_ab(double h_mm, int threads, int reps) {
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, threads);
  const SparseMatrix K = unloaded_tangent(h_mm);
  LinearSolver ls;
  ls.factorize(K);  // symbolic analysis
  std::vector<double> times[2];
  Eigen::VectorXd x[2];
  const Eigen::VectorXd b = Eigen::VectorXd::Ones(K.rows());
  for (int r = 0; r < reps; ++r)
    for (int i = 0; i < 2; ++i) {
      set_factorisation_blas_threads(i + 1);
      const auto t0 = Clock::now();
      ls.factorize(K);
      times[i].push_back(std::chrono::duration<double>(Clock::now() - t0).count());
      x[i] = ls.solve(b);
      std::printf("  pair %d, %d BLAS thread%s: %.3f s\n", r + 1, i + 1, i ? "s" : "", times[i].back());
    }
  set_factorisation_blas_threads(1);
  auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };
  const double m1 = median(times[0]), m2 = median(times[1]);
  std::printf("  %d dofs, %d TBB threads: median factorisation 1 BLAS thread %.3f s, 2 BLAS threads %.3f s "
              "(2/1 = %.3f); solutions %s\n",
              static_cast<int>(K.rows()), threads, m1, m2, m2 / m1,
              std::memcmp(x[0].data(), x[1].data(), sizeof(double) * x[0].size()) ? "differ in their bits" : "identical");
}

/// Where a protocol run stands: the wall clock and the solver's counts so far. Two marks give the
/// cost of what ran between them.
struct ProgressMark {
  Clock::time_point wall;
  long states, iterations, factorizations;
};

ProgressMark progress_mark(const QuasiStaticRun& run) {
  return ProgressMark{Clock::now(), run.stats().states, run.static_solver().stats().iterations,
                      run.static_solver().stats().factorizations};
}

double seconds_between(const ProgressMark& a, const ProgressMark& b) { return std::chrono::duration<double>(b.wall - a.wall).count(); }

/// A trial's climb, from its first report to its last (the line goes on with the gap after it).
void print_trial(int trial, const ProgressMark& first, const ProgressMark& last) {
  std::printf("  trial %2d: climb %8.1f s, %5ld states, %6ld Newton its, %5ld factorisations", trial, seconds_between(first, last),
              last.states - first.states, last.iterations - first.iterations, last.factorizations - first.factorizations);
  std::fflush(stdout);
}

/// The gap before the next trial's first report, after the last report of a trial: the release, the
/// rest, then the first 2.5 s at 0 kPa.
void print_gap(const ProgressMark& last, const ProgressMark& release_end, const ProgressMark& rest_end, const ProgressMark& now) {
  std::printf(" | then release + rest %6.1f s, %3ld states, %4ld its, %4ld facts (release %5.1f s, %ld states, %ld its, "
              "%ld facts; rest %5.1f s, %ld states, %ld its, %ld facts); 2.5 s at 0 kPa %5.1f s, %2ld states, "
              "%3ld its, %3ld facts\n",
              seconds_between(last, rest_end), rest_end.states - last.states, rest_end.iterations - last.iterations,
              rest_end.factorizations - last.factorizations, seconds_between(last, release_end),
              release_end.states - last.states, release_end.iterations - last.iterations,
              release_end.factorizations - last.factorizations, seconds_between(release_end, rest_end),
              rest_end.states - release_end.states, rest_end.iterations - release_end.iterations,
              rest_end.factorizations - release_end.factorizations, seconds_between(rest_end, now), now.states - rest_end.states,
              now.iterations - rest_end.iterations, now.factorizations - rest_end.factorizations);
  std::fflush(stdout);
}

/// The whole run's cost, with the solver's breakdown.
void print_totals(const QuasiStaticRun& run, double wall) {
  const StaticStats& st = run.static_solver().stats();
  const double states = static_cast<double>(run.stats().states), its = static_cast<double>(st.iterations);
  std::printf("  total %.1f s wall: %ld states (+%ld rejected), %ld Newton iterations (%.2f per state), "
              "%ld factorisations, %ld Krylov iterations\n",
              wall, run.stats().states, run.stats().rejected_steps, st.iterations, its / std::max(1.0, states),
              st.factorizations, st.krylov_iterations);
  std::printf("  per Newton iteration %.3f s (assembly %.1f s, factorisation + solves %.1f s in all); per state %.3f s\n",
              wall / std::max(1.0, its), st.assembly_s, st.factor_s, wall / std::max(1.0, states));
  std::printf("  Krylov steps %ld, CG give-ups %ld, factorisations forced by a Krylov step that did not halve |R| %ld, "
              "last-factor steps %ld (of which after negative curvature in CG, no factorisation %ld), chord steps %ld\n",
              st.krylov_steps, st.krylov_give_ups, st.contraction_refactors, st.last_factor_steps, st.indefinite_by_cg,
              st.chord_steps);
}

/// The protocol's header line: the model's size and the options.
void print_protocol_header(const std::string& file, const BuiltModel& bm, int threads, const std::vector<std::string>& sets) {
  std::printf("protocol %s: %d nodes, %d elements, %d dofs, %zu trials, %d threads", file.c_str(),
              bm.model.mesh.num_nodes(), bm.model.mesh.num_elements(), bm.model.num_dofs(), bm.load.trials.size(),
              threads);
  for (const std::string& k : sets) std::printf(", --set %s", k.c_str());
  std::printf("\n");
}

/// The quasi-static protocol of `file` (its own mesh unless --h-mm is given, its own trials unless
/// trials > 0, `sets` as simulate's --set), timed as a whole and per trial, with the solver's
/// breakdown; with `angles` non-empty every report (trial, time, pressure, angle) goes to that CSV.
void protocol(const std::string& file, double h_mm, bool set_h, int trials, int threads, std::vector<std::string> sets,
              const std::string& angles, const std::string& save_after_first, const std::string& resume_file,
              const std::string& save_each) {
  tbb::global_control gc(tbb::global_control::max_allowed_parallelism, threads);
  if (set_h) sets.push_back("mesh.h_mm=" + std::to_string(h_mm));
  if (trials > 0) sets.push_back("load.trials=" + std::to_string(trials));
  const Scene scene = Scene::load(file, sets);
  auto bm = build_model(scene);
  const Assembler A(bm->model);
  QuasiStaticRun run(A, bm->solver.quasi_static);
  print_protocol_header(file, *bm, threads, sets);
  std::FILE* csv = angles.empty() ? nullptr : std::fopen(angles.c_str(), "w");
  if (csv) std::fprintf(csv, "trial,time_s,pressure_kPa,angle_deg\n");
  const auto t0 = Clock::now();
  auto since = [](Clock::time_point t) { return std::chrono::duration<double>(Clock::now() - t).count(); };
  // Per trial: from its first report (the 2.5 s mark of the 0 kPa step) to its last (the end of the
  // top hold), and the gap before it: the release from the previous trial's top pressure and the
  // rest (counted at the end of the rest segment), then the first 2.5 s at 0 kPa. The gap's share
  // says how much of a trial's cost is not the climb.
  const std::vector<QuasiStaticRun::Segment> segs = QuasiStaticRun::segments(bm->load);
  // --resume: continue from a checkpoint saved with --save-after-first-trial (e.g. by the other time
  // control: the release clears the step control's memory, so the gap that follows is a clean A/B).
  QuasiStaticCheckpoint resume;
  if (!resume_file.empty()) {
    std::ifstream in(resume_file, std::ios::binary);
    resume = QuasiStaticCheckpoint::read(in, static_cast<std::size_t>(A.num_dofs()), A.initial_state().size());
    std::printf("  resumed from %s before segment %zu\n", resume_file.c_str(), resume.next_segment);
  }
  int trial = resume_file.empty() ? 0 : segs[resume.next_segment - 1].trial + 1;
  ProgressMark first = progress_mark(run), last = first, release_end = first, rest_end = first;
  auto sink = [&](const QuasiStaticCheckpoint& c) {
    const QuasiStaticRun::Segment& sg = segs[c.next_segment - 1];
    if (!save_after_first.empty() && sg.trial == 0 && c.next_segment < segs.size() && segs[c.next_segment].trial == 1) {
      std::ofstream out(save_after_first, std::ios::binary);
      c.write(out);
      out.close();  // std::exit below does not destroy this scope's objects
      print_trial(trial, first, last);
      std::printf("\n  saved the state after trial 1 to %s (%.1f s wall)\n", save_after_first.c_str(), since(t0));
      if (csv) std::fclose(csv);
      std::exit(0);
    }
    // --save-each-trial PREFIX: the state after trial N (before the release) to PREFIX.tN, the run
    // going on: a later gap can then be rerun (e.g. under another control) without trials 1..N.
    if (!save_each.empty() && c.next_segment < segs.size() && segs[c.next_segment].trial == sg.trial + 1) {
      std::ofstream out(save_each + ".t" + std::to_string(sg.trial + 1), std::ios::binary);
      c.write(out);
    }
    if (sg.trial > 0 && sg.t0 == 0.0 && sg.t1 == 0.0 && sg.g1 == sg.g0 && sg.p1 == 0.0 && sg.p0 != 0.0)
      release_end = progress_mark(run);                                                                  // the release
    if (sg.trial > 0 && sg.t0 == 0.0 && sg.t1 == 0.0 && sg.g1 > sg.g0) rest_end = progress_mark(run);  // the rest
  };
  run.run(
      bm->load,
      [&](const StateRecord& r, const Eigen::VectorXd&, const std::vector<double>&) {
        const ProgressMark now = progress_mark(run);
        if (csv) std::fprintf(csv, "%d,%.6f,%.4f,%.9f\n", r.trial, r.time_s, r.pressure_Pa * 1e-3, r.angle_deg), std::fflush(csv);
        if (r.trial != trial) {
          if (trial > 0) {
            print_trial(trial, first, last);
            print_gap(last, release_end, rest_end, now);
          }
          trial = r.trial;
          first = now;
        }
        last = now;
      },
      sink, resume_file.empty() ? nullptr : &resume);
  print_trial(trial, first, last);
  std::printf("\n");
  if (csv) std::fclose(csv);
  print_totals(run, since(t0));
}

}  // namespace

int main(int argc, char** argv) {
  double h = 2.0;
  int threads = tbb::info::default_concurrency();
  bool skip_trial = false, kernel_only = false, checksum = false;
  int reps = 7;
  std::string only_element;  // "" = both
  std::string scene_file, protocol_file;
  bool set_h = false, do_orderings = false, do_blas_ab = false;
  int trials = 0;
  std::vector<std::string> sets;
  std::string angles, save_after_first, resume_file, save_each;
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--h-mm") && i + 1 < argc) h = std::atof(argv[++i]), set_h = true;
    else if (!std::strcmp(argv[i], "--threads") && i + 1 < argc) threads = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--skip-trial")) skip_trial = true;
    else if (!std::strcmp(argv[i], "--kernel-only")) kernel_only = true;  // force kernel only (profiling)
    else if (!std::strcmp(argv[i], "--element") && i + 1 < argc) only_element = argv[++i];
    else if (!std::strcmp(argv[i], "--reps") && i + 1 < argc) reps = std::max(1, std::atoi(argv[++i]));
    else if (!std::strcmp(argv[i], "--checksum")) checksum = true;
    else if (!std::strcmp(argv[i], "--scene-force") && i + 1 < argc) scene_file = argv[++i];
    else if (!std::strcmp(argv[i], "--protocol") && i + 1 < argc) protocol_file = argv[++i];
    else if (!std::strcmp(argv[i], "--trials") && i + 1 < argc) trials = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--set") && i + 1 < argc) sets.push_back(argv[++i]);
    else if (!std::strcmp(argv[i], "--angles") && i + 1 < argc) angles = argv[++i];
    else if (!std::strcmp(argv[i], "--save-after-first-trial") && i + 1 < argc) save_after_first = argv[++i];
    else if (!std::strcmp(argv[i], "--resume") && i + 1 < argc) resume_file = argv[++i];
    else if (!std::strcmp(argv[i], "--save-each-trial") && i + 1 < argc) save_each = argv[++i];
    else if (!std::strcmp(argv[i], "--orderings")) do_orderings = true;
    else if (!std::strcmp(argv[i], "--blas-threads") && i + 1 < argc) set_factorisation_blas_threads(std::max(1, std::atoi(argv[++i])));
    else if (!std::strcmp(argv[i], "--blas-ab")) do_blas_ab = true;
  }
  if (do_blas_ab) {
    std::printf("factorisation with 1 and 2 BLAS threads (h=%.2f mm):\n", h);
    blas_threads_ab(h, threads, reps);
    return 0;
  }
  if (do_orderings) {
    std::printf("fill-reducing orderings of the tangent (h=%.2f mm):\n", h);
    orderings(h, threads, reps);
    return 0;
  }
  if (!protocol_file.empty()) {
    protocol(protocol_file, h, set_h, trials, threads, sets, angles, save_after_first, resume_file, save_each);
    return 0;
  }
  if (!scene_file.empty()) {
    std::printf("force kernel with history (threads available: %d):\n", tbb::info::default_concurrency());
    scene_force(scene_file, h, threads, reps);
    return 0;
  }
  if (checksum) {
    std::printf("kernel checksums (h=%.2f mm):\n", h);
    for (const char* el : {"tet4", "tet10"})
      if (only_element.empty() || only_element == el) kernel_checksum(el, h, threads);
    return 0;
  }
  std::printf("pneufem engine benchmark (threads available: %d)\n", tbb::info::default_concurrency());
  std::printf("force kernel:\n");
  for (const char* el : {"tet4", "tet10"})
    if (only_element.empty() || only_element == el) kernel_rates(el, h, threads, reps);
  if (kernel_only) return 0;
  std::printf("implicit:\n");
  newton_iteration(h, threads);
  if (!skip_trial) one_trial(h, threads);
  return 0;
}
