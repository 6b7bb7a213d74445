// Viscoelastic creep and relaxation of a homogeneous block through the whole quasi-static driver
// (adaptive physical time steps) vs the analytic standard linear solid (SLS), and convergence of
// the response as the time tolerance tightens.
//
// Small-strain SLS from the Prony convention of damage/viscoelastic.h: the base law is the
// long-term response E_inf = 3 mu (nearly incompressible, so all deformation is isochoric) and one
// term adds gamma E_inf with relaxation time tau. Under a constant stress sigma0 applied at t = 0:
//   eps(t) = sigma0 / E_inf * (1 - gamma / (1 + gamma) * exp(-t / tau_c)),  tau_c = (1 + gamma) tau.
#include <cmath>
#include <cstdio>
#include <sstream>

#include <gtest/gtest.h>

#include "damage/effects.h"
#include "engine/history_step.h"
#include "engine/quasi_static.h"
#include "core/errors.h"
#include "tests/engine/test_meshes.h"

namespace pneufem {
namespace {

using namespace testing;

constexpr double kMu = 1e5, kGamma = 0.5, kTau = 2.0, kSigma = 50.0;  // sigma0 / mu = 5e-4: small strain

struct CreepRun {
  std::vector<double> t, strain;
  long states = 0;
};

/// Unit cube on symmetry supports (x = 0, y = 0, z = 0 planes), loaded in tension on x = 1 by a
/// negative pressure (a follower load; at strain 5e-4 the area change is 1e-3).
Model tension_block(ElementType type, MaterialPtr material) {
  Model model = single_part_model(box(1.0, 1.0, 1.0, 1, 1, 1, type), std::move(material));
  fix(model, nodes_on_plane(model.mesh, 0, 0.0), {true, false, false});
  fix(model, nodes_on_plane(model.mesh, 1, 0.0), {false, true, false});
  fix(model, nodes_on_plane(model.mesh, 2, 0.0), {false, false, true});
  model.pressure_faces = faces_where(model.mesh, [](const Eigen::Vector3d& X) { return X.x() > 1 - 1e-12; });
  model.angle.tip_nodes = nodes_on_plane(model.mesh, 0, 1.0);
  return model;
}

CreepRun creep(double time_tol, double max_dt = 1.0, long max_segment_steps = 5000, double min_dt = 1e-3,
               TimeControl control = TimeControl::Change, ViscoModuli moduli = ViscoModuli::long_term) {
  const Model model = tension_block(ElementType::Tet10,
                                    make_viscoelastic(neo_hookean(kMu, 1e3 * kMu), ViscoParams{{kGamma}, {kTau}, moduli}));
  Assembler asmb(model);
  LoadHistory load;
  TrialLoad tl;
  tl.time_s = {0.0, 1e-6, 6 * kTau};
  tl.pressure_Pa = {0.0, -kSigma, -kSigma};
  for (double t = 0.5; t <= 6 * kTau + 1e-9; t += 0.5) tl.output_s.push_back(t);
  load.trials.push_back(tl);
  QuasiStaticOptions opt;
  opt.time_tol = time_tol;
  opt.max_dt_s = max_dt;
  opt.max_segment_steps = max_segment_steps;
  opt.min_dt_s = min_dt;
  opt.time_control = control;
  QuasiStaticRun run(asmb, opt);
  CreepRun out;
  const int corner = nodes_on_plane(model.mesh, 0, 1.0).front();
  run.run(load, [&](const StateRecord& r, const Eigen::VectorXd& u, const std::vector<double>&) {
    out.t.push_back(r.time_s);
    out.strain.push_back(u[3 * corner]);
  });
  out.states = run.stats().states;
  return out;
}

// A history that needs more physical steps than the budget allows stops with a diagnosis (which
// element, where in time, what to change) instead of grinding on: with time_tol = 1e-7 the creep
// of the first 0.5 s segment needs hundreds of steps, the budget is 20.
TEST(Creep, StalledTimeSteppingStopsWithElementAndHint) {
  try {
    creep(1e-7, 1.0, 20);
    FAIL() << "expected a PhysicsError";
  } catch (const PhysicsError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("physical time stepping stalled: 20 steps"), std::string::npos) << what;
    // Homogeneous block: every element creeps alike, so any of them may be the "fastest".
    // The message names the element by its external id (1-based here), e.element() is its index.
    EXPECT_NE(what.find("fastest at element " + std::to_string(e.element() + 1) + " "), std::string::npos) << what;
    EXPECT_NE(what.find("solver.max_segment_steps"), std::string::npos) << what;
    EXPECT_GE(e.element(), 0);
    EXPECT_GT(e.time_s(), 0.0);
    EXPECT_LT(e.time_s(), 0.5);
  }
  // The same run with the default budget completes (the budget, not the physics, stopped it).
  EXPECT_NO_THROW(creep(1e-7, 1.0, 5000));
}

// Regression: a step at min_dt_s that the no-sliver rule stretches to the segment end (0.45 s step,
// 0.05 s left -> one 0.5 s step) was rejected for its history change, retried at min_dt_s,
// stretched again, forever. Minimal steps are accepted: the run completes, one state per 0.5 s output
// segment (plus the 1 us load ramp), 25 in all.
TEST(Creep, MinimalStepStretchedToTheSegmentEndIsAccepted) {
  const CreepRun r = creep(1e-7, 1.0, 100, 0.45);
  EXPECT_EQ(r.states, 25);
  ASSERT_FALSE(r.strain.empty());
  EXPECT_GT(r.strain.back(), 0.0);
}

double sls_creep(double t) {
  const double E = 3 * kMu, tc = (1 + kGamma) * kTau;
  return kSigma / E * (1 - kGamma / (1 + kGamma) * std::exp(-t / tc));
}

TEST(Creep, HomogeneousBlockFollowsTheStandardLinearSolid) {
  const CreepRun r = creep(1e-6);
  ASSERT_GT(r.t.size(), 10u);
  double worst = 0.0;
  for (std::size_t i = 0; i < r.t.size(); ++i) {
    worst = std::max(worst, std::abs(r.strain[i] - sls_creep(r.t[i])));
    // The series of docs/verification.md's figure (docs/figures/verification_figures.py creep).
    std::printf("creep series long_term: t_s %.17g strain %.17g sls %.17g\n", r.t[i], r.strain[i], sls_creep(r.t[i]));
  }
  // Errors: finite strain vs small strain O(eps) ~ 5e-4 relative, compressibility O(mu/K) = 1e-3,
  // follower area change 1e-3, time integration (tight tolerance) below that: 0.5 % of the
  // final strain bounds them; the creep itself is gamma/(1+gamma) = 33 % of it.
  EXPECT_LT(worst, 5e-3 * sls_creep(1e9));
  EXPECT_GT(sls_creep(1e9) - r.strain.front(), 0.2 * sls_creep(1e9));  // the block really creeps
}

// The same block with the neo-Hookean constants as the INSTANTANEOUS response (Abaqus's
// MODULI=INSTANTANEOUS, damage/viscoelastic.h): E_0 = 3 mu, E_inf = E_0 / (1 + gamma), so the SLS creep is
// (1 + gamma) times the long-term convention's, eps(t) = sigma0 / E_0 (1 + gamma - gamma exp(-t / tau_c)):
// it starts on the elastic strain of the given constants and creeps beyond it to (1 + gamma) times it.
// Same error budget as above (0.5 % of the final strain; the creep is 33 % of it).
TEST(Creep, InstantaneousModuliStartOnTheElasticStrainAndCreepBeyondIt) {
  const CreepRun r = creep(1e-6, 1.0, 5000, 1e-3, TimeControl::Change, ViscoModuli::instantaneous);
  ASSERT_GT(r.t.size(), 10u);
  const double final_strain = (1 + kGamma) * sls_creep(1e9), elastic = kSigma / (3 * kMu);
  double worst = 0.0;
  for (std::size_t i = 0; i < r.t.size(); ++i) {
    worst = std::max(worst, std::abs(r.strain[i] - (1 + kGamma) * sls_creep(r.t[i])));
    std::printf("creep series instantaneous: t_s %.17g strain %.17g sls %.17g\n", r.t[i], r.strain[i],
                (1 + kGamma) * sls_creep(r.t[i]));
  }
  EXPECT_LT(worst, 5e-3 * final_strain);
  EXPECT_NEAR((1 + kGamma) * sls_creep(0.0), elastic, 1e-12 * elastic);  // the analytic start is the elastic strain
  EXPECT_GT(r.strain.back() - elastic, 0.2 * final_strain);  // and the block creeps beyond it
}

TEST(Creep, ResponseConvergesAsTheTimeToleranceTightens) {
  // Let the tolerance alone control the steps (max step = the whole hold) and measure each
  // history against a very tight run: the error must fall as the tolerance tightens.
  const CreepRun ref = creep(1e-8, 12.0);
  std::vector<double> err;
  std::vector<long> states;
  for (double tol : {2e-5, 5e-6, 1.25e-6}) {
    const CreepRun r = creep(tol, 12.0);
    ASSERT_EQ(r.t.size(), ref.t.size());
    double worst = 0.0;
    for (std::size_t i = 0; i < r.t.size(); ++i) worst = std::max(worst, std::abs(r.strain[i] - ref.strain[i]));
    err.push_back(worst / sls_creep(1e9));
    states.push_back(r.states);
  }
  std::printf("creep history error vs time_tol 2e-5, 5e-6, 1.25e-6: %.2e %.2e %.2e (states %ld %ld %ld, reference %ld)\n",
              err[0], err[1], err[2], states[0], states[1], states[2], ref.states);
  EXPECT_LT(states[0], states[1]);
  EXPECT_LT(states[1], states[2]);
  // The error falls monotonically and by >= 4x over a 16x tighter tolerance (the report times
  // every 0.5 s already force short steps at the loosest tolerance, which caps the first gain).
  EXPECT_LT(err[1], err[0]);
  EXPECT_LT(err[2], err[1]);
  EXPECT_LT(err[2], 0.25 * err[0]);
}

// Error control (TimeControl::Error): time_tol bounds a local-error estimate, not the change, so
// the smooth relaxation of a hold is crossed in far fewer steps for the same accuracy, and the
// history still converges as the tolerance tightens (the estimate is O(h^2) per step: a 4x
// tighter tolerance halves the steps' length).
TEST(Creep, ErrorControlConvergesWithFewerStepsThanTheChangeLimit) {
  const CreepRun ref = creep(1e-8, 12.0);
  auto error_of = [&](const CreepRun& r) {
    EXPECT_EQ(r.t.size(), ref.t.size());
    double worst = 0.0;
    for (std::size_t i = 0; i < r.t.size() && i < ref.t.size(); ++i) worst = std::max(worst, std::abs(r.strain[i] - ref.strain[i]));
    return worst / sls_creep(1e9);
  };
  const CreepRun change = creep(1.25e-6, 12.0);
  const double e_change = error_of(change);
  std::vector<double> err;
  std::vector<long> states;
  for (double tol : {2.5e-7, 6.25e-8, 1.5625e-8}) {
    const CreepRun r = creep(tol, 12.0, 5000, 1e-3, TimeControl::Error);
    err.push_back(error_of(r));
    states.push_back(r.states);
  }
  std::printf("error control: history error vs time_tol 2.5e-7, 6.25e-8, 1.5625e-8: %.2e %.2e %.2e (states %ld %ld %ld); "
              "change limit 1.25e-6: %.2e (%ld states)\n",
              err[0], err[1], err[2], states[0], states[1], states[2], e_change, change.states);
  EXPECT_LT(states[0], states[1]);
  EXPECT_LT(states[1], states[2]);
  EXPECT_LT(err[1], err[0]);
  EXPECT_LT(err[2], err[1]);
  // Measured: 1.49e-5 with 62 states vs the change limit's 1.90e-5 with 75. The 0.5 s report
  // times cap both controls' steps here; in a 16 s hold with two report times the gap is larger
  // (BENCHMARKS §7).
  EXPECT_LT(err[1], e_change);
  EXPECT_LT(states[1], change.states);
}

// An instantaneous release to zero pressure (between the trials of a staircase) is solved in one
// Newton solve from the reference configuration instead of following the load path down
// (StaticSolver::release_from_reference). With the history frozen the end state does not depend on
// the path, so both must reach the same equilibrium and the same history: here a block loaded to
// ~20 % strain, held for tau (a Prony overstress half relaxed, so the released block keeps
// gamma / (1 + gamma) (1 - exp(-tau / tau_c)) ~ 16 % of its strain), with Mullins softening under
// the Prony term. A solver that has no equilibrium of its own yet does not try the direct solve,
// which gives the path-followed release to compare with.
TEST(Creep, ReleaseFromTheReferenceReachesThePathFollowedEquilibrium) {
  constexpr double kLoad = 0.2 * kMu;  // follower tension (Pa): ~20 % strain, Mullins energy ~m
  const Model model = tension_block(
      ElementType::Tet10, make_viscoelastic(make_mullins(neo_hookean(kMu, 1e3 * kMu), MullinsParams{2.0, 2e3, 0.1}),
                                            ViscoParams{{kGamma}, {kTau}}));
  const Assembler asmb(model);
  const StaticOptions so{.rel_tol = 1e-8, .max_increment_Pa = kLoad / 4};
  StaticSolver solver(asmb, so);
  std::vector<double> state = asmb.initial_state();
  Eigen::VectorXd u = Eigen::VectorXd::Zero(asmb.num_dofs());
  solver.advance(0.0, -kLoad, 0.0, 0.5, state, u);           // ramp
  solver.advance(-kLoad, -kLoad, 0.5, 0.5 + kTau, state, u);  // hold: the overstress relaxes
  const Eigen::VectorXd u_loaded = u;
  std::vector<double> state_path = state;
  Eigen::VectorXd u_path = u;

  solver.advance(-kLoad, 0.0, 0.5 + kTau, 0.5 + kTau, state, u);
  EXPECT_EQ(solver.stats().release_attempts, 1);
  EXPECT_EQ(solver.stats().direct_releases, 1);

  StaticSolver fresh(asmb, so);
  fresh.advance(-kLoad, 0.0, 0.5 + kTau, 0.5 + kTau, state_path, u_path);
  EXPECT_EQ(fresh.stats().release_attempts, 0);
  EXPECT_GE(fresh.stats().increments, 2);  // followed the path down (first step kLoad / 4, then growing)

  // The release is not trivial: the block keeps a residual strain (~16 % of the loaded one).
  EXPECT_GT(u_path.norm(), 0.1 * u_loaded.norm());
  // Same equilibrium within the Newton tolerance: |R| <= 1e-8 of the force scale moves the
  // displacement by ~1e-8 of its size; 1e-5 leaves room for the conditioning of K (K / mu = 1e3).
  EXPECT_LT((u - u_path).norm(), 1e-5 * u_path.norm());
  ASSERT_EQ(state.size(), state_path.size());
  double scale = 0.0, diff = 0.0;
  for (std::size_t i = 0; i < state.size(); ++i) {
    scale = std::max(scale, std::abs(state_path[i]));
    diff = std::max(diff, std::abs(state[i] - state_path[i]));
  }
  EXPECT_LT(diff, 1e-5 * scale);
}


// A staircase of equal ramps (0.5 s, sigma0/4 each) and holds of 6 tau: every hold relaxes the
// block, so every ramp is the same problem. The hold's steps grow to max_dt_s, so without memory
// every ramp would first be tried whole and rejected for its history change (a wasted solve of
// the full load increment, 2-3 per ramp of the paper's staircase). The control remembers the
// first ramp's start as a pressure increment: only the first ramp is rejected, under both
// controls, and the later ramps are as accurate as the first.
TEST(Creep, ARampAfterAHoldStartsFromThePreviousRampNotFromTheHoldStep) {
  const Model model =
      tension_block(ElementType::Tet10, make_viscoelastic(neo_hookean(kMu, 1e3 * kMu), ViscoParams{{kGamma}, {kTau}}));
  const Assembler asmb(model);
  const int corner = nodes_on_plane(model.mesh, 0, 1.0).front();
  auto staircase = [&](int ramps, TimeControl control, double tol, std::vector<double>* strain) {
    LoadHistory load;
    TrialLoad tl;
    const double hold = 6 * kTau;
    for (int k = 0; k <= ramps; ++k) {
      const double t0 = k * (0.5 + hold);
      tl.time_s.push_back(t0);
      tl.pressure_Pa.push_back(-0.25 * kSigma * k);
      if (k == ramps) break;
      tl.time_s.push_back(t0 + hold);
      tl.pressure_Pa.push_back(-0.25 * kSigma * k);
      tl.output_s.push_back(t0 + hold);
    }
    load.trials.push_back(tl);
    QuasiStaticOptions opt;
    opt.time_tol = tol;
    opt.max_dt_s = hold;
    opt.time_control = control;
    opt.max_segment_steps = 100000;
    QuasiStaticRun run(asmb, opt);
    run.run(load, [&](const StateRecord&, const Eigen::VectorXd& u, const std::vector<double>&) {
      if (strain) strain->push_back(u[3 * corner]);
    });
    return run.stats().rejected_steps;
  };
  for (TimeControl control : {TimeControl::Change, TimeControl::Error}) {
    const double tol = control == TimeControl::Change ? 2e-6 : 5e-7;
    const long one = staircase(2, control, tol, nullptr);  // hold, one ramp, hold
    std::vector<double> strain, ref;
    const long four = staircase(5, control, tol, &strain);  // four ramps after the first hold
    staircase(5, control, tol / 64, &ref);
    std::printf("%s control: rejected steps with one ramp %ld, with four %ld\n",
                control == TimeControl::Change ? "change" : "error", one, four);
    EXPECT_GE(one, 1);  // the first ramp is tried whole and rejected: the memory is needed
    EXPECT_EQ(four, one);  // ...and the later ramps are not
    ASSERT_EQ(strain.size(), ref.size());
    // The strain at the end of every hold is the relaxed SLS value sigma/E_inf within the tight
    // run's (the steps' error decays over a 6 tau hold): 1e-4 relative of the largest strain.
    // The later ramps, started from the memory, are as accurate as the first, which the control
    // found without it: the error at each hold's end against a 64x tighter run stays within 1.5x
    // the first ramp's (measured 1.22x with the change limit, whose remembered first step is a
    // little longer than the retry after the rejection; 1.00x with the error control).
    const double first = std::abs(strain[1] - ref[1]);
    EXPECT_GT(first, 0.0);
    for (std::size_t i = 2; i < ref.size(); ++i) EXPECT_LE(std::abs(strain[i] - ref[i]), 1.5 * first) << "hold " << i;
  }
}

// The drive control's error model (engine/history_step.h): the Prony update
// Q' = exp(-x) Q + a k(x) (S0' - S0) over one step of a drive S0(t) = c t^2 / 2 misses the exact
// solution of dQ/dt + Q/tau = a dS0/dt by a c tau^2 G(h / tau). The exact solution is taken from
// the same update over 4000 sub-steps (exact for each linear piece, so its own error is
// O(sub-step^2), ~1e-7 relative here): the error model and its series branch (x < 0.1) must match
// it to 1e-5 relative over short and long steps (a wrong coefficient, e.g. x^3/6 for x^3/12, or the
// first-order h^2/2 of a backward-Euler update would be off by >= 2x).
TEST(DriveControl, LinearDriveErrorIsTheErrorOfThePronyUpdateForACurvedDrive) {
  constexpr double a = 0.3, tau = 2.0, c = 7.0;
  Material::LinearDrive d;
  d.terms = 1;
  d.a[0] = a;
  d.tau_s[0] = tau;
  auto update = [&](double q, double t0, double t1) {
    const double x = (t1 - t0) / tau, k = -std::expm1(-x) / x;
    return std::exp(-x) * q + a * k * (0.5 * c * t1 * t1 - 0.5 * c * t0 * t0);
  };
  for (double h : {0.01, 0.1, 0.19, 0.21, 0.6, 2.0, 6.0, 40.0}) {
    const double one = update(0.0, 0.0, h);
    double fine = 0.0;
    const int n = 4000;
    for (int i = 0; i < n; ++i) fine = update(fine, h * i / n, h * (i + 1) / n);
    EXPECT_NEAR(linear_drive_error(d, c, h), fine - one, 1e-5 * (fine - one)) << "h = " << h;
  }
  // Two terms add (the same S0'' drives both); no terms, no error.
  Material::LinearDrive two = d;
  two.terms = 2;
  two.a[1] = 0.1;
  two.tau_s[1] = 0.5;
  Material::LinearDrive one_b = d;
  one_b.a[0] = 0.1;
  one_b.tau_s[0] = 0.5;
  EXPECT_NEAR(linear_drive_error(two, c, 1.0), linear_drive_error(d, c, 1.0) + linear_drive_error(one_b, c, 1.0), 1e-15);
  EXPECT_EQ(linear_drive_error(Material::LinearDrive{}, c, 1.0), 0.0);
}

// Release and rest of a staircase between two trials, as in the paper's story: the block is loaded
// in 0.5 s, held for 2 tau (its Prony overstress half relaxed), released in zero time and left to
// recover for 5 tau before the second trial. The drive control must cross the release + rest in a
// handful of states, and every reported strain must agree with a reference run of 100x shorter
// error bound.
struct StaircaseRun {
  std::vector<double> strain;
  long states = 0, gap_states = 0, rejected = 0;
  Eigen::VectorXd u;
};
StaircaseRun two_trials(TimeControl control, double tol, double max_dt, const QuasiStaticCheckpoint* resume = nullptr,
                        QuasiStaticCheckpoint* after_rest = nullptr, MaterialPtr material = nullptr) {
  if (!material) material = make_viscoelastic(neo_hookean(kMu, 1e3 * kMu), ViscoParams{{kGamma}, {kTau}});
  const Model model = tension_block(ElementType::Tet10, std::move(material));
  const Assembler asmb(model);
  const int corner = nodes_on_plane(model.mesh, 0, 1.0).front();
  LoadHistory load;
  TrialLoad tl;
  tl.time_s = {0.0, 0.5, 0.5 + 2 * kTau};
  tl.pressure_Pa = {0.0, -kSigma, -kSigma};
  tl.output_s = {0.0, 0.5, 0.5 + 0.5 * kTau, 0.5 + 2 * kTau};  // t = 0 of trial 2: the end of the rest
  load.trials = {tl, tl};
  load.rest_between_trials_s = 5 * kTau;
  QuasiStaticOptions opt;
  opt.time_tol = tol;
  opt.time_control = control;
  opt.max_dt_s = max_dt;
  opt.max_segment_steps = 100000;
  QuasiStaticRun run(asmb, opt);
  StaircaseRun out;
  const std::vector<QuasiStaticRun::Segment> segs = QuasiStaticRun::segments(load);
  long before_gap = -1;
  run.run(
      load, [&](const StateRecord&, const Eigen::VectorXd& u, const std::vector<double>&) { out.strain.push_back(u[3 * corner]); },
      [&](const QuasiStaticCheckpoint& c) {
        const QuasiStaticRun::Segment& sg = segs[c.next_segment - 1];
        if (sg.trial == 0 && c.next_segment < segs.size() && segs[c.next_segment].trial == 1) before_gap = c.stats.states;
        if (sg.trial == 1 && sg.t1 == 0.0 && sg.g1 > sg.g0) {  // the rest
          out.gap_states = c.stats.states - before_gap;
          if (after_rest) *after_rest = c;
        }
      },
      resume);
  out.states = run.stats().states;
  out.rejected = run.stats().rejected_steps;
  out.u = run.u();
  return out;
}

TEST(DriveControl, CrossesReleaseAndRestInFewStatesAndAgreesWithAFineReference) {
  // time_tol: ~2 % of the viscous strain the release leaves (~4e-5), the story's ratio.
  constexpr double tol = 1e-6;
  const StaircaseRun drive = two_trials(TimeControl::Drive, tol, 100.0);
  const StaircaseRun tighter = two_trials(TimeControl::Drive, tol / 16, 100.0);
  const StaircaseRun error = two_trials(TimeControl::Error, tol, 100.0);
  const StaircaseRun ref = two_trials(TimeControl::Drive, tol / 100, 100.0);
  std::printf("release + rest: drive control %ld states (%ld in all, %ld rejected), error control %ld (%ld, %ld), "
              "reference (tol / 100) %ld (%ld)\n",
              drive.gap_states, drive.states, drive.rejected, error.gap_states, error.states, error.rejected,
              ref.gap_states, ref.states);
  // The release and 4 steps over the 5 tau of rest (measured 5; the error control takes 17: its
  // first step falls back to the change limit and its estimate counts the exact decay of Q as error).
  EXPECT_LE(drive.gap_states, 6);
  EXPECT_LT(drive.gap_states, error.gap_states);
  ASSERT_EQ(drive.strain.size(), ref.strain.size());
  ASSERT_EQ(tighter.strain.size(), ref.strain.size());
  auto worst_of = [&](const StaircaseRun& r) {
    double worst = 0.0;
    for (std::size_t i = 0; i < ref.strain.size(); ++i) worst = std::max(worst, std::abs(r.strain[i] - ref.strain[i]));
    return worst;
  };
  for (std::size_t i = 0; i < ref.strain.size(); ++i)
    std::printf("  report %zu: reference %.6e, drive %+.3e, drive at time_tol / 16 %+.3e, error control %+.3e\n", i,
                ref.strain[i], drive.strain[i] - ref.strain[i], tighter.strain[i] - ref.strain[i],
                error.strain[i] - ref.strain[i]);
  const double worst = worst_of(drive), worst_tighter = worst_of(tighter);
  std::printf("largest strain difference to the reference: %.3g at time_tol, %.3g at time_tol / 16 (strain %.3g)\n", worst,
              worst_tighter, sls_creep(1e9));
  // At fixed load the isochoric stress S0 + Q is fixed, so an error dQ of the viscous update moves
  // S0 = 2 mu_inf D, i.e. the strain's deviator, by dQ / (2 mu_inf): the error in viscous-strain units
  // is the strain's error. An accepted step's estimate is <= 2 time_tol and the relaxation damps the
  // earlier steps' errors, so a report is off by ~ a step's error: 2 time_tol bounds it (measured
  // 0.19 time_tol). A control that crossed the rest in one step (10 s, 5 tau) would be off by
  // ~0.34 x the released viscous strain, ~14 time_tol, and fail.
  EXPECT_LT(worst, 2 * tol);
  // ...and the error falls with the tolerance: for h << tau the local error grows like h^3, so a 16x
  // tighter tolerance shortens the steps ~2.5x and the error ~6x (measured 5.8x); >= 4x is asserted.
  // (A 4x tighter one happens to take the same steps here: a step estimated at 0.48 time_tol is
  // accepted by both, since only estimates above 2 time_tol are rejected.)
  EXPECT_LT(worst_tighter, 0.25 * worst);
}

// The same staircase with fatigue under the Prony layer, its threshold between the stretch the
// release leaves and the loaded one: the damage grows fast in the holds and, after the release,
// slowly for a while, until the recovering block falls below the threshold (the story's end caps
// after trials 6-9, bench/notes/2026-11-28-gap-damage-budget.md). The drive control keeps the error
// control's estimate (Milne on damage AND viscous strain) at damaging points, since their damage
// errors are not damped; but a damage change can move the stress by no more than |dd| |S0| (the
// backward-Euler increment and the exact one both lie between 0 and h max(ddot)), so the error of
// damage changes whose sum moves the point's stress by less than time_tol cannot matter more than one
// accepted viscous step. Those (the rest's) get the drive estimate; without that budget the rest's
// slow damage put the Milne estimate of the relaxing viscous strain back into the control (the
// exponential decay counted as error) and the rest took 8 states instead of 5.
TEST(DriveControl, SlowDamageInTheRestDoesNotShortenItsSteps) {
  FatigueParams fp;
  fp.driver = FatigueDriver::max_principal_stretch;
  // The loaded stretch is ~1 + 1.5e-4 in x, the release leaves a few 1e-5 that recover over the rest:
  // the threshold between them, so g = lambda / lambda_th - 1 ~ 1.3e-4 in the hold and ~1e-5 falling
  // to 0 early in the rest.
  fp.lambda_th = 1.00002;
  fp.q = 1.0;
  fp.n = 1.0;
  fp.tau_s = 100.0;  // ~5e-6 damage in a hold, a few 1e-8 per step early in the rest (< time_tol)
  auto material = [&] { return make_viscoelastic(make_fatigue(neo_hookean(kMu, 1e3 * kMu), fp), ViscoParams{{kGamma}, {kTau}}); };
  constexpr double tol = 1e-6;  // as above: ~2 % of the viscous strain the release leaves
  const StaircaseRun drive = two_trials(TimeControl::Drive, tol, 100.0, nullptr, nullptr, material());
  const StaircaseRun error = two_trials(TimeControl::Error, tol, 100.0, nullptr, nullptr, material());
  const StaircaseRun ref = two_trials(TimeControl::Error, tol / 100, 100.0, nullptr, nullptr, material());
  std::printf("with damage in the rest: release + rest drive %ld states (%ld in all), error %ld (%ld), reference %ld (%ld)\n",
              drive.gap_states, drive.states, error.gap_states, error.states, ref.gap_states, ref.states);
  // As without damage (measured 5; 8 when every damaging point keeps Milne's estimate in the rest).
  EXPECT_LE(drive.gap_states, 6);
  ASSERT_EQ(drive.strain.size(), ref.strain.size());
  ASSERT_EQ(error.strain.size(), ref.strain.size());
  double worst = 0.0, worst_error = 0.0;
  for (std::size_t i = 0; i < ref.strain.size(); ++i) {
    worst = std::max(worst, std::abs(drive.strain[i] - ref.strain[i]));
    worst_error = std::max(worst_error, std::abs(error.strain[i] - ref.strain[i]));
    std::printf("  report %zu: reference %.6e, drive %+.3e, error control %+.3e\n", i, ref.strain[i],
                drive.strain[i] - ref.strain[i], error.strain[i] - ref.strain[i]);
  }
  // Every report within 2 time_tol of the reference, as the test above (a report is off by about one
  // accepted step's error; the damage taken unchecked adds at most time_tol of stress in all).
  EXPECT_LT(worst, 2 * tol);
  EXPECT_LT(worst_error, 2 * tol);
}

// A run under the drive control resumed from a checkpoint taken after the rest (memory: the last
// two states' drives) continues bit for bit as the uninterrupted run.
TEST(DriveControl, ResumedRunContinuesBitForBit) {
  QuasiStaticCheckpoint c;
  const StaircaseRun whole = two_trials(TimeControl::Drive, 1e-6, 100.0, nullptr, &c);
  ASSERT_FALSE(c.drive_cur.empty());
  std::stringstream ss;
  c.write(ss);
  const QuasiStaticCheckpoint back = QuasiStaticCheckpoint::read(ss, static_cast<std::size_t>(whole.u.size()), c.state.size());
  EXPECT_EQ(back.drive_prev, c.drive_prev);
  EXPECT_EQ(back.drive_cur, c.drive_cur);
  const StaircaseRun resumed = two_trials(TimeControl::Drive, 1e-6, 100.0, &back);
  EXPECT_EQ(resumed.states, whole.states);
  EXPECT_TRUE(resumed.u == whole.u);
}

// The linear drive is D = S0 / (2 mu_inf) of the viscoelastic layer, the outermost of a stack (the
// decorators enforce viscoelastic(fatigue(mullins(base)))); fatigue, Mullins and the stiffness scale
// forward the calls to their base, and a stack without a Prony term has none. D is checked against S0
// in the state, (11, 22, 33, 23, 13, 12) with the off-diagonals x sqrt 2.
TEST(DriveControl, TheViscoelasticLayerReportsItsLinearDrive) {
  FatigueParams fp;
  fp.driver = FatigueDriver::max_principal_stretch;
  fp.lambda_th = 1.01;
  fp.tau_s = 100.0;
  const MaterialPtr inner = make_fatigue(make_mullins(neo_hookean(kMu, 1e3 * kMu), MullinsParams{2.0, 2e3, 0.1}), fp);
  EXPECT_EQ(inner->linear_drive().terms, 0);
  EXPECT_EQ(neo_hookean(kMu, 1e3 * kMu)->linear_drive().terms, 0);
  const MaterialPtr stack = make_viscoelastic(inner, ViscoParams{{kGamma}, {kTau}});
  const Material::LinearDrive d = stack->linear_drive();
  ASSERT_EQ(d.terms, 1);
  EXPECT_EQ(d.a[0], kGamma);
  EXPECT_EQ(d.tau_s[0], kTau);
  EXPECT_EQ(d.recovery, 1.0);  // long-term moduli: beta = 1
  const MaterialPtr inst = make_viscoelastic(neo_hookean(kMu, 1e3 * kMu), ViscoParams{{kGamma}, {kTau}, ViscoModuli::instantaneous});
  EXPECT_NEAR(inst->linear_drive().recovery, 1.0 + kGamma, 1e-15);  // 1 / beta
  EXPECT_NEAR(inst->linear_drive().a[0], kGamma / (1.0 + kGamma), 1e-15);  // Abaqus's g
  Mat3 F;
  F << 1.1, 0.05, 0.0, 0.02, 0.95, 0.01, 0.0, 0.03, 0.97;
  std::vector<double> state(static_cast<std::size_t>(stack->state_size())), next(state.size());
  stack->init_state(state);
  PointResponse r;
  stack->evaluate(std::span<const Mat3>(&F, 1), TimeStep{0.5, 0.5}, state, next, std::span<PointResponse>(&r, 1), false);
  std::vector<double> D(6);
  stack->linear_drive_value(next, D);
  EXPECT_GT(std::abs(D[0]), 1e-3);  // a real stress, not zeros
  for (int k = 0; k < 6; ++k) EXPECT_NEAR(D[k], (k < 3 ? 1.0 : std::sqrt(2.0)) * next[k] / (2 * kMu), 1e-15) << k;
}

// Bad options stop with a clear error before any step.
TEST(DriveControl, BadOptionsAreRejected) {
  const Model model =
      tension_block(ElementType::Tet4, make_viscoelastic(neo_hookean(kMu, 1e3 * kMu), ViscoParams{{kGamma}, {kTau}}));
  const Assembler asmb(model);
  QuasiStaticOptions opt;
  opt.time_control = TimeControl::Drive;
  opt.time_tol = 0.0;
  EXPECT_THROW(QuasiStaticRun(asmb, opt), InputError);
  opt.time_tol = 0.01;
  opt.max_dt_s = 0.5 * opt.min_dt_s;
  EXPECT_THROW(QuasiStaticRun(asmb, opt), InputError);
}

}  // namespace
}  // namespace pneufem

namespace pneufem {
namespace {

using namespace testing;

// A block under constant tension whose fatigue damage runs away (stretch driver above threshold,
// first-order kinetics). Its points fail (d = d_fail = 0.5) and keep the residual stiffness
// 1 - d_fail (damage/fatigue.h), so the block does not collapse: the run reaches the end, every
// point failed, with the stretch of a block of half the shear modulus (the volumetric response is
// not degraded; with K = 1000 mu that changes the stretch by ~1e-3, hence 1 %).
// A run that then stops for another reason (here the step budget, with max_dt_s = 0.5 s for a
// 1000 s hold) names the failed points in its message.
TEST(FatigueRunaway, FailedPointsKeepTheirResidualStiffnessAndAreNamedWhenARunStops) {
  FatigueParams fp;
  fp.driver = FatigueDriver::max_principal_stretch;
  fp.lambda_th = 1.01;
  fp.tau_s = 1.0;
  fp.q = 1.0;
  fp.d_fail = 0.5;
  const Model model = tension_block(ElementType::Tet4, make_fatigue(neo_hookean(kMu, 1e3 * kMu), fp));
  const Model half = tension_block(ElementType::Tet4, neo_hookean(0.5 * kMu, 1e3 * kMu));
  LoadHistory load;
  TrialLoad tl;
  tl.time_s = {0.0, 1e-3, 1000.0};
  tl.pressure_Pa = {0.0, -0.3 * kMu, -0.3 * kMu};  // stretch ~1.1 undamaged, above lambda_th
  tl.output_s = {1000.0};
  load.trials.push_back(tl);
  const int corner = nodes_on_plane(model.mesh, 0, 1.0).front();
  auto end_stretch = [&](const Model& m, const QuasiStaticOptions& opt, std::vector<double>* state) {
    const Assembler asmb(m);
    QuasiStaticRun run(asmb, opt);
    double x = NAN;
    run.run(load, [&](const StateRecord&, const Eigen::VectorXd& u, const std::vector<double>& s) {
      x = 1.0 + u[3 * corner];
      if (state) *state = s;
    });
    return x;
  };
  std::vector<double> state;
  const double lam = end_stretch(model, QuasiStaticOptions{}, &state);
  const double lam_half = end_stretch(half, QuasiStaticOptions{}, nullptr);
  EXPECT_NEAR(lam - 1.0, lam_half - 1.0, 0.01 * (lam_half - 1.0));
  ASSERT_FALSE(state.empty());
  for (double s : state) EXPECT_EQ(s, 1.0 - fp.d_fail);  // every point failed, and stopped there

  QuasiStaticOptions budget;
  budget.max_dt_s = 0.5;
  budget.max_segment_steps = 300;
  try {
    end_stretch(model, budget, nullptr);
    FAIL() << "1000 s in steps of at most 0.5 s cannot fit a budget of 300 steps";
  } catch (const PhysicsError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("6 material points had failed (damage >= d_fail)"), std::string::npos) << what;
    EXPECT_NE(what.find("a damage law is destroying that part"), std::string::npos) << what;
    EXPECT_GT(e.time_s(), 0.0);
    EXPECT_LT(e.time_s(), 1000.0);
  }
}

}  // namespace
}  // namespace pneufem
