// The reduced-order model of engine/rom.h: its pieces (NNLS, splines, the Jacobian, the stored
// basis) against exact answers, and the whole model against the full quasi-static FEM on a small
// pneu-net (3 chambers, h = 6 mm) through the paper's staircase with every history effect, each
// effect alone, and an effect registered only through damage/registry.h.
//
// The basis is built once, from the ELASTIC reference (effects off): no effect constant enters it,
// so every comparison below is with parameters the basis never saw.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>
#include <map>
#include <string>

#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include "analysis/paper_metrics.h"
#include "core/errors.h"
#include "damage/registry.h"
#include "engine/angle.h"
#include "engine/assembly.h"
#include "engine/path_model.h"
#include "engine/path_spline.h"
#include "engine/quasi_static.h"
#include "engine/rom.h"
#include "materials/tensor.h"
#include "scenes/build_model.h"
#include "tests/support/input_error.h"

namespace pneufem {
namespace {

using pneufem::test::error_of;

// ------------------------------------------------------------------ splines

/// The not-a-knot spline reproduces a cubic exactly on uneven knots (value, slope, curvature).
TEST(PathSpline, NotAKnotSplineReproducesACubic) {
  const std::vector<double> th = {0.0, 0.7, 1.1, 2.0, 2.4, 3.3, 4.0};
  auto f = [](double x) { return 1.0 - 2.0 * x + 0.5 * x * x - 0.3 * x * x * x; };
  auto df = [](double x) { return -2.0 + x - 0.9 * x * x; };
  auto d2f = [](double x) { return 1.0 - 1.8 * x; };
  const std::vector<double> m = spline_slopes<double>(th, [&](std::size_t k) { return f(th[k]); });
  for (std::size_t k = 0; k < th.size(); ++k) EXPECT_NEAR(m[k], df(th[k]), 1e-12);
  for (double x = 0.05; x < 4.0; x += 0.17) {
    const int k = path_segment_index(th, x);
    const double dth = th[k + 1] - th[k];
    const Hermite h((x - th[k]) / dth, dth);
    EXPECT_NEAR(h.value(f(th[k]), f(th[k + 1]), m[k], m[k + 1]), f(x), 1e-12);
    EXPECT_NEAR(h.slope(f(th[k]), f(th[k + 1]), m[k], m[k + 1]), df(x), 1e-11);
    EXPECT_NEAR(h.curvature(f(th[k]), f(th[k + 1]), m[k], m[k + 1]), d2f(x), 1e-10);
  }
}

// ------------------------------------------------------------------ the small pneu-net

// 3 chambers, h = 6 mm (5,385 dof), the paper's 0 -> 45 kPa staircase (5 kPa steps) with 4 s holds
// and 2 s marks; the story's constants with the 3-chamber fatigue rate (tests/app/test_story.cpp).
const std::string kStory = std::string(PNEUFEM_TEST_DATA_DIR) + "/../../scenes/examples/paper_story.toml";
const std::vector<std::string> kSmall = {"geometry.chambers=3",     "mesh.h_mm=6.0", "output.vtu=\"none\"",
                                         "load.hold_s=4.0",         "load.mark_s=2.0",
                                         "materials.silicone.fatigue.tau_s=80.0"};
const std::vector<std::string> kElastic = {"materials.silicone.mullins.enabled=false", "materials.silicone.fatigue.enabled=false",
                                           "materials.silicone.viscoelastic.enabled=false", "gravity.g_m_s2=[0.0, 0.0, 0.0]",
                                           "gravity.rig_angle_deg=-1.0", "load.pressure_lag_s=0.0", "load.trials=1"};

Scene small_scene(std::vector<std::string> extra) {
  std::vector<std::string> sets = kSmall;
  sets.insert(sets.end(), extra.begin(), extra.end());
  return Scene::load(kStory, sets);
}

/// The elastic reference, its path and basis: built once for the whole file (~10 s).
struct Offline {
  std::unique_ptr<BuiltModel> ref;
  ElasticPathTrace trace;
  ReducedBasis basis;
};
const Offline& offline() {
  static const Offline* o = [] {
    auto* out = new Offline;
    out->ref = build_model(small_scene(kElastic));
    PathModelOptions po;
    po.p_top_Pa = 1.8 * 45e3;
    po.dp_Pa = 45e3 / 40.0;
    po.newton = out->ref->solver.quasi_static.newton;
    out->trace = trace_elastic_path(out->ref->model, po);
    out->basis = build_reduced_basis(out->ref->model, out->trace, RomBasisOptions{});
    return out;
  }();
  return *o;
}

/// The same with softened equilibria (6 levels to 0.9; solver.reduced_softened_levels = 6): built once (~20 s).
const ReducedBasis& softened_basis() {
  static const ReducedBasis* b = [] {
    RomBasisOptions opt;
    opt.softened_levels = 6;
    opt.softened_max = 0.9;
    return new ReducedBasis(build_reduced_basis(offline().ref->model, offline().trace, opt));
  }();
  return *b;
}

struct Record {
  std::vector<int> trial;
  std::vector<double> t, angle;
};

Record fem_run(const BuiltModel& bm) {
  Record r;
  Assembler A(bm.model);
  QuasiStaticRun run(A, bm.solver.quasi_static);
  run.run(bm.load, [&](const StateRecord& s, const Eigen::VectorXd&, const std::vector<double>&) {
    r.trial.push_back(s.trial), r.t.push_back(s.time_s), r.angle.push_back(s.angle_deg);
  });
  return r;
}

/// Three trials of fatigue alone with 16 s holds: the case the fatigue-feedback tests share, its
/// model and FEM record built once for the whole file.
const std::vector<std::string> kFatigue = {"load.hold_s=16.0", "load.mark_s=2.5", "load.trials=3",
                                           "materials.silicone.mullins.enabled=false",
                                           "materials.silicone.viscoelastic.enabled=false"};
struct FatigueCase {
  std::unique_ptr<BuiltModel> bm;
  Record fem;
};
const FatigueCase& fatigue_case() {
  static const FatigueCase* c = [] {
    auto* out = new FatigueCase;
    out->bm = build_model(small_scene(kFatigue));
    out->fem = fem_run(*out->bm);
    return out;
  }();
  return *c;
}

Record rom_run(const BuiltModel& bm, const ReducedBasis& basis, ReducedRunStats* stats = nullptr, bool reuse_jacobian = true) {
  Record r;
  const ReducedOrderModel rom(offline().ref->model, basis, bm.model);
  ReducedRun run(rom, bm.solver.quasi_static);
  run.set_jacobian_reuse(reuse_jacobian);
  run.run(bm.load, [&](const StateRecord& s, const ReducedCoordinates&, const Eigen::VectorXd&) {
    r.trial.push_back(s.trial), r.t.push_back(s.time_s), r.angle.push_back(s.angle_deg);
  });
  if (stats) *stats = run.stats();
  return r;
}

/// a^T M b with the lumped nodal mass M (one value per node).
double mass_dot(const Eigen::VectorXd& mass, const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  double s = 0.0;
  for (Eigen::Index i = 0; i < mass.size(); ++i) s += mass[i] * a.segment<3>(3 * i).dot(b.segment<3>(3 * i));
  return s;
}

/// The paper's NRMSE of each trial of `a` against trial 1 of `ideal` (angles at marks and ends).
std::vector<double> nrmse(const LoadHistory& load, const Record& a, const Record& ideal) {
  auto steps = [&](const Record& r, int trial) {
    StepAngles s;
    s.trial = trial;
    const TrialLoad& tl = load.trials[static_cast<std::size_t>(trial - 1)];
    auto at = [&](double t) {
      for (std::size_t i = 0; i < r.t.size(); ++i)
        if (r.trial[i] == trial && std::abs(r.t[i] - t) < 1e-9) return r.angle[i];
      ADD_FAILURE() << "no report at trial " << trial << " t " << t;
      return 0.0;
    };
    for (std::size_t k = 0; k < tl.step_start_s.size(); ++k) {
      s.level_kPa.push_back(tl.step_level_Pa[k] * 1e-3);
      s.at_mark_deg.push_back(at(tl.step_start_s[k] + tl.mark_s));
      s.at_end_deg.push_back(at(tl.step_end_s[k]));
    }
    return s;
  };
  std::vector<double> out;
  const StepAngles ref = steps(ideal, 1);
  for (std::size_t k = 0; k < load.trials.size(); ++k) out.push_back(paper_metrics(steps(a, static_cast<int>(k) + 1), ref).nrmse);
  return out;
}

/// The accuracy targets: every report angle within `angle_tol` deg of the FEM's, every
/// trial's NRMSE (against the elastic model) within `nrmse_tol` points; and the drift of the top
/// angle from trial 1 to the last trial (what the effects do) within `drift_rel` of the FEM's.
void expect_follows_fem(const std::vector<std::string>& effects, double angle_tol, double nrmse_tol, double drift_rel,
                        const ReducedBasis* basis = nullptr) {
  const auto bm = build_model(small_scene(effects));
  const Record fem = fem_run(*bm), rom = rom_run(*bm, basis ? *basis : offline().basis);
  ASSERT_EQ(fem.angle.size(), rom.angle.size());
  double worst = 0.0;
  for (std::size_t i = 0; i < fem.angle.size(); ++i) {
    ASSERT_EQ(fem.trial[i], rom.trial[i]);
    ASSERT_NEAR(fem.t[i], rom.t[i], 1e-9);
    worst = std::max(worst, std::abs(fem.angle[i] - rom.angle[i]));
  }
  const int last = fem.trial.back();
  EXPECT_LE(worst, angle_tol) << "largest |ROM - FEM| over the reports";
  const auto ideal_bm = build_model(small_scene(kElastic).with({"load.trials=" + std::to_string(last)}));
  const Record ideal = rom_run(*ideal_bm, offline().basis);
  const std::vector<double> nf = nrmse(bm->load, fem, ideal), nr = nrmse(bm->load, rom, ideal);
  for (std::size_t k = 0; k < nf.size(); ++k)
    EXPECT_NEAR(100.0 * nr[k], 100.0 * nf[k], nrmse_tol) << "NRMSE (points) of trial " << k + 1;
  std::printf("worst %.4f deg; NRMSE points:", worst);
  for (std::size_t k = 0; k < nf.size(); ++k) std::printf(" %.3f/%.3f", 100 * nf[k], 100 * nr[k]);
  std::printf("\n");
  if (drift_rel > 0.0) {
    // The change from trial 1 to the last trial at every report (what the effects do over trials):
    // the ROM's against the FEM's, relative to the FEM's largest change.
    const std::size_t per_trial = fem.angle.size() / static_cast<std::size_t>(last);
    double largest = 0.0, off = 0.0;
    for (std::size_t i = 0; i < per_trial; ++i) {
      const std::size_t j = i + (static_cast<std::size_t>(last) - 1) * per_trial;
      ASSERT_NEAR(fem.t[j], fem.t[i], 1e-9) << "reports at the same time of each trial";
      const double df = fem.angle[j] - fem.angle[i], dr = rom.angle[j] - rom.angle[i];
      largest = std::max(largest, std::abs(df));
      off = std::max(off, std::abs(dr - df));
    }
    EXPECT_GT(largest, 0.1) << "the effects change the angle from trial 1 to " << last << " (not a vacuous test)";
    EXPECT_LE(off, drift_rel * largest) << "change from trial 1 to " << last << ": ROM against FEM";
  }
}

// The elastic reference is the path itself: the reduced run of the reference reproduces the FEM's
// elastic staircase to the spline's interpolation error between path samples (1.1 kPa apart; the
// error of a cubic spline there is ~1e-4 of the angle, measured 2e-4 deg at 30 deg) plus Newton's
// tolerance. 0.005 deg is 0.05 % of the 9.4 deg at 45 kPa.
TEST(ReducedModel, ReproducesTheElasticReference) {
  const auto bm = build_model(small_scene(kElastic));
  const Record fem = fem_run(*bm);
  ReducedRunStats st;
  const Record rom = rom_run(*bm, offline().basis, &st);
  ASSERT_EQ(fem.angle.size(), rom.angle.size());
  for (std::size_t i = 0; i < fem.angle.size(); ++i) EXPECT_NEAR(rom.angle[i], fem.angle[i], 5e-3) << "report " << i;
  EXPECT_FALSE(st.beyond_path);
  EXPECT_GT(fem.angle.back() + 1.0, 9.0);  // the staircase does bend the actuator (not a vacuous test)
}

// The kept Jacobian (modified Newton) changes the iterates, not the equilibria: every effect, three
// trials, against plain Newton with a fresh Jacobian at every iteration. Both stop within
// 1e-6 (1 + |theta|) deg of the reduced equations' root (~1e-5 deg at 10 deg), and the history each
// state leaves differs by as little, so 1e-3 deg over ~400 states is 100x the tolerance, and 1e4 x
// below the 0.5 deg the model is judged by. The kept one must also do what it is for: at most half as
// many tangents as Newton iterations (measured: 61 tangents for 1 244 iterations; plain Newton 903 for 588).
TEST(ReducedModel, AKeptJacobianReachesTheSameEquilibriaWithFewerTangents) {
  const auto bm = build_model(small_scene({"load.trials=3"}));
  ReducedRunStats kept, fresh;
  const Record a = rom_run(*bm, offline().basis, &kept, true), b = rom_run(*bm, offline().basis, &fresh, false);
  ASSERT_EQ(a.angle.size(), b.angle.size());
  for (std::size_t i = 0; i < a.angle.size(); ++i) EXPECT_NEAR(a.angle[i], b.angle[i], 1e-3) << "report " << i;
  EXPECT_EQ(fresh.reused_tangents, 0);
  EXPECT_GE(fresh.tangents, fresh.newton_iterations);
  EXPECT_LE(2 * kept.tangents, kept.newton_iterations) << kept.tangents << " tangents, " << kept.newton_iterations << " iterations";
  EXPECT_GT(a.angle.back() - a.angle.front(), 1.0);  // the run bends (not a vacuous comparison)
  std::printf("kept: %ld tangents / %ld iterations; fresh: %ld / %ld\n", kept.tangents, kept.newton_iterations, fresh.tangents,
              fresh.newton_iterations);
}

// Results users can trust: a reduced run's every report is the same to the bit on 1 and 2 threads
// (the kept points' force and tangent are summed chunk by chunk in a fixed order, and each chunk's
// product, Eigen's or BLAS's, runs on one thread). Every effect, one trial.
TEST(ReducedModel, AReducedRunIsBitIdenticalForAnyThreadCount) {
  const auto bm = build_model(small_scene({"load.trials=1"}));
  Record one, two;
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 1);
    one = rom_run(*bm, offline().basis);
  }
  {
    tbb::global_control c(tbb::global_control::max_allowed_parallelism, 2);
    two = rom_run(*bm, offline().basis);
  }
  ASSERT_EQ(one.angle.size(), two.angle.size());
  for (std::size_t i = 0; i < one.angle.size(); ++i) EXPECT_EQ(one.angle[i], two.angle[i]) << "report " << i;
  EXPECT_GT(*std::max_element(one.angle.begin(), one.angle.end()), 5.0);  // the run bends (8.4 deg; not a vacuous comparison)
}

// Every effect of the story together, three trials. The tolerances are the targets (0.5 deg,
// 0.5 NRMSE points); the drift of the top angle (trial 1 -> 3, ~1 deg here) within 25 %: the 1-dof
// path model's Galerkin balance overestimated it ~2x, which this catches.
TEST(ReducedModel, FollowsTheFemThroughMullinsFatigueAndCreep) { expect_follows_fem({"load.trials=3"}, 0.5, 0.5, 0.25); }

TEST(ReducedModel, FollowsTheFemForEachEffectAlone) {
  // Each alone over two trials (creep over one: it recovers between trials).
  expect_follows_fem({"load.trials=1", "materials.silicone.mullins.enabled=false", "materials.silicone.fatigue.enabled=false"}, 0.5, 0.5, 0.0);
  expect_follows_fem({"load.trials=2", "materials.silicone.viscoelastic.enabled=false", "materials.silicone.fatigue.enabled=false"}, 0.5, 0.5, 0.25);
  expect_follows_fem({"load.trials=2", "materials.silicone.viscoelastic.enabled=false", "materials.silicone.mullins.enabled=false"}, 0.5, 0.5, 0.25);
}

// ---- Enrichment from FEM snapshots of a damaged trial.

/// The largest |ROM - FEM| over the reports of `fem` and `rom` (same reports).
double largest_difference(const Record& fem, const Record& rom) {
  EXPECT_EQ(fem.angle.size(), rom.angle.size());
  double worst = 0.0;
  for (std::size_t i = 0; i < std::min(fem.angle.size(), rom.angle.size()); ++i)
    worst = std::max(worst, std::abs(fem.angle[i] - rom.angle[i]));
  return worst;
}

// Fatigue alone over three trials with the paper's 16 s holds (the drift is then ~0.7 deg at
// 45 kPa). In the FEM a damaged point stretches more, which damages it faster; the softening
// responses of the basis hold that local feedback only to first order, so the reduced model's
// drift falls behind (measured 0.108 deg at trial 3's top, 8 % of the drift). A basis that also
// takes the reports of ONE FEM trial, run with other fatigue constants (lambda_th 1.7 instead of
// 1.6: the snapshots do not contain the answer), follows it within 0.015 deg (measured). Bounds:
// 0.04 deg (the measured error with a margin for other compilers and thread counts; still 2.7x
// below the plain basis's error) and at most half the plain basis's error.
TEST(ReducedModel, SnapshotsOfOneDamagedTrialCarryTheFatigueFeedback) {
  const std::vector<std::string>& fatigue = kFatigue;
  const auto& bm = fatigue_case().bm;
  std::vector<std::string> other = fatigue;
  other.push_back("materials.silicone.fatigue.lambda_th=1.7");
  other.push_back("load.trials=1");
  const auto snap_bm = build_model(small_scene(other));
  std::vector<Eigen::VectorXd> snapshots;
  {
    Assembler A(snap_bm->model);
    QuasiStaticRun run(A, snap_bm->solver.quasi_static);
    run.run(snap_bm->load, [&](const StateRecord&, const Eigen::VectorXd& u, const std::vector<double>&) { snapshots.push_back(u); });
  }
  ASSERT_GE(snapshots.size(), 10u);
  const ReducedBasis enriched = build_reduced_basis(offline().ref->model, offline().trace, RomBasisOptions{}, snapshots);
  EXPECT_GT(enriched.num_modes(), offline().basis.num_modes()) << "the snapshots add modes of their own";
  const Record& fem = fatigue_case().fem;
  const double plain = largest_difference(fem, rom_run(*bm, offline().basis));
  const double with_snapshots = largest_difference(fem, rom_run(*bm, enriched));
  EXPECT_GT(fem.angle.back() - fem.angle[fem.angle.size() / 3 - 1], 0.3) << "fatigue drifts the top angle (not a vacuous test)";
  EXPECT_LE(with_snapshots, 0.04);
  EXPECT_LE(with_snapshots, 0.5 * plain) << "plain basis " << plain << " deg";
}

// RomBasisOptions::ecsw_blocks. ECSW per softening cluster keeps nearly every element of a small
// cluster (it must reproduce each cluster's force in every mode); one block per region keeps fewer
// and integrates each region's force within the same tolerance. The fatigue case's three trials:
// the hyper-reduction's share of the error against the FEM stays small beside the basis's own
// (the plain basis: 0.108 deg at trial 3's top). Measured: 498 kept elements per cluster, 197 per
// region (of 770 soft), 0.1077 / 0.1229 deg from the FEM. Bound: the blocks' error within 0.03 deg
// of the clusters' (2x the measured 0.015).
TEST(ReducedModel, EcswBlocksPerRegionKeepFewerElementsAndFollowTheFem) {
  RomBasisOptions opt;
  opt.ecsw_blocks = 1;
  const ReducedBasis blocks = build_reduced_basis(offline().ref->model, offline().trace, opt);
  const ReducedBasis& clusters = offline().basis;
  ASSERT_EQ(blocks.num_modes(), clusters.num_modes()) << "the same modes: only the sampling differs";
  const Record& fem = fatigue_case().fem;
  const auto& bm = fatigue_case().bm;
  const double e_clusters = largest_difference(fem, rom_run(*bm, clusters));
  const double e_blocks = largest_difference(fem, rom_run(*bm, blocks));
  std::printf("kept elements: %zu per cluster, %zu per region (of %d soft); |ROM - FEM| %.4f / %.4f deg\n", clusters.elements.size(),
              blocks.elements.size(), clusters.info.soft_elements, e_clusters, e_blocks);
  EXPECT_LT(blocks.elements.size(), clusters.elements.size());
  EXPECT_LE(blocks.info.ecsw_worst_residual, opt.ecsw_tolerance * (1.0 + 1e-9));
  EXPECT_LE(std::abs(e_blocks - e_clusters), 0.03);
}

// RomBasisOptions::galerkin_theta_row (the theta row tested with the path tangent instead of the
// angle's influence vector; an experiment's option, bench_rom --galerkin-theta). On the path (q = 0)
// the theta row is (p_el - p) x (test . g) for either test vector, so the elastic reference is
// reproduced as well (the same 5e-3 deg as ReproducesTheElasticReference). Off the path, with the
// default basis, the Galerkin row is what the header says the influence vector fixes: it overstates
// a softening. Measured on three fatigue trials: 0.219 deg off the FEM against 0.013 deg (17x);
// bound: at least 2x, the header's "about twofold". (With a basis rich in damaged states the
// Galerkin row can be the closer one: bench/results/rom_h6_ceiling.)
TEST(ReducedModel, AGalerkinThetaRowReproducesTheElasticReferenceButOverstatesFatigue) {
  RomBasisOptions opt;
  opt.galerkin_theta_row = true;
  const ReducedBasis galerkin = build_reduced_basis(offline().ref->model, offline().trace, opt);
  const auto elastic = build_model(small_scene(kElastic));
  const Record fem = fem_run(*elastic), rom = rom_run(*elastic, galerkin);
  ASSERT_EQ(fem.angle.size(), rom.angle.size());
  for (std::size_t i = 0; i < fem.angle.size(); ++i) EXPECT_NEAR(rom.angle[i], fem.angle[i], 5e-3) << "report " << i;
  const auto fatigue = build_model(small_scene({"load.trials=3", "materials.silicone.mullins.enabled=false",
                                                "materials.silicone.viscoelastic.enabled=false"}));
  const Record fem_f = fem_run(*fatigue);
  const double petrov = largest_difference(fem_f, rom_run(*fatigue, offline().basis));
  const double gal = largest_difference(fem_f, rom_run(*fatigue, galerkin));
  std::printf("three fatigue trials, largest |ROM - FEM|: Petrov-Galerkin row %.4f deg, Galerkin row %.4f deg\n", petrov, gal);
  EXPECT_GT(gal, 2.0 * petrov) << "the Galerkin row overstates the softening with the default basis";
}

// The reduced Jacobian against central differences of the residual at a state off the path
// (theta between two samples, q of the given amplitude, lambda 0.1): every column within 1e-4 of
// |J| (steps 1e-6 deg, 1e-9 m, 1e-6: truncation and round-off both below that).
void expect_jacobian_matches_finite_differences(const Model& reference, const ReducedBasis& basis, const Model& model,
                                                double amplitude) {
  const ReducedOrderModel rom(reference, basis, model);
  ReducedCoordinates z;
  const int k = basis.num_samples() / 2;
  z.theta = 0.5 * (basis.theta[k] + basis.theta[k + 1]);
  z.q = Eigen::VectorXd::Zero(rom.num_modes());
  for (int j = 0; j < z.q.size(); ++j) z.q[j] = amplitude * std::cos(1.3 * j + 0.4);
  z.lambda = 0.1;
  const std::vector<double> h0 = rom.initial_history();
  std::vector<double> h1(h0.size());
  const double p = basis.p[k];
  const TimeStep ts{1.0, 0.5};
  Eigen::MatrixXd J;
  rom.residual(z, p, ts, h0, h1, &J);
  const int n = static_cast<int>(J.cols());
  ASSERT_EQ(n, rom.num_modes() + 2);
  for (int c = 0; c < n; ++c) {
    const double h = c == 0 ? 1e-6 * std::max(1.0, std::abs(z.theta)) : c <= rom.num_modes() ? 1e-9 : 1e-6;
    ReducedCoordinates zp = z, zm = z;
    auto bump = [&](ReducedCoordinates& y, double s) {
      if (c == 0) y.theta += s;
      else if (c <= rom.num_modes()) y.q[c - 1] += s;
      else y.lambda += s;
    };
    bump(zp, h);
    bump(zm, -h);
    const Eigen::VectorXd d = (rom.residual(zp, p, ts, h0, h1, nullptr) - rom.residual(zm, p, ts, h0, h1, nullptr)) / (2 * h);
    EXPECT_LE((d - J.col(c)).norm(), 1e-4 * J.norm()) << "column " << c;
  }
}

// Tangent-free modes (RomBasisOptions::tangent_free_modes): the modes are made mass-orthogonal to
// every tangent of the path, so the reduced equations carry no gauge (ReducedBasis::gauge all zero,
// the multiplier's row lambda = 0). Checked: the modes hold less than 1e-4 of any sample tangent's
// mass norm squared (the tangents' POD leaves 1e-6 of their energy; the default basis holds 0.26-0.42
// on the h = 6 story, so the bound cannot pass by accident), the Jacobian without the gauge matches
// finite differences (bound as in ReducedJacobian), the elastic reference is reproduced (5e-3 deg as
// the other bases), and three fatigue trials stay within 2x the gauge basis's error (measured
// 2026-11-29: 0.0147 against 0.0126 deg; the basis gives up the modes' parts along the tangents,
// which must not cost the drift).
TEST(ReducedModel, TangentFreeModesNeedNoGaugeAndFollowTheFem) {
  RomBasisOptions opt;
  opt.tangent_free_modes = true;
  const Offline& o = offline();
  const ReducedBasis tf = build_reduced_basis(o.ref->model, o.trace, opt);
  ASSERT_GT(tf.num_modes(), 0);
  EXPECT_TRUE(tf.gauge.isZero(0.0));
  const Eigen::VectorXd mass = Assembler(o.ref->model).lumped_mass();  // a copy: the Assembler is a temporary
  const double m_tot = mass.sum();
  for (int k = 1; k < tf.num_samples(); ++k) {
    const Eigen::VectorXd t = tf.dU.col(k);
    double held = 0.0;
    for (int j = 0; j < tf.num_modes(); ++j) held += std::pow(mass_dot(mass, tf.Phi.col(j), t), 2) / m_tot;
    EXPECT_LT(held / mass_dot(mass, t, t), 1e-4) << "sample " << k;
  }
  const auto one = build_model(small_scene({"load.trials=1"}));
  {
    const ReducedOrderModel rom(o.ref->model, tf, one->model);
    ReducedCoordinates z;
    z.q = Eigen::VectorXd::Zero(rom.num_modes());
    z.lambda = 0.1;
    const std::vector<double> h0 = rom.initial_history();
    std::vector<double> h1(h0.size());
    EXPECT_EQ(rom.residual(z, tf.p[1], TimeStep{1.0, 0.5}, h0, h1, nullptr)[rom.num_modes() + 1], z.lambda) << "the row lambda = 0";
  }
  expect_jacobian_matches_finite_differences(o.ref->model, tf, one->model, 2e-5);
  const auto elastic = build_model(small_scene(kElastic));
  const Record fem = fem_run(*elastic), rom = rom_run(*elastic, tf);
  ASSERT_EQ(fem.angle.size(), rom.angle.size());
  for (std::size_t i = 0; i < fem.angle.size(); ++i) EXPECT_NEAR(rom.angle[i], fem.angle[i], 5e-3) << "report " << i;
  const auto fatigue = build_model(small_scene({"load.trials=3", "materials.silicone.mullins.enabled=false",
                                                "materials.silicone.viscoelastic.enabled=false"}));
  const Record fem_f = fem_run(*fatigue);
  const double gauge = largest_difference(fem_f, rom_run(*fatigue, o.basis));
  const double free = largest_difference(fem_f, rom_run(*fatigue, tf));
  std::printf("three fatigue trials, largest |ROM - FEM|: gauge basis %.4f deg, tangent-free %.4f deg\n", gauge, free);
  EXPECT_LE(free, 2.0 * gauge);
}

// Softened equilibria instead of FEM snapshots (RomBasisOptions::softened_levels): the same
// fatigue case, with a basis that has seen no run with history at all, only static equilibria of
// the elastic reference with its most strained elements softened. Measured (bench_rom,
// 2026-11-27): the trial-3 error falls from 0.108 deg (plain) to 0.040 deg (6 levels), the kept
// points' fatigue damage deficit from -11 % to a few %. Bounds: 0.06 deg (the measurement with a
// margin for compilers and thread counts) and at most 0.6 x the plain basis's error. The same
// basis must also survive the vent between trials: without starting a release from rest, this
// basis stopped at theta = -1.5 deg at 0 kPa and stayed on that branch (12 deg off in trial 3).
TEST(ReducedModel, SoftenedEquilibriaCarryTheFatigueFeedback) {
  const auto& bm = fatigue_case().bm;
  const ReducedBasis& softened = softened_basis();
  EXPECT_GT(softened.num_modes(), offline().basis.num_modes()) << "the softened equilibria add modes of their own";
  const Record& fem = fatigue_case().fem;
  const double plain = largest_difference(fem, rom_run(*bm, offline().basis));
  const Record rom = rom_run(*bm, softened);
  const double with_softened = largest_difference(fem, rom);
  EXPECT_GT(fem.angle.back() - fem.angle[fem.angle.size() / 3 - 1], 0.3) << "fatigue drifts the top angle (not a vacuous test)";
  EXPECT_LE(with_softened, 0.06);
  EXPECT_LE(with_softened, 0.6 * plain) << "plain basis " << plain << " deg";
  for (std::size_t i = 0; i < rom.angle.size(); ++i) {
    if (std::abs(fem.angle[i]) < 0.01) {
      EXPECT_GE(rom.angle[i], -0.01) << "report " << i << " at rest after a vent";
    }
  }
}

// The corrected history (ReplayOptions::corrected_at) sees the drift that the Newton-step check
// cannot: the same fatigue case, plain basis (0.108 deg behind the FEM at trial 3's top, measured;
// 8 % of the drift). The Newton step measures the reduced state against the full equilibrium for
// the reduced run's OWN history (and one step from it, with the fatigue law's rate terms in the
// tangent, overshoots: measured 1.1 deg at trial 3's top); the corrected history is built by the
// full model along the corrected states. Measured (2026-11-27): corrected at every loaded report,
// the reduced angle minus the estimate is within 0.016 deg of the FEM at every report (the rest is
// the history between reports, taken along the held correction); corrected at the top hold's two
// reports only (what simulate's check does), the estimate there is 0.096 / 0.070 deg against the
// actual 0.108 / 0.078 at trial 3. Bounds: 0.03 deg and 0.3 x the error for every report (the
// measurement with a margin for compilers and thread counts); at the tops, within 30 % of the
// error in trials 2-3, where it is more than 0.03 deg.
TEST(ReducedModel, CorrectedHistorySeesTheFatigueDriftTheNewtonCheckMisses) {
  const auto& bm = fatigue_case().bm;
  const Record& fem = fatigue_case().fem;
  const ReducedOrderModel rom(offline().ref->model, offline().basis, bm->model);
  ReducedRun run(rom, bm->solver.quasi_static);
  std::vector<double> angle;
  run.run(bm->load, [&](const StateRecord& s, const ReducedCoordinates&, const Eigen::VectorXd&) { angle.push_back(s.angle_deg); });
  ASSERT_EQ(angle.size(), fem.angle.size());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  // The estimates at every report, NaN where not checked.
  auto estimates = [&](const std::function<bool(const ReducedStep&)>& corrected_at, std::vector<double>* newton) {
    std::vector<double> corrected(angle.size(), nan);
    ReplayOptions opt;
    opt.corrected_at = corrected_at;
    if (newton) opt.newton_at = corrected_at;
    opt.newton = bm->solver.quasi_static.newton;
    replay_reduced_run(rom, run.trajectory(), [&](const ReducedStep& s, const Eigen::VectorXd&, const std::vector<double>&,
                                                  const ReducedCheck& c) {
      corrected[static_cast<std::size_t>(s.report)] = c.corrected_angle_error_deg;
      if (newton) (*newton)[static_cast<std::size_t>(s.report)] = c.newton_angle_error_deg;
    }, opt);
    return corrected;
  };
  std::vector<double> newton(angle.size(), nan);
  const std::vector<double> every = estimates([](const ReducedStep& s) { return s.pressure_Pa > 0.0; }, &newton);
  const std::vector<double> tops = estimates([](const ReducedStep& s) { return s.pressure_Pa > 44e3; }, nullptr);
  double actual = 0.0, newton_off = 0.0, every_off = 0.0;
  for (std::size_t i = 0; i < angle.size(); ++i) {
    const double e = angle[i] - fem.angle[i];
    actual = std::max(actual, std::abs(e));
    if (fem.angle[i] < 0.01) continue;  // unloaded: not checked
    ASSERT_FALSE(std::isnan(every[i])) << "report " << i << ": the corrected solve converges";
    every_off = std::max(every_off, std::abs(e - every[i]));
    newton_off = std::max(newton_off, std::abs(e - newton[i]));
    if (!std::isnan(tops[i]) && fem.trial[i] > 1 && std::abs(e) > 0.03) {
      EXPECT_NEAR(tops[i], e, 0.3 * std::abs(e)) << "top report " << i << " of trial " << fem.trial[i];
    }
  }
  EXPECT_GT(actual, 0.05) << "the plain basis falls behind the FEM's drift (not a vacuous test)";
  EXPECT_LE(every_off, 0.03) << "actual error " << actual << " deg";
  EXPECT_LE(every_off, 0.3 * actual) << "actual error " << actual << " deg";
  EXPECT_LT(every_off, newton_off) << "the corrected history sees more than one Newton step with the run's own history";
}

// The corrected history fed back into the run (corrected_history_in_run): the same fatigue case and
// plain basis as above, the full model's correction taken at the top hold's reports of every trial.
// The kept points then integrate the history along the corrected trajectory, and the reduced run
// follows the FEM's drift where its own history lags. Measured (2026-11-29): the largest error over
// the three trials' reports falls from 0.108 deg (plain, trial 3's top) to 0.016 deg (0.15x; six
// checks, all converged). Bound: 0.3x, twice the measurement, for compilers and thread counts.
TEST(ReducedModel, CorrectedHistoryInTheRunFollowsTheFatigueDrift) {
  const auto& bm = fatigue_case().bm;
  const Record& fem = fatigue_case().fem;
  const ReducedOrderModel rom(offline().ref->model, offline().basis, bm->model);
  int checks = 0, failed = 0;
  auto angles = [&](bool corrected) {
    ReducedRun run(rom, bm->solver.quasi_static);
    if (corrected)
      run.set_history_corrector(corrected_history_in_run(
          rom, [](const ReducedStep& s) { return s.report >= 0 && s.pressure_Pa > 44e3; }, bm->solver.quasi_static.newton,
          [&](const ReducedStep&, bool converged) { ++checks, failed += converged ? 0 : 1; }));
    std::vector<double> angle;
    run.run(bm->load, [&](const StateRecord& s, const ReducedCoordinates&, const Eigen::VectorXd&) { angle.push_back(s.angle_deg); });
    return angle;
  };
  const std::vector<double> plain = angles(false), fed = angles(true);
  ASSERT_EQ(plain.size(), fem.angle.size());
  ASSERT_EQ(fed.size(), fem.angle.size());
  double plain_worst = 0.0, fed_worst = 0.0;
  for (std::size_t i = 0; i < fem.angle.size(); ++i) {
    plain_worst = std::max(plain_worst, std::abs(plain[i] - fem.angle[i]));
    fed_worst = std::max(fed_worst, std::abs(fed[i] - fem.angle[i]));
  }
  std::printf("worst: plain %.4f, fed %.4f deg; checks %d\n", plain_worst, fed_worst, checks);
  EXPECT_GT(plain_worst, 0.05) << "the plain basis falls behind the FEM's drift (not a vacuous test)";
  EXPECT_EQ(failed, 0) << "every check converged (of " << checks << ")";
  EXPECT_LE(fed_worst, 0.3 * plain_worst);
}

/// The isochoric part of a material scaled by s (written here from the definition in engine/rom.h,
/// not taken from the library, so the test checks softened_states against the model it claims).
class IsochoricTimes final : public Material {
 public:
  IsochoricTimes(MaterialPtr base, double s) : base_(std::move(base)), s_(s) {}
  std::string name() const override { return "isochoric_times(" + base_->name() + ")"; }
  void evaluate(std::span<const Mat3> F, const TimeStep& step, std::span<const double> so, std::span<double> sn,
                std::span<PointResponse> out, bool tangent) const override {
    base_->evaluate(F, step, so, sn, out, tangent);
    for (PointResponse& r : out) {
      r.psi_iso *= s_;
      r.P_iso *= s_;
      if (tangent) r.A_iso *= s_;
    }
  }
  double initial_shear_modulus() const override { return s_ * base_->initial_shear_modulus(); }
  double initial_bulk_modulus() const override { return base_->initial_bulk_modulus(); }

 private:
  MaterialPtr base_;
  double s_;
};

// The softened equilibria are static solves of the softened reference: none for no levels; with two
// levels to 0.6, the first state of the uniform field (m = 0) is the equilibrium at the sample's
// pressure of the reference whose soft parts' isochoric stress is scaled by 1 - 0.3 (bin 8 of 16,
// exact): Newton started from it on that model takes no iteration (|R| within the solver's relative
// tolerance), while on the unsoftened reference it is far from equilibrium (not a vacuous check).
TEST(ReducedModel, SoftenedStatesAreEquilibriaOfTheSoftenedReference) {
  const Offline& o = offline();
  EXPECT_TRUE(softened_states(o.ref->model, o.trace, {10}, 0, 0.9).empty());
  const std::vector<Eigen::VectorXd> s = softened_states(o.ref->model, o.trace, {10}, 2, 0.6);
  ASSERT_FALSE(s.empty());
  // Softer walls bend further at the same pressure: every state's angle exceeds the path's there.
  const double path_angle = bending_angle(o.ref->model, o.trace.u[10]).angle_deg;
  for (const Eigen::VectorXd& u : s) EXPECT_GT(bending_angle(o.ref->model, u).angle_deg, path_angle);
  // The softened model: the fabric (100x stiffer than the silicone, engine/rom.h) is never softened.
  Model soft = o.ref->model;
  double softest = INFINITY;
  for (const Part& p : soft.parts) softest = std::min(softest, p.material->initial_shear_modulus());
  for (Part& p : soft.parts)
    if (p.material->initial_shear_modulus() < 100.0 * softest) p.material = std::make_shared<IsochoricTimes>(p.material, 0.7);
  const double p_Pa = o.trace.p_Pa[10];
  Eigen::VectorXd u = s[0];
  const NewtonReport on_softened = StaticSolver(Assembler(soft)).solve(p_Pa, TimeStep{}, {}, {}, u);
  EXPECT_TRUE(on_softened.converged) << on_softened.failure;
  EXPECT_EQ(on_softened.iterations, 0) << "|R| " << on_softened.residual_N << " N of " << on_softened.reference_N;
  Eigen::VectorXd v = s[0];
  const NewtonReport on_reference = StaticSolver(Assembler(o.ref->model)).solve(p_Pa, TimeStep{}, {}, {}, v);
  EXPECT_GT(on_reference.iterations, 0);
}

// ---- An effect the reduced model has never heard of: registered only through damage/registry.h.

/// Peak-energy softening: P = eta(W_max) P_base with eta = 1 - a W_max / (W_max + c), W_max the
/// largest isochoric energy the point has seen (its one history variable). While loading
/// (W = W_max), eta depends on W only, so the tangent eta A + eta'(W) P (x) P is symmetric and exact.
class PeakEnergySoftening final : public Material {
 public:
  PeakEnergySoftening(MaterialPtr base, double a, double c_Pa) : base_(std::move(base)), a_(a), c_(c_Pa) {}
  std::string name() const override { return "peak_energy_softening(" + base_->name() + ")"; }
  int state_size() const override { return base_->state_size() + 1; }
  void init_state(std::span<double> s) const override {
    const int nb = base_->state_size();
    const std::size_t n = s.size() / static_cast<std::size_t>(nb + 1);
    for (std::size_t i = 0; i < n; ++i) {
      base_->init_state(s.subspan(i * (nb + 1), static_cast<std::size_t>(nb)));
      s[i * (nb + 1) + nb] = 0.0;
    }
  }
  void evaluate(std::span<const Mat3> F, const TimeStep& step, std::span<const double> so, std::span<double> sn,
                std::span<PointResponse> out, bool tangent) const override {
    const std::size_t nb = static_cast<std::size_t>(base_->state_size()), stride = nb + 1;
    for (std::size_t i = 0; i < F.size(); ++i) {
      const bool has = !so.empty();
      base_->evaluate(F.subspan(i, 1), step, has ? so.subspan(i * stride, nb) : so, has ? sn.subspan(i * stride, nb) : sn,
                      out.subspan(i, 1), tangent);
      PointResponse& r = out[i];
      const double old = has ? so[i * stride + nb] : 0.0;
      const double W = r.psi_iso, Wm = std::max(old, W);
      if (has) sn[i * stride + nb] = Wm;
      const double eta = 1.0 - a_ * Wm / (Wm + c_);
      if (tangent) {
        r.A_iso *= eta;
        if (W >= old) r.A_iso -= a_ * c_ / ((W + c_) * (W + c_)) * flatten(r.P_iso) * flatten(r.P_iso).transpose();
      }
      r.P_iso *= eta;
      r.psi_iso *= eta;  // reported energy only (the potential of the loading branch is not needed)
    }
  }
  double initial_shear_modulus() const override { return base_->initial_shear_modulus(); }
  double initial_bulk_modulus() const override { return base_->initial_bulk_modulus(); }
  bool is_split() const override { return base_->is_split(); }

 private:
  MaterialPtr base_;
  double a_, c_;
};

void register_peak_energy_softening() {
  static const bool done = [] {
    MaterialEffect e;
    e.name = "peak_energy_softening";
    e.doc = "test: softening by the peak isochoric energy, P -> (1 - a W_max / (W_max + c)) P";
    e.params = {{"a", "1", "largest softened fraction", 0.2, 0.0, 0.9, false},
                {"c_MPa", "MPa", "energy of half the softening", 0.02, 0.001, 1.0, true}};
    e.decorate = [](MaterialPtr base, const std::map<std::string, double>& v) {
      return std::make_shared<const PeakEnergySoftening>(std::move(base), v.at("a"), v.at("c_MPa") * 1e6);
    };
    e.order = 5;
    register_material_effect(e);
    return true;
  }();
  (void)done;
}

// The effect softens the walls ~12 % from the first loading on, which pushes the 45 kPa step of
// this actuator towards its limit point (14.0 deg against the elastic 9.2 deg). With the linear
// responses alone (the plain basis): every level below 45 kPa within 0.035 deg, the 45 kPa step
// 0.23 deg under the FEM, the trials' NRMSE 0.81 and 0.82 points under the FEM's (16.8 %, 18.1 %),
// whatever the basis size (8-64 modes), mode samples, clusters or hyper-reduction. With the softened
// equilibria (solver.reduced_softened_levels = 6) measured 0.090 deg and 0.28 / 0.23 points: the issue's
// targets (0.5 deg, 0.5 points) hold, and are the tolerances.
TEST(ReducedModel, FollowsTheFemForAnEffectKnownOnlyToTheRegistry) {
  register_peak_energy_softening();
  expect_follows_fem({"load.trials=2", "materials.silicone.viscoelastic.enabled=false", "materials.silicone.mullins.enabled=false",
                      "materials.silicone.fatigue.enabled=false", "materials.silicone.peak_energy_softening.enabled=true",
                      "materials.silicone.peak_energy_softening.a=0.15"},
                     0.5, 0.5, 0.25, &softened_basis());
}

// ------------------------------------------------------------------ Jacobian, storage, bad input

/// The analytic Jacobian (q columns) and the theta column's difference against central differences
/// of the residual, at a state off the path with damaged history. Step: 1e-6 of the coordinate's
/// scale; truncation ~1e-12 relative, round-off ~1e-10 / 1e-6: tolerance 1e-4 of the Jacobian's norm.
// The follower load's second order in q (ReducedBasis::pq, pw) against the full mesh's load: the
// load is quadratic in the positions, so [g(u + d) + g(u - d)] / 2 - g(u) = g2[d, d] / 2 exactly at
// any u (the symmetric difference has no truncation error for a quadratic). Tolerance 1e-9 of the
// term: round-off of assemblies whose entries are ~1e3 times the term (d is a fraction of u).
TEST(ReducedModel, FollowerLoadSecondOrderMatchesTheFullMesh) {
  const Offline& o = offline();
  const ReducedBasis& B = o.basis;
  const Assembler A(o.ref->model);
  const int r = B.num_modes();
  ASSERT_GT(r, 0);
  const Eigen::Index nd = B.dofs();
  auto load = [&](const Eigen::VectorXd& u) {
    Eigen::VectorXd f = Eigen::VectorXd::Zero(nd);
    A.add_pressure(u, 1.0, f, nullptr);
    A.zero_fixed(f);
    return f;
  };
  for (int k : {B.num_samples() / 3, B.num_samples() - 2}) {
    Eigen::VectorXd q(r);
    for (int j = 0; j < r; ++j) q[j] = 3e-4 * std::cos(0.7 * j + 0.2 * k);
    const Eigen::VectorXd u = B.U.col(k), d = B.Phi * q;
    const Eigen::VectorXd half_g2 = 0.5 * (load(u + d) + load(u - d)) - load(u);
    Eigen::VectorXd qq(static_cast<Eigen::Index>(r) * r);
    for (int l = 0; l < r; ++l) qq.segment(static_cast<Eigen::Index>(r) * l, r) = q[l] * q;
    const Eigen::VectorXd want_q = B.Phi.transpose() * half_g2;
    const Eigen::VectorXd got_q = 0.5 * B.pq * qq;
    ASSERT_GT(want_q.norm(), 0.0);
    EXPECT_LE((got_q - want_q).norm(), 1e-9 * want_q.norm()) << "sample " << k;
    const double want_w = B.W.col(k).dot(half_g2), got_w = 0.5 * B.pw.col(k).dot(qq);
    EXPECT_NEAR(got_w, want_w, 1e-9 * std::abs(want_w) + 1e-12 * want_q.norm()) << "sample " << k;
  }
}

// The stiff parts in the bracket (RomBasisOptions::stiff_parts, engine/rom.h). Without hyper-
// reduction, at a path sample (where every splined operator is its sample's value), the reduced
// residual is the exact projection of the full residual, T^T R(u_el + Phi q) with T = [w, Phi]:
// E + P is the projection of the reference's residual to second order in q plus the load's exact
// second order, and the bracket adds the internal force's remainder of every element it keeps.
// With the fabric linear (the default), the fabric's remainder is missing; with it exact, the two
// agree to the trace's equilibrium tolerance. Checked against the full mesh's residual (assembled
// by Assembler, independent of the reduced arithmetic) at two samples, q a large correction of this
// small actuator (5e-5 m; 1e-4 inverts an element). Measured (2026-11-29), relative to the part of
// the residual the correction drives: exact 1e-9 / 2e-10 (q rows) and 1e-8 / 8e-10 (theta row) at
// the two samples; linear 3.9e-3 / 3.4e-3 and 1.7e-2 / 0.17 (the theta row, which sets the angle,
// 17 % off near the top). Bounds 1e-6 (the trace's Newton tolerance leaves an equilibrium residual
// of ~1e-9 of the load) and the linear q rows at least 100 x the exact ones (so the fabric's
// remainder is real here and the agreement not vacuous). The sampled fabric (ECSW at 1e-2 on the
// remainder, trained on other states than these): measured 2.4e-5 / 3.2e-6 (q rows) and
// 5.1e-3 / 1.3e-4 (theta row), 160-1000x and 3.4-1300x closer than the linear fabric; bounds 0.1x
// and 0.5x the linear fabric's (the weights are fitted to 1e-2 on their training states only).
TEST(ReducedModel, StiffPartsInTheBracketMakeTheUnsampledResidualTheExactProjection) {
  const Offline& o = offline();
  const Assembler A(o.ref->model);
  RomBasisOptions exact_opt;
  exact_opt.hyper_reduce = false;
  exact_opt.stiff_parts = RomBasisOptions::StiffParts::exact;
  RomBasisOptions linear_opt = exact_opt;
  linear_opt.stiff_parts = RomBasisOptions::StiffParts::linear;
  const ReducedBasis exact = build_reduced_basis(o.ref->model, o.trace, exact_opt);
  const ReducedBasis linear = build_reduced_basis(o.ref->model, o.trace, linear_opt);
  RomBasisOptions sampled_opt = exact_opt;
  sampled_opt.stiff_parts = RomBasisOptions::StiffParts::sampled;
  const ReducedBasis sampled = build_reduced_basis(o.ref->model, o.trace, sampled_opt);
  ASSERT_GT(sampled.elements.size(), linear.elements.size()) << "some fabric elements are sampled";
  ASSERT_LT(sampled.elements.size(), exact.elements.size()) << "not all of them";
  ASSERT_GT(exact.elements.size(), linear.elements.size()) << "the fabric's elements are kept";
  const int r = exact.num_modes();
  ASSERT_EQ(r, linear.num_modes());
  const Eigen::Index nd = exact.dofs();
  auto full = [&](const Eigen::VectorXd& u, double p) {
    Eigen::VectorXd f = Eigen::VectorXd::Zero(nd), fp = Eigen::VectorXd::Zero(nd);
    A.internal(u, TimeStep{}, {}, {}, &f, nullptr, nullptr);
    A.add_pressure(u, p, fp, nullptr);
    Eigen::VectorXd R = f - fp;
    A.zero_fixed(R);
    return R;
  };
  const ReducedOrderModel rom_exact(o.ref->model, exact, o.ref->model), rom_linear(o.ref->model, linear, o.ref->model),
      rom_sampled(o.ref->model, sampled, o.ref->model);
  for (int k : {exact.num_samples() / 3, exact.num_samples() - 3}) {
    ReducedCoordinates z;
    z.theta = exact.theta[k];
    z.q = Eigen::VectorXd(r);
    for (int j = 0; j < r; ++j) z.q[j] = 5e-5 * std::cos(0.9 * j + 0.3 * k);
    const double p = 0.9 * exact.p[k];  // off equilibrium, so the pressure terms count too
    const Eigen::VectorXd u = rom_exact.displacement(z);
    const Eigen::VectorXd R = full(u, p), R0 = full(exact.U.col(k), p);
    Eigen::VectorXd want(r + 1), driven(r + 1);
    want[0] = exact.W.col(k).dot(R);
    want.tail(r) = exact.Phi.transpose() * R;
    driven[0] = exact.W.col(k).dot(R - R0);
    driven.tail(r) = exact.Phi.transpose() * (R - R0);
    std::vector<double> h;
    const Eigen::VectorXd got_exact = rom_exact.residual(z, p, TimeStep{}, {}, h, nullptr).head(r + 1);
    const Eigen::VectorXd got_linear = rom_linear.residual(z, p, TimeStep{}, {}, h, nullptr).head(r + 1);
    const Eigen::VectorXd got_sampled = rom_sampled.residual(z, p, TimeStep{}, {}, h, nullptr).head(r + 1);
    // Rows in their own units (theta row: w is per degree): compare each block relative to its part
    // driven by q.
    auto rel = [&](const Eigen::VectorXd& got, Eigen::Index i, Eigen::Index n) {
      return (got.segment(i, n) - want.segment(i, n)).norm() / driven.segment(i, n).norm();
    };
    const double exact_q = rel(got_exact, 1, r), linear_q = rel(got_linear, 1, r);
    const double exact_w = rel(got_exact, 0, 1), linear_w = rel(got_linear, 0, 1);
    const double sampled_q = rel(got_sampled, 1, r), sampled_w = rel(got_sampled, 0, 1);
    std::printf("sample %d: q rows off by %.2e (exact) / %.2e (sampled) / %.2e (linear), theta row %.2e / %.2e / %.2e of the "
                "q-driven part\n", k, exact_q, sampled_q, linear_q, exact_w, sampled_w, linear_w);
    EXPECT_LE(exact_q, 1e-6) << "sample " << k << "; linear fabric " << linear_q;
    EXPECT_LE(exact_w, 1e-6) << "sample " << k << "; linear fabric " << linear_w;
    EXPECT_GE(linear_q, 100.0 * exact_q) << "sample " << k << ": the fabric's remainder is not vacuous here";
    EXPECT_LE(sampled_q, 0.1 * linear_q) << "sample " << k;
    EXPECT_LE(sampled_w, 0.5 * linear_w) << "sample " << k;
  }
}

// The reduced cavity volume is V + b.q + q^T H q / 2 (ReducedOrderModel::cavity_volume): its error
// against the full mesh's volume of the same displacement is third order in q, so halving q cuts
// it ~8x (a first-order volume: ~4x). Checked at two amplitudes, with the ratio's bound 6 (between
// 4 and 8: the spline of H between samples adds a small second-order part).
// RomBasisOptions::release_responses. After a zero-time release a relaxing (Prony) material holds a
// frozen stress, the path's stress history weighted by a kernel of time; the released state is the
// unloaded body's response to it, a small self-equilibrated shape that neither the loaded softening
// responses nor the softened equilibria contain. The release responses are those shapes, so the
// FEM's released state (trial 2's first report, 0 kPa, of a creep-only run without gravity) should
// lie in the basis's span. Measured on the small model: the share of its departure (mass norm) the
// span leaves out is 0.546 without them, 0.120 with them (0.469 with the clusters' responses at the
// six mode samples alone, 0.404 with those in a POD of their own: the whole body's at every path
// sample carry it). Bounds: above 0.4 without (else the test is vacuous), below 0.25 with (2x the
// measurement: another build's POD of the same responses stays well within that).
TEST(ReducedModel, ReleaseResponsesHoldTheReleasedStateOfARelaxingMaterial) {
  const auto bm = build_model(small_scene({"load.trials=2", "materials.silicone.mullins.enabled=false",
                                           "materials.silicone.fatigue.enabled=false", "gravity.g_m_s2=[0.0, 0.0, 0.0]"}));
  Eigen::VectorXd released;
  {
    Assembler A(bm->model);
    QuasiStaticRun run(A, bm->solver.quasi_static);
    struct Enough {};  // the rest of trial 2 is not needed: the observer stops the run
    try {
      run.run(bm->load, [&](const StateRecord& s, const Eigen::VectorXd& u, const std::vector<double>&) {
        if (s.trial == 2) {
          released = u;
          throw Enough{};
        }
      });
    } catch (const Enough&) {
    }
  }
  ASSERT_GT(released.size(), 0);
  const Model& ref = offline().ref->model;
  const Eigen::VectorXd mass = Assembler(ref).lumped_mass();
  auto mdot = [&](const Eigen::VectorXd& a, const Eigen::VectorXd& b) { return mass_dot(mass, a, b); };
  auto left_out = [&](const ReducedBasis& B) {
    const Eigen::VectorXd t = B.dU.col(0);
    const Eigen::VectorXd d = released - (mdot(t, released) / mdot(t, t)) * t;  // the departure beyond theta's part
    Eigen::MatrixXd MPhi = B.Phi;
    for (Eigen::Index i = 0; i < MPhi.rows(); ++i) MPhi.row(i) *= mass[i / 3];
    const Eigen::VectorXd q = (B.Phi.transpose() * MPhi).ldlt().solve(MPhi.transpose() * d);
    const Eigen::VectorXd res = d - B.Phi * q;
    return std::sqrt(mdot(res, res) / mdot(d, d));
  };
  RomBasisOptions opt;
  opt.release_responses = true;
  const ReducedBasis with = build_reduced_basis(ref, offline().trace, opt);
  const double plain = left_out(offline().basis), with_release = left_out(with);
  std::printf("released state's departure left out of the span: %.3f plain, %.3f with release responses\n", plain, with_release);
  EXPECT_GT(plain, 0.4);
  EXPECT_LT(with_release, 0.25);
}

// Below the path's start (theta < 0: a rest after a release overshoots it) the bracket
// G_hat - G_hat_ref of the reference material at q = 0 must stay second order in theta: G_hat_ref is
// extrapolated from its first interval as G_hat's kept points follow the extrapolated path. Held at
// its end value instead it left a first-order force -G_hat' theta (large once the fabric is in the
// bracket: no equilibrium in a rest at 0 kPa, bench/results/rom_h6_ceiling section 10). At p = 0 the
// residual at -d and +d sums the pressure term (p_el - p) v and the bracket on both sides: their
// first orders cancel in the sum when the extrapolation continues the path, so halving d quarters
// the sum (a held G_hat_ref: halves it). Bounds: the ratio above 3.3 (between first order's 2 and
// second order's 4; measured 3.9-4.0), and the sum below 5 % of the first-order change a held
// G_hat_ref would leave, |G_hat_ref(x1) - G_hat_ref(0)| d / x1 (else the test is vacuous).
TEST(ReducedModel, TheReferenceBracketBelowThePathIsSecondOrder) {
  const Offline& o = offline();
  RomBasisOptions opt;
  opt.hyper_reduce = false;
  opt.stiff_parts = RomBasisOptions::StiffParts::exact;
  const ReducedBasis B = build_reduced_basis(o.ref->model, o.trace, opt);
  const ReducedOrderModel rom(o.ref->model, B, o.ref->model);
  ASSERT_EQ(B.p[0], 0.0) << "the path starts unloaded";
  const int r = B.num_modes();
  const double x1 = (B.theta[1] - B.theta[0]) / ReducedBasis::kRefSub;  // the fine grid's first interval (deg)
  const Eigen::VectorXd held_slope = (B.Gref.col(1) - B.Gref.col(0)) / x1;
  auto sum_at = [&](double d) {
    Eigen::VectorXd out = Eigen::VectorXd::Zero(r + 1);
    for (double sign : {-1.0, 1.0}) {
      ReducedCoordinates z;
      z.theta = B.theta[0] + sign * d;
      z.q = Eigen::VectorXd::Zero(r);
      std::vector<double> h;
      out += rom.residual(z, 0.0, TimeStep{}, {}, h, nullptr).head(r + 1);
    }
    return out;
  };
  for (const auto& [row, n] : {std::pair<Eigen::Index, Eigen::Index>{0, 1}, {1, r}}) {
    const double d = x1 / 4;
    const double s1 = sum_at(d).segment(row, n).norm(), s2 = sum_at(d / 2).segment(row, n).norm();
    const double held = held_slope.segment(row, n).norm() * d;
    std::printf("%s: sum %.3e at d, %.3e at d/2 (ratio %.2f); a held reference would leave %.3e\n", row == 0 ? "theta row" : "q rows",
                s1, s2, s1 / s2, held);
    ASSERT_GT(s2, 0.0);
    EXPECT_GT(s1 / s2, 3.3);
    EXPECT_LT(s1, 0.05 * held);
  }
}

TEST(ReducedModel, CavityVolumeIsSecondOrderInTheCorrection) {
  const Offline& o = offline();
  const ReducedOrderModel rom(o.ref->model, o.basis, o.ref->model);
  const Assembler A(o.ref->model);
  const int k = o.basis.num_samples() / 2;
  auto error = [&](double amplitude) {
    ReducedCoordinates z;
    z.theta = o.basis.theta[k];
    z.q = Eigen::VectorXd(rom.num_modes());
    for (int j = 0; j < z.q.size(); ++j) z.q[j] = amplitude * std::cos(0.9 * j + 0.3);
    return std::abs(rom.cavity_volume(z) - A.cavity_volume(rom.displacement(z)));
  };
  const double e1 = error(4e-5), e2 = error(2e-5);
  ASSERT_GT(e2, 0.0);
  EXPECT_GT(e1 / e2, 6.0) << "errors " << e1 << ", " << e2 << " m^3";
}

// Amplitudes: 2e-5 (near the path) and 5e-5 (a large correction of this small actuator: 1e-4
// inverts an element). The follower load's second-order block is ~1e-6 of the Jacobian here, below
// what finite differences resolve; FollowerLoadSecondOrderMatchesTheFullMesh checks its operator.
class ReducedJacobian : public ::testing::TestWithParam<double> {};
INSTANTIATE_TEST_SUITE_P(ReducedModel, ReducedJacobian, ::testing::Values(2e-5, 5e-5));

TEST_P(ReducedJacobian, MatchesFiniteDifferences) {
  const Offline& o = offline();
  const auto bm = build_model(small_scene({"load.trials=1"}));
  expect_jacobian_matches_finite_differences(o.ref->model, o.basis, bm->model, GetParam());
}

TEST(ReducedModel, StoredBasisRoundTripsBitForBitAndDamageIsAnError) {
  const ReducedBasis& b = offline().basis;
  const std::vector<double> d = b.to_doubles();
  const ReducedBasis c = ReducedBasis::from_doubles(d);
  EXPECT_EQ(c.to_doubles(), d);
  std::vector<double> bad = d;
  bad.resize(d.size() / 2);
  EXPECT_NE(error_of([&] { ReducedBasis::from_doubles(bad); }).find("truncated"), std::string::npos);
  bad = d;
  bad[1] = 1.0;  // another format version
  EXPECT_NE(error_of([&] { ReducedBasis::from_doubles(bad); }).find("not a reduced basis of this pneufem version"), std::string::npos);
  bad = d;
  bad[2] = -3.0;  // a count
  EXPECT_NE(error_of([&] { ReducedBasis::from_doubles(bad); }).find("damaged"), std::string::npos);
}

TEST(ReducedModel, ABasisOfAnotherMeshOrFabricIsRejected) {
  const Offline& o = offline();
  const auto other = build_model(Scene::load(kStory, {"geometry.chambers=2", "mesh.h_mm=6.0", "output.vtu=\"none\""}));
  EXPECT_NE(error_of([&] { ReducedOrderModel(o.ref->model, o.basis, other->model); }).find("mesh"), std::string::npos);
  const auto stiff = build_model(small_scene({"materials.fabric.E_MPa=3000.0"}));
  const std::string e = error_of([&] { ReducedOrderModel(o.ref->model, o.basis, stiff->model); });
  EXPECT_NE(e.find("fabric"), std::string::npos) << e;
}

TEST(ReducedModel, OptionsOutOfRangeAreAnError) {
  const Offline& o = offline();
  ElasticPathTrace t;
  t.p_Pa = {o.basis.p[0], o.basis.p[1], o.basis.p[2]};
  for (int k = 0; k < 3; ++k) t.u.push_back(o.basis.U.col(k));
  for (auto set : std::vector<std::function<void(RomBasisOptions&)>>{[](RomBasisOptions& x) { x.max_modes = 0; },
                                                                     [](RomBasisOptions& x) { x.ecsw_tolerance = 1.5; },
                                                                     [](RomBasisOptions& x) { x.pod_tolerance = 0.0; },
                                                                     [](RomBasisOptions& x) { x.clusters = 0; }}) {
    RomBasisOptions opt;
    set(opt);
    EXPECT_NE(error_of([&] { build_reduced_basis(o.ref->model, t, opt); }).find("out of range"), std::string::npos);
  }
  const auto with_effects = build_model(small_scene({}));
  EXPECT_NE(error_of([&] { build_reduced_basis(with_effects->model, t, RomBasisOptions{}); }).find("elastic"), std::string::npos);
}

}  // namespace
}  // namespace pneufem
