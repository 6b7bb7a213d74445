// The reduced (path) model of engine/path_model.h against the full quasi-static FEM on a small
// pneu-net: exact for the elastic reference itself, and within a stated error for each kind of
// history/scaling effect that diagnose calibrates with it.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <algorithm>
#include <map>
#include <random>
#include <string>

#include <gtest/gtest.h>

#include "engine/angle.h"
#include "engine/assembly.h"
#include "engine/path_model.h"
#include "engine/quasi_static.h"
#include "engine/static_solver.h"
#include "core/errors.h"
#include "scenes/build_model.h"

namespace pneufem {
namespace {

// 3 chambers, coarse: ~5k dofs. Three 5 kPa steps with 3 s holds, two trials.
const std::vector<std::string> kSmall = {"geometry.chambers=3",   "mesh.h_mm=6.0", "load.max_kPa=15.0",
                                         "load.hold_s=3.0",       "load.trials=2", "load.output_every_s=0.5",
                                         "solver.time_tol=0.02",  "output.vtu=\"none\""};

struct Histories {
  std::vector<double> t_s, fem_deg, rom_deg;
};

/// FEM states of `sets` and the reduced model replaying the same pressure at the same times.
Histories compare(const std::vector<std::string>& extra, int max_points = PathModelOptions{}.max_points) {
  std::vector<std::string> sets = kSmall;
  sets.insert(sets.end(), extra.begin(), extra.end());
  const Scene scene = Scene::load("", sets);
  auto bm = build_model(scene);
  Histories h;
  std::vector<double> p;
  {
    Assembler A(bm->model);
    QuasiStaticRun run(A, bm->solver.quasi_static);
    run.run(bm->load, [&](const StateRecord& r, const Eigen::VectorXd&, const std::vector<double>&) {
      if (!h.t_s.empty() && r.global_time_s <= h.t_s.back()) return;
      h.t_s.push_back(r.global_time_s);
      h.fem_deg.push_back(r.angle_deg);
      p.push_back(r.pressure_Pa);
    });
  }
  // Reference: the same mesh, elastic (effects off, unit scales, no gravity).
  auto ref = build_model(Scene::load("", kSmall));
  PathModelOptions po;
  po.p_top_Pa = 25e3;
  po.max_points = max_points;
  const PathModel rom(ref->model, po);
  // Pressure between reports follows the load's breakpoints: replay them too.
  PathLoad load;
  double offset = 0.0;
  for (const TrialLoad& tr : bm->load.trials) {
    for (std::size_t i = 0; i < tr.time_s.size(); ++i) {
      const double t = offset + tr.time_s[i];
      if (!load.t_s.empty() && t <= load.t_s.back()) continue;
      load.t_s.push_back(t);
      load.p_Pa.push_back(tr.pressure_Pa[i]);
    }
    offset += tr.duration() + bm->load.rest_between_trials_s;
  }
  // Merge report times.
  std::map<double, double> merged;
  for (std::size_t i = 0; i < load.t_s.size(); ++i) merged[load.t_s[i]] = load.p_Pa[i];
  for (std::size_t i = 0; i < h.t_s.size(); ++i) merged[h.t_s[i]] = p[i];
  PathLoad all;
  for (auto [t, pp] : merged) {
    all.t_s.push_back(t);
    all.p_Pa.push_back(pp);
  }
  const std::vector<double> a = rom.run(bm->model, all);
  for (double t : h.t_s) {
    const auto it = std::lower_bound(all.t_s.begin(), all.t_s.end(), t);
    h.rom_deg.push_back(a[it - all.t_s.begin()]);
  }
  return h;
}

/// Largest |rom - fem| relative to the largest |fem|.
double rel_error(const Histories& h) {
  double e = 0.0, m = 0.0;
  for (std::size_t i = 0; i < h.t_s.size(); ++i) {
    e = std::max(e, std::abs(h.rom_deg[i] - h.fem_deg[i]));
    m = std::max(m, std::abs(h.fem_deg[i]));
  }
  return e / m;
}

TEST(PathModel, ElasticReferenceIsReproduced) {
  const Histories h = compare({});
  // The difference form is exact for the reference at the path's samples (the states at 5 kPa
  // levels coincide with them; between samples see the next test); what remains is Newton
  // tolerances: 1e-6 of the angle is generous.
  ASSERT_GT(h.fem_deg.back(), 0.5);
  EXPECT_LT(rel_error(h), 1e-6);
}

// Between the path's samples, near the limit point: diagnose traces the path at 1/40 of the
// recording's peak pressure and compares at any pressure, and a staircase to 45 kPa spends its top
// hold where the angle rises fastest. The elastic model's reduced angle must stay on its FEM curve
// there too, not only at the samples.
TEST(PathModel, ElasticReferenceBetweenSamplesNearTheLimitPoint) {
  auto ref = build_model(Scene::load("", {"geometry.chambers=3", "mesh.h_mm=6.0"}));
  const double p_max = 46e3;  // Pa: as a recording's peak, 45 kPa plus overshoot
  PathModelOptions po;
  po.p_top_Pa = 1.8 * p_max;  // as diagnose (app/diagnose/evaluator.cpp)
  po.dp_Pa = p_max / 40.0;
  const PathModel rom(ref->model, po);
  // FEM equilibria at 36.5, 37.5, ..., 45.5 kPa: between samples (1.15 kPa apart), top quarter.
  const int n = 10;
  const double lo = 36.5e3, hi = 45.5e3;
  PathLoad load;
  for (int i = 0; i <= n; ++i) {
    load.t_s.push_back(i);
    load.p_Pa.push_back(lo + (hi - lo) * i / n);
  }
  const std::vector<double> a = rom.run(ref->model, load);
  double worst = 0.0, top = 0.0;
  {
    const Assembler A(ref->model);
    StaticSolver solver(A, ref->solver.quasi_static.newton);
    Eigen::VectorXd u = Eigen::VectorXd::Zero(A.num_dofs());
    std::vector<double> state;
    double p_prev = 0.0;
    for (int i = 0; i <= n; ++i) {
      solver.advance(p_prev, load.p_Pa[i], 0.0, 0.0, state, u);
      p_prev = load.p_Pa[i];
      const double fem = bending_angle(ref->model, u).angle_deg;
      worst = std::max(worst, std::abs(a[i] - fem));
      top = std::max(top, std::abs(fem));
      if (std::getenv("PNEUFEM_TEST_VERBOSE")) std::printf("%g kPa: fem %.5f rom %.5f\n", load.p_Pa[i] / 1e3, fem, a[i]);
    }
  }
  ASSERT_GT(top, 5.0);  // the 3-chamber actuator bends ~10° at 45 kPa, its steepest part
  // Bound 0.02 % of the largest angle: measured 0.0034 % (0.0003°); with a chord for p_el(theta)
  // and the reference force cached at 16 sub-points it was 0.175 % (0.017°; on the 15-chamber
  // actuator 0.6° at 44 kPa, and the diagnosis of a CalculiX-made recording without any hidden
  // effect named a stiffness change that was not there).
  EXPECT_LT(worst, 2e-4 * top);
}

// The scalar equilibrium solve on thousands of tiny pressure changes (the denoised 400 Hz record
// diagnose replays): the secant often converges from one side without ever bracketing the root,
// which must count as converged, not as "no equilibrium". An elastic model's angle depends on the
// pressure alone, so a random walk and the same pressures in sorted order must give the same
// angles (1e-6 of the peak: the solve tolerance is 1e-7 of the path's top pressure).
TEST(PathModel, TinyPressureChangesConvergeAndArePathIndependent) {
  auto ref = build_model(Scene::load("", kSmall));
  std::vector<std::string> sets = kSmall;
  sets.push_back("materials.silicone.stiffness_scale=0.8");  // not the reference: nonlinear residual
  auto soft = build_model(Scene::load("", sets));
  PathModelOptions po;
  po.p_top_Pa = 20e3;
  const PathModel rom(ref->model, po);
  std::mt19937_64 rng(11);
  std::normal_distribution<double> step(0.0, 20.0);
  PathLoad walk;
  double p = 5e3;
  for (int i = 0; i < 3000; ++i) {
    p = std::clamp(p + step(rng), 0.0, 15e3);
    walk.t_s.push_back(0.01 * i);
    walk.p_Pa.push_back(p);
  }
  std::vector<double> a_walk;
  ASSERT_NO_THROW(a_walk = rom.run(soft->model, walk));
  std::vector<std::size_t> order(walk.p_Pa.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return walk.p_Pa[a] < walk.p_Pa[b]; });
  PathLoad sorted;
  for (std::size_t i = 0; i < order.size(); ++i) {
    sorted.t_s.push_back(0.01 * i);
    sorted.p_Pa.push_back(walk.p_Pa[order[i]]);
  }
  const std::vector<double> a_sorted = rom.run(soft->model, sorted);
  double peak = 0.0, err = 0.0;
  for (std::size_t i = 0; i < order.size(); ++i) {
    peak = std::max(peak, std::abs(a_sorted[i]));
    err = std::max(err, std::abs(a_sorted[i] - a_walk[order[i]]));
  }
  ASSERT_GT(peak, 0.1);
  EXPECT_LT(err, 1e-6 * peak);
}

// Calibration needs the reduced model's angle to be a smooth function of the constants. With F
// linear in theta between path samples, F'(theta) jumped at every sample and so did the residual
// of any model but the reference: the equilibrium angle stuck to a sample over a band of
// constants and then jumped on (2026-11-26, default actuator: 0.4 deg for a 0.05 % change of a
// Prony gamma, which made the objective piecewise constant and trapped BOBYQA). Here the scale of
// the silicone sweeps 0.70 -> 1.00 at 15 kPa (the angle crosses ~10 path samples, all inside the
// traced path): consecutive angle increments must change smoothly. Measured: with the spline path
// the largest change of an increment is 2 % of the largest increment (the curvature of the angle
// in the scale); with the linear path 94 % (an increment of ~0 next to a full one where the angle
// stuck at a sample). 10 % separates the two with a wide margin.
TEST(PathModel, AngleIsSmoothInTheConstants) {
  auto ref = build_model(Scene::load("", kSmall));
  PathModelOptions po;
  po.p_top_Pa = 25e3;  // the softest model at 15 kPa bends as the reference at ~21 kPa
  // Built from its trace, as diagnose --cache does (the plain constructor traces and delegates).
  const ElasticPathTrace trace = trace_elastic_path(ref->model, po);
  const PathModel rom(ref->model, po, trace);
  // A stored trace that does not fit the model is refused, saying why.
  auto refused = [&](ElasticPathTrace t, const std::string& why) {
    try {
      const PathModel bad(ref->model, po, t);
      ADD_FAILURE() << "accepted a trace that " << why;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(why), std::string::npos) << e.what();
    }
  };
  ElasticPathTrace shorter = trace, swapped = trace, nan = trace;
  shorter.u[1].conservativeResize(shorter.u[1].size() - 3);
  refused(shorter, "dof");
  std::swap(swapped.u[1], swapped.u[2]);
  refused(swapped, "is not increasing in pressure and angle at sample 2");
  nan.u[2][7] = NAN;
  refused(nan, "non-finite");
  PathLoad load;
  load.t_s = {0.0};
  load.p_Pa = {15e3};
  std::vector<double> theta;
  for (int i = 0; i <= 60; ++i) {
    std::vector<std::string> sets = kSmall;
    sets.push_back("materials.silicone.stiffness_scale=" + std::to_string(0.7 + 0.005 * i));
    theta.push_back(rom.run(build_model(Scene::load("", sets))->model, load).front());
  }
  std::vector<double> d;
  for (std::size_t i = 1; i < theta.size(); ++i) d.push_back(theta[i] - theta[i - 1]);
  double dmax = 0.0, dd = 0.0;
  for (std::size_t i = 0; i < d.size(); ++i) {
    dmax = std::max(dmax, std::abs(d[i]));
    if (i > 0) dd = std::max(dd, std::abs(d[i] - d[i - 1]));
  }
  std::printf("angle %.4f -> %.4f deg; largest increment %.3g deg, largest change of one %.3g deg\n", theta.front(),
              theta.back(), dmax, dd);
  if (std::getenv("PNEUFEM_TEST_VERBOSE"))
    for (double x : d) std::printf(" %.5f", x);
  ASSERT_GT(theta.front() - theta.back(), 0.5);  // the sweep moves the angle across several samples
  EXPECT_LT(dd, 0.1 * dmax);
}

// Uniform changes (a scale of the silicone, viscoelasticity of all of it) keep the deformation on
// the elastic path: the reduced model must follow the FEM within a few % of the angle. Damage
// that concentrates in the interior walls (Mullins, fatigue) changes the deformation shape; the
// 1-dof model then misjudges the SIZE of the effect (measured: it overestimates the angle change
// by ~2-2.5x) while getting its sign and time structure right — which is what ranking candidates
// needs; diagnose --refine corrects the constants with the FEM (space mapping). We assert the
// ratio of effect sizes stays in [1, 3] so a regression in either model shows. (Softening only
// some regions elastically is worse still — the Ritz model is then too stiff — which is why
// region sensitivity in `compare` uses the FEM, not this model.)
TEST(PathModel, HistoryEffectsFollowTheFem) {
  struct Case {
    const char* name;
    std::vector<std::string> sets;
    double tol;                  ///< max |rom - fem| / max |fem| (uniform effects), or
    double ratio_lo, ratio_hi;   ///< range of (rom effect size) / (fem effect size) (localised)
  };
  const std::vector<Case> cases = {
      {"stiffness", {"materials.silicone.stiffness_scale=0.8"}, 0.03, 0, 0},
      {"viscoelastic",
       {"materials.silicone.viscoelastic.enabled=true", "materials.silicone.viscoelastic.moduli=long_term",
        "materials.silicone.viscoelastic.gamma=[0.5]", "materials.silicone.viscoelastic.tau_s=[2.0]"},
       0.02, 0, 0},
      // The same term with the Yeoh constants as the instantaneous response (Abaqus's default): the
      // angle creeps beyond the elastic one, towards the long-term material 1/(1 + gamma) = 0.67 times
      // as stiff, softer than the stiffness case. Measured (2026-11-27): effect 55.8 % of the peak
      // angle, reduced-model error 3.01 % (long-term case 0.44 % of a 21.5 % effect, stiffness 0.93 % of
      // 37.3 %): further along the elastic path the 1-dof model's shape error grows. Bound 4 %: the
      // measured error with the headroom of the other uniform cases (the error of this case is ~5 % of
      // its effect, that of the long-term one 2 %).
      {"viscoelastic_instantaneous",
       {"materials.silicone.viscoelastic.enabled=true", "materials.silicone.viscoelastic.moduli=instantaneous",
        "materials.silicone.viscoelastic.gamma=[0.5]", "materials.silicone.viscoelastic.tau_s=[2.0]"},
       0.04, 0, 0},
      {"mullins",
       {"materials.silicone.mullins.enabled=true", "materials.silicone.mullins.r=3.0",
        "materials.silicone.mullins.m_MPa=0.0005"},
       0.0, 1.0, 3.0},
      {"fatigue",
       {"materials.silicone.fatigue.enabled=true", "materials.silicone.fatigue.W_th_MPa=0.002",
        "materials.silicone.fatigue.tau_s=50.0"},
       0.0, 1.0, 3.0},
  };
  const Histories e = compare({});
  for (const Case& c : cases) {
    if (const char* only = std::getenv("PNEUFEM_TEST_CASE"); only && std::string(only) != c.name) continue;
    const Histories h = compare(c.sets);
    double dmax = 0.0, rmax = 0.0, emax = 0.0;
    for (std::size_t i = 0; i < std::min(h.fem_deg.size(), e.fem_deg.size()); ++i) {
      dmax = std::max(dmax, std::abs(h.fem_deg[i] - e.fem_deg[i]));
      rmax = std::max(rmax, std::abs(h.rom_deg[i] - e.fem_deg[i]));
      emax = std::max(emax, std::abs(e.fem_deg[i]));
    }
    if (std::getenv("PNEUFEM_TEST_VERBOSE"))
      for (std::size_t i = 0; i < h.t_s.size(); ++i)
        std::printf("  t %7.2f fem %8.4f rom %8.4f elastic %8.4f\n", h.t_s[i], h.fem_deg[i], h.rom_deg[i], e.fem_deg[i]);
    std::printf("%s: effect %.1f %% of the peak angle (reduced model %.1f %%), reduced-model error %.2f %%\n", c.name,
                100 * dmax / emax, 100 * rmax / emax, 100 * rel_error(h));
    // The effect must matter (else the test proves nothing): > 2 % change of the peak angle.
    EXPECT_GT(dmax, 0.02 * emax) << c.name;
    if (c.tol > 0) {
      EXPECT_LT(rel_error(h), c.tol) << c.name;
    } else {
      EXPECT_GE(rmax / dmax, c.ratio_lo) << c.name;
      EXPECT_LE(rmax / dmax, c.ratio_hi) << c.name;
    }
  }
}

// Above max_points the reduced model keeps an importance sample of elements, each with all its
// quadrature points. The interior walls bend with one or two quadratic elements through them; an
// element's centroid (its mean strain) misses the bending strain, and creep driven by it came out
// too small (BENCHMARKS.md §8: 68 % of the FEM's near the default actuator's limit point). Here a
// quarter of the elements of the small actuator are sampled (225 of 910). Measured: creep 0.1950
// deg against the FEM's 0.1954, error 0.53 % of the peak angle; with centroids (before 2026-11-26)
// 0.1751 deg (90 %) and 3.1 %. Bounds: the creep within 5 % (the sampling's scatter, ~2 % on the
// default actuator with 500 elements) and the 2 % of the uniform effects above.
TEST(PathModel, SampledElementsFollowTheFemsCreep) {
  const std::vector<std::string> visco = {"materials.silicone.viscoelastic.enabled=true",
                                          "materials.silicone.viscoelastic.moduli=long_term",  // as measured
                                          "materials.silicone.viscoelastic.gamma=[0.5]",
                                          "materials.silicone.viscoelastic.tau_s=[2.0]"};
  const Histories e = compare({});
  const Histories h = compare(visco, 900);
  double fem_effect = 0.0, rom_effect = 0.0;
  for (std::size_t i = 0; i < std::min(h.fem_deg.size(), e.fem_deg.size()); ++i) {
    fem_effect = std::max(fem_effect, std::abs(h.fem_deg[i] - e.fem_deg[i]));
    rom_effect = std::max(rom_effect, std::abs(h.rom_deg[i] - e.fem_deg[i]));
  }
  std::printf("sampled: creep %.4f deg (FEM %.4f), reduced-model error %.2f %%\n", rom_effect, fem_effect, 100 * rel_error(h));
  EXPECT_GT(fem_effect, 0.02 * std::abs(e.fem_deg.back()));
  EXPECT_NEAR(rom_effect / fem_effect, 1.0, 0.05);
  EXPECT_LT(rel_error(h), 0.02);
}

}  // namespace
}  // namespace pneufem
