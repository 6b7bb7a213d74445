// The candidate-effect catalog (app/diagnose/effect_catalog.h): bounds are sane, every candidate's overrides
// build on the default scene and land on the right keys, registered material effects appear, and the
// creep candidate in both moduli conventions names the one a recording shows (one diagnosis, ~1 min).
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>

#include <gtest/gtest.h>

#include "app/diagnose/command.h"
#include "app/diagnose/effect_catalog.h"
#include "core/errors.h"
#include "damage/registry.h"
#include "damage/viscoelastic.h"
#include "scenes/build_model.h"
#include "tests/support/input_error.h"

namespace pneufem {
namespace {

const std::vector<std::string> kTiny = {"geometry.chambers=3", "mesh.h_mm=6.0"};

using pneufem::test::error_of;

void register_test_effect_once() {
  static const bool done = [] {
    MaterialEffect e;
    e.name = "catalog_test_softening";
    e.doc = "test: no-op decorator with one parameter";
    e.params = {{"k_MPa", "MPa", "test parameter", 0.05, 0.01, 0.1, true}};
    e.decorate = [](MaterialPtr b, const std::map<std::string, double>&) { return b; };
    register_material_effect(e);
    return true;
  }();
  (void)done;
}

TEST(EffectCatalog, BuiltInsComeFirstWithSaneBounds) {
  const auto& all = candidate_effects();
  const std::vector<std::string> names = {"stiffness",          "viscoelastic", "viscoelastic_instantaneous",
                                          "viscoelastic_broad", "mullins",      "fatigue",
                                          "fatigue_saturating", "fatigue_uniform", "pressure_lag",
                                          "gravity"};
  ASSERT_GE(all.size(), names.size());
  for (std::size_t i = 0; i < names.size(); ++i) EXPECT_EQ(all[i].name, names[i]);
  for (const CandidateEffect& c : all) {
    EXPECT_FALSE(c.description.empty()) << c.name;
    EXPECT_FALSE(c.signature.empty()) << c.name;
    ASSERT_TRUE(c.sets) << c.name;
    for (const CandidateParameter& p : c.params) {
      EXPECT_LT(p.lo, p.hi) << c.name << "." << p.name;
      EXPECT_TRUE(p.initial >= p.lo && p.initial <= p.hi) << c.name << "." << p.name;
      EXPECT_TRUE(p.truth >= p.lo && p.truth <= p.hi) << c.name << "." << p.name;
      if (p.log) {
        EXPECT_GT(p.lo, 0.0) << c.name << "." << p.name;
      }
    }
  }
  EXPECT_TRUE(candidate_effect("fatigue").history);
  EXPECT_FALSE(candidate_effect("stiffness").history);
  const std::string e = error_of([] { candidate_effect("creep"); });
  EXPECT_NE(e.find("unknown candidate effect 'creep'"), std::string::npos) << e;
  EXPECT_NE(e.find("stiffness, viscoelastic, viscoelastic_instantaneous, viscoelastic_broad, mullins, fatigue, "
                   "fatigue_saturating, fatigue_uniform, pressure_lag, gravity"),
            std::string::npos)
      << e;
}

TEST(EffectCatalog, EveryCandidateBuildsOnTheDefaultSceneWithItsValuesOnTheRightKeys) {
  register_test_effect_once();
  const Scene base = Scene::load("", kTiny);
  for (const CandidateEffect& c : candidate_effects()) {
    SCOPED_TRACE(c.name);
    std::vector<double> truth;
    for (const CandidateParameter& p : c.params) truth.push_back(p.truth);
    const Scene s = base.with(c.sets(base, truth));
    EXPECT_NO_THROW(build_model(s));
    EXPECT_NE(error_of([&] { c.sets(base, {}); }).find("parameter value(s)"), std::string::npos);
  }
  auto with = [&](const std::string& name, std::vector<double> v) { return base.with(candidate_effect(name).sets(base, v)); };
  Scene s = with("stiffness", {1.3});
  EXPECT_DOUBLE_EQ(s.number("materials.silicone.stiffness_scale"), 1.3);
  EXPECT_DOUBLE_EQ(s.number("materials.fabric.stiffness_scale"), 1.0);  // the fabric is not a soft material
  // Relative to the scene's own scale.
  const Scene soft = base.with({"materials.silicone.stiffness_scale=0.5"});
  EXPECT_DOUBLE_EQ(soft.with(candidate_effect("stiffness").sets(soft, {1.3})).number("materials.silicone.stiffness_scale"), 0.65);
  s = with("viscoelastic", {0.5, 4.0});
  EXPECT_TRUE(s.boolean("materials.silicone.viscoelastic.enabled"));
  EXPECT_EQ(s.numbers("materials.silicone.viscoelastic.gamma"), std::vector<double>{0.5});
  EXPECT_EQ(s.numbers("materials.silicone.viscoelastic.tau_s"), std::vector<double>{4.0});
  EXPECT_EQ(s.string("materials.silicone.viscoelastic.moduli"), "long_term");  // the convention it always had
  EXPECT_FALSE(s.has("materials.fabric.viscoelastic"));
  s = with("viscoelastic_instantaneous", {0.5, 4.0});
  EXPECT_TRUE(s.boolean("materials.silicone.viscoelastic.enabled"));
  EXPECT_EQ(s.numbers("materials.silicone.viscoelastic.gamma"), std::vector<double>{0.5});
  EXPECT_EQ(s.numbers("materials.silicone.viscoelastic.tau_s"), std::vector<double>{4.0});
  EXPECT_EQ(s.string("materials.silicone.viscoelastic.moduli"), "instantaneous");
  s = with("mullins", {3.0, 0.01});
  EXPECT_TRUE(s.boolean("materials.silicone.mullins.enabled"));
  EXPECT_DOUBLE_EQ(s.number("materials.silicone.mullins.r"), 3.0);
  EXPECT_DOUBLE_EQ(s.number("materials.silicone.mullins.m_MPa"), 0.01);
  EXPECT_DOUBLE_EQ(s.number("materials.silicone.mullins.beta"), base.number("materials.silicone.mullins.beta"));
  s = with("fatigue", {0.02, 2000.0});
  EXPECT_DOUBLE_EQ(s.number("materials.silicone.fatigue.W_th_MPa"), 0.02);
  EXPECT_DOUBLE_EQ(s.number("materials.silicone.fatigue.tau_s"), 2000.0);
  EXPECT_EQ(s.string("materials.silicone.fatigue.driver"), base.string("materials.silicone.fatigue.driver"));
  EXPECT_DOUBLE_EQ(s.number("materials.silicone.fatigue.n"), 1.0);  // first-order kinetics
  s = with("fatigue_saturating", {0.01, 50.0});
  EXPECT_DOUBLE_EQ(s.number("materials.silicone.fatigue.W_th_MPa"), 0.01);
  EXPECT_DOUBLE_EQ(s.number("materials.silicone.fatigue.tau_s"), 50.0);
  EXPECT_DOUBLE_EQ(s.number("materials.silicone.fatigue.n"), 6.0);  // saturating
  EXPECT_DOUBLE_EQ(with("pressure_lag", {0.5, 0.0}).number("load.pressure_lag_s"), 0.5);
  EXPECT_DOUBLE_EQ(with("pressure_lag", {0.5, 0.0}).number("load.pressure_lag2_s"), 0.0);  // first order
  EXPECT_DOUBLE_EQ(with("pressure_lag", {0.24, 0.27}).number("load.pressure_lag2_s"), 0.27);  // second order
  // ... and what its constants mean, in the diagnosis's words: the order, zeta and f_n, or the RC stages.
  const CandidateEffect& lag = candidate_effect("pressure_lag");
  ASSERT_TRUE(lag.reading);
  EXPECT_NE(lag.reading({0.4, 0.0}).find("First order"), std::string::npos) << lag.reading({0.4, 0.0});
  const std::string under = lag.reading({2.0 * 0.45 / (2.0 * M_PI * 0.6), 1.0 / (2.0 * M_PI * 0.6)});
  EXPECT_NE(under.find("under-damped"), std::string::npos) << under;
  EXPECT_NE(under.find("zeta = 0.45, f_n = 0.6 Hz"), std::string::npos) << under;
  EXPECT_NE(under.find("overshoots a step by 21 %"), std::string::npos) << under;
  const std::string over = lag.reading({0.5, 0.2});  // T1 T2 = 0.04, T1 + T2 = 0.5
  EXPECT_NE(over.find("two first-order stages of 0.4 s and 0.1 s"), std::string::npos) << over;
  // Gravity: the rig angle in the actuator's frame; on the built-in actuator phi = 0 hangs the tip
  // down along +y, 90 deg is horizontal with g towards the fabric (-z), bit for bit the vectors the
  // hidden-effect datasets were made with (g_m_s2 = [0, 9.81 cos(phi), -9.81 sin(phi)]).
  EXPECT_DOUBLE_EQ(with("gravity", {37.5}).number("gravity.rig_angle_deg"), 37.5);
  auto g_of = [&](double phi) { return build_model(with("gravity", {phi}))->model.gravity_m_s2; };
  EXPECT_EQ(g_of(0.0), Eigen::Vector3d(0.0, 9.81, 0.0));
  EXPECT_EQ(g_of(90.0), Eigen::Vector3d(0.0, 0.0, -9.81));
  const double phi = 37.5 * 3.14159265358979323846 / 180.0;
  EXPECT_EQ(g_of(37.5), Eigen::Vector3d(0.0, 9.81 * std::cos(phi), -9.81 * std::sin(phi)));
  EXPECT_NEAR((g_of(180.0) - Eigen::Vector3d(0.0, -9.81, 0.0)).norm(), 0.0, 1e-12);
  // g90 points the way the actuator bends (angle.bend_direction), i.e. to the fabric side.
  EXPECT_GT(g_of(90.0).dot(base.vec3("angle.bend_direction")), 0.0);
  // A gravity vector of the scene is replaced, not added to.
  EXPECT_EQ(build_model(base.with({"gravity.g_m_s2=[0.0, 0.0, -9.81]"}).with(candidate_effect("gravity").sets(base, {0.0})))
                ->model.gravity_m_s2,
            Eigen::Vector3d(0.0, 9.81, 0.0));
}

TEST(EffectCatalog, RegisteredMaterialEffectsBecomeCandidates) {
  register_test_effect_once();
  const CandidateEffect& c = candidate_effect("catalog_test_softening");
  ASSERT_EQ(c.params.size(), 1u);
  EXPECT_EQ(c.params[0].name, "k_MPa");
  EXPECT_EQ(c.params[0].truth, 0.05);  // the registered default
  EXPECT_TRUE(c.params[0].log);
  const Scene base = Scene::load("", kTiny);
  const std::vector<std::string> sets = c.sets(base, {0.07});
  EXPECT_EQ(sets, (std::vector<std::string>{"materials.silicone.catalog_test_softening.enabled=true",
                                            "materials.silicone.catalog_test_softening.k_MPa=0.07"}));
  EXPECT_EQ(soft_materials(base), std::vector<std::string>{"silicone"});
}

// The material candidates take their units and calibration ranges from the effect registry, the
// one place they are declared (damage/registry.h); the catalog declares only which constants are
// calibrated, where the calibration starts and the truth synth hides.
TEST(EffectCatalog, MaterialCandidatesTakeUnitsAndRangesFromTheRegistry) {
  register_test_effect_once();
  int checked = 0;
  for (const CandidateEffect& c : candidate_effects()) {
    const std::string effect = c.name == "viscoelastic_instantaneous" || c.name == "viscoelastic_broad" ? "viscoelastic"
                               : c.name == "fatigue_saturating"                                        ? "fatigue"
                                                                                                       : c.name;
    const MaterialEffect* fx = find_material_effect(effect);
    if (!fx) continue;
    EXPECT_EQ(c.history, fx->history) << c.name;
    for (const CandidateParameter& p : c.params) {
      const EffectParameter& r = fx->param(p.name);
      EXPECT_EQ(p.unit, r.unit) << c.name << "." << p.name;
      // The two ranges the catalog derives from the registry's: the saturating fatigue's tau, whose
      // lower bound is 10 s (effect_catalog.cpp: with n = 6, tau sets the knee, not the damage), and
      // the broad creep's tau, the registry's range of one term widened by the spectrum's decade each
      // way (BroadCreepSpreadsItsTwoConstantsOverThreeTerms checks what that range means).
      if (c.name == "fatigue_saturating" && p.name == "tau_s") {
        EXPECT_EQ(p.lo, 10.0);
        EXPECT_EQ(p.hi, r.hi);
      } else if (c.name == "viscoelastic_broad" && p.name == "tau_s") {
        EXPECT_DOUBLE_EQ(p.lo, r.lo / 10.0);
        EXPECT_DOUBLE_EQ(p.hi, r.hi * 10.0);
      } else {
        EXPECT_EQ(p.lo, r.lo) << c.name << "." << p.name;
        EXPECT_EQ(p.hi, r.hi) << c.name << "." << p.name;
      }
      EXPECT_EQ(p.log, r.log) << c.name << "." << p.name;
      ++checked;
    }
  }
  EXPECT_GE(checked, 2 + 2 + 2 + 2 + 2 + 2 + 1);  // viscoelastic in both conventions and broad, mullins,
                                                  // fatigue with and without saturation, the test effect
  // Calibration start and synth truth are the catalog's own, and not defaults: Mullins starts at
  // r = 5 (near the middle of log [1.1, 20]) and hides r = 3, while a scene's default is 8.
  const CandidateEffect& m = candidate_effect("mullins");
  EXPECT_EQ(m.params[0].initial, 5.0);
  EXPECT_EQ(m.params[0].truth, 3.0);
  EXPECT_EQ(builtin_effect("mullins").param("r").default_value, 8.0);
}

// The creep candidate in both moduli conventions (issue 35): the same Prony constants and ranges,
// each fixing `moduli`, so the diagnosis names the convention that fits. They describe the same
// creep from opposite ends (elastic constants = long-term vs instantaneous response), so one is
// not added on top of the other: a candidate refuses to switch the convention of a table already
// enabled (an effect selected before, or the scene's own), naming what to do instead.
TEST(EffectCatalog, CreepIsTriedInBothModuliConventions) {
  const CandidateEffect& lt = candidate_effect("viscoelastic");
  const CandidateEffect& inst = candidate_effect("viscoelastic_instantaneous");
  EXPECT_TRUE(lt.history);
  EXPECT_TRUE(inst.history);
  ASSERT_EQ(inst.params.size(), lt.params.size());
  for (std::size_t i = 0; i < lt.params.size(); ++i) {
    EXPECT_EQ(inst.params[i].name, lt.params[i].name);
    EXPECT_EQ(inst.params[i].lo, lt.params[i].lo);
    EXPECT_EQ(inst.params[i].hi, lt.params[i].hi);
    EXPECT_EQ(inst.params[i].truth, lt.params[i].truth);
  }
  EXPECT_NE(lt.description.find("long-term"), std::string::npos) << lt.description;
  EXPECT_NE(inst.description.find("instantaneous"), std::string::npos) << inst.description;
  EXPECT_NE(inst.signature.find("creeps above it"), std::string::npos) << inst.signature;

  const Scene base = Scene::load("", kTiny);
  // Built, the two are the same Prony term on the two readings of the constants.
  auto moduli_of = [&](const CandidateEffect& c) {
    const auto bm = build_model(base.with(c.sets(base, {0.5, 4.0})));
    for (const Part& p : bm->model.parts)
      if (const auto* v = dynamic_cast<const Viscoelastic*>(p.material.get())) return v->moduli();
    ADD_FAILURE() << c.name << ": no viscoelastic part";
    return ViscoModuli::long_term;
  };
  EXPECT_EQ(moduli_of(lt), ViscoModuli::long_term);
  EXPECT_EQ(moduli_of(inst), ViscoModuli::instantaneous);

  // On top of the other convention: refused, naming the table and the way out.
  const Scene with_lt = base.with(lt.sets(base, {0.5, 4.0}));
  const std::string e = error_of([&] { inst.sets(with_lt, {0.3, 2.0}); });
  EXPECT_NE(e.find("candidate 'viscoelastic_instantaneous': materials.silicone.viscoelastic is already enabled with "
                   "moduli = \"long_term\"; this candidate would switch it to \"instantaneous\""),
            std::string::npos)
      << e;
  EXPECT_NE(error_of([&] { lt.sets(base.with(inst.sets(base, {0.5, 4.0})), {0.3, 2.0}); }).find("already enabled"),
            std::string::npos);
  // The same convention again (a re-fit of a scene's own creep) replaces its constants, as before.
  const Scene refit = with_lt.with(lt.sets(with_lt, {0.3, 2.0}));
  EXPECT_EQ(refit.numbers("materials.silicone.viscoelastic.gamma"), std::vector<double>{0.3});
  // A scene whose creep is switched off is free for either.
  const Scene off = with_lt.with({"materials.silicone.viscoelastic.enabled=false"});
  EXPECT_EQ(off.with(inst.sets(off, {0.3, 2.0})).string("materials.silicone.viscoelastic.moduli"), "instantaneous");
}

// Creep with a broad relaxation spectrum (issue 35, bench/notes/2026-11-29-diag3.md): the calibrated
// gamma and tau spread over three Prony terms of one fixed shape, tau/10, tau and 10 tau with weights
// proportional to tau_i^(1/4) summing to gamma, in the instantaneous convention; gamma with the
// registry's range, tau with the range where one of the terms lies in the registry's range of a
// term (bench/notes/2026-11-29-diag4.md); not stacked on the one-term creep (one table, a different
// number of terms).
TEST(EffectCatalog, BroadCreepSpreadsItsTwoConstantsOverThreeTerms) {
  const CandidateEffect& one = candidate_effect("viscoelastic_instantaneous");
  const CandidateEffect& broad = candidate_effect("viscoelastic_broad");
  EXPECT_TRUE(broad.history);
  ASSERT_EQ(broad.params.size(), 2u);
  for (std::size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(broad.params[i].name, one.params[i].name);
    EXPECT_EQ(broad.params[i].unit, one.params[i].unit);
    EXPECT_EQ(broad.params[i].log, one.params[i].log);
  }
  EXPECT_EQ(broad.params[0].lo, one.params[0].lo);  // gamma: the registry's
  EXPECT_EQ(broad.params[0].hi, one.params[0].hi);
  const Scene base = Scene::load("", kTiny);
  // tau's range, read through the terms it writes: at its lower bound the SLOWEST term sits at the
  // registry's lowest relaxation time of a term, at its upper bound the FASTEST at the highest, so
  // the spectrum can sit wherever one of its terms can (and extend a decade beyond each end).
  // 1e-12 relative: the values pass through the scene's text (json::num, shortest round-trip).
  const EffectParameter& term = find_material_effect("viscoelastic")->param("tau_s");
  const auto terms_at = [&](double tau) {
    return base.with(broad.sets(base, {0.6, tau})).numbers("materials.silicone.viscoelastic.tau_s");
  };
  const std::vector<double> at_lo = terms_at(broad.params[1].lo), at_hi = terms_at(broad.params[1].hi);
  ASSERT_EQ(at_lo.size(), 3u);
  ASSERT_EQ(at_hi.size(), 3u);
  EXPECT_NEAR(*std::max_element(at_lo.begin(), at_lo.end()), term.lo, 1e-12 * term.lo);
  EXPECT_NEAR(*std::min_element(at_hi.begin(), at_hi.end()), term.hi, 1e-12 * term.hi);
  // ... a wider range than one term's on both sides (the point of it: the slow spectrum is reachable).
  EXPECT_LT(broad.params[1].lo, one.params[1].lo);
  EXPECT_GT(broad.params[1].hi, one.params[1].hi);
  EXPECT_GE(broad.params[1].initial, broad.params[1].lo);
  EXPECT_LE(broad.params[1].initial, broad.params[1].hi);
  const Scene s = base.with(broad.sets(base, {0.6, 4.0}));
  EXPECT_EQ(s.string("materials.silicone.viscoelastic.moduli"), "instantaneous");
  const std::vector<double> g = s.numbers("materials.silicone.viscoelastic.gamma");
  const std::vector<double> tau = s.numbers("materials.silicone.viscoelastic.tau_s");
  ASSERT_EQ(g.size(), 3u);
  ASSERT_EQ(tau.size(), 3u);
  // 1e-12: the values pass through the scene's text (json::num, shortest round-trip) and a sum.
  EXPECT_NEAR(tau[0], 0.4, 1e-12);
  EXPECT_NEAR(tau[1], 4.0, 1e-12);
  EXPECT_NEAR(tau[2], 40.0, 1e-12);
  EXPECT_NEAR(g[0] + g[1] + g[2], 0.6, 1e-12);
  EXPECT_NEAR(g[1] / g[0], std::pow(10.0, 0.25), 1e-12);
  EXPECT_NEAR(g[2] / g[1], std::pow(10.0, 0.25), 1e-12);
  // Built: one viscoelastic law of three terms whose long-term modulus is 1/(1 + gamma) of the base's.
  const auto bm = build_model(s);
  const Viscoelastic* v = nullptr;
  for (const Part& p : bm->model.parts)
    if (const auto* w = dynamic_cast<const Viscoelastic*>(p.material.get())) v = w;
  ASSERT_NE(v, nullptr);
  EXPECT_EQ(v->terms(), 3);
  EXPECT_EQ(v->moduli(), ViscoModuli::instantaneous);
  EXPECT_NEAR(v->long_term_shear_modulus() * 1.6, v->initial_shear_modulus(), 1e-9 * v->initial_shear_modulus());
  // What the constants mean, in the diagnosis's words.
  ASSERT_TRUE(broad.reading);
  const std::string r = broad.reading({0.6, 4.0});
  EXPECT_NE(r.find("at 0.4 s"), std::string::npos) << r;
  EXPECT_NE(r.find("at 40 s"), std::string::npos) << r;
  EXPECT_NE(r.find("long-term response 0.625 of the instantaneous one"), std::string::npos) << r;
  // Not on top of the one-term creep, nor the other way round; a re-fit of itself replaces its terms.
  const std::string e = error_of([&] { broad.sets(base.with(one.sets(base, {0.3, 2.0})), {0.6, 4.0}); });
  EXPECT_NE(e.find("candidate 'viscoelastic_broad': materials.silicone.viscoelastic is already enabled with 1 "
                   "term(s); this candidate would switch it to 3"),
            std::string::npos)
      << e;
  EXPECT_NE(error_of([&] { one.sets(s, {0.3, 2.0}); }).find("already enabled with 3 term(s)"), std::string::npos);
  EXPECT_NEAR(s.with(broad.sets(s, {0.2, 1.0})).numbers("materials.silicone.viscoelastic.tau_s")[2], 10.0, 1e-12);
  // One family: forms of one effect, which diagnose swaps after a round (try_other_forms) instead of stacking.
  for (const char* n : {"viscoelastic", "viscoelastic_instantaneous", "viscoelastic_broad"})
    EXPECT_EQ(candidate_effect(n).family, "creep") << n;
  for (const char* n : {"fatigue", "fatigue_saturating"}) EXPECT_EQ(candidate_effect(n).family, "fatigue") << n;
  for (const char* n : {"stiffness", "mullins", "pressure_lag", "gravity"}) EXPECT_EQ(candidate_effect(n).family, "") << n;
}

// Fatigue with and without saturation (issue 35 item 5): the same law at its integrity exponent's two
// ends, n = 1 and n = 6, which the candidates fix; the two cannot be stacked (one fatigue table per
// material), as the two creep conventions cannot.
TEST(EffectCatalog, FatigueIsTriedWithAndWithoutSaturation) {
  const CandidateEffect& f1 = candidate_effect("fatigue");
  const CandidateEffect& f6 = candidate_effect("fatigue_saturating");
  EXPECT_TRUE(f6.history);
  ASSERT_EQ(f6.params.size(), 2u);
  EXPECT_EQ(f6.params[0].name, "W_th_MPa");
  EXPECT_EQ(f6.params[1].name, "tau_s");
  EXPECT_EQ(f6.params[0].lo, f1.params[0].lo);
  EXPECT_EQ(f6.params[1].hi, f1.params[1].hi);
  EXPECT_NE(f6.description.find("saturates"), std::string::npos) << f6.description;
  const Scene base = Scene::load("", kTiny);
  const Scene with1 = base.with(f1.sets(base, {0.02, 2000.0}));
  const std::string e = error_of([&] { f6.sets(with1, {0.01, 50.0}); });
  EXPECT_NE(e.find("candidate 'fatigue_saturating': materials.silicone.fatigue is already enabled with n = 1; this "
                   "candidate would switch it to 6"),
            std::string::npos)
      << e;
  EXPECT_NE(error_of([&] { f1.sets(base.with(f6.sets(base, {0.01, 50.0})), {0.02, 2000.0}); }).find("already enabled"),
            std::string::npos);
  // A re-fit of the same form replaces the constants.
  EXPECT_DOUBLE_EQ(with1.with(f1.sets(with1, {0.03, 900.0})).number("materials.silicone.fatigue.tau_s"), 900.0);
}

// End to end: a recording whose creep goes beyond the elastic model (tests/data/hidden/
// viscoelastic_instantaneous.csv: synth with gamma 0.5, tau 4 s in the instantaneous convention on
// the hidden-effect datasets' actuator, scripts/make_hidden_datasets.sh) is diagnosed as
// viscoelastic_instantaneous; the long-term candidate, whose creep can only approach the elastic
// model from the stiff side, explains nothing (its constants go to their lower bounds). Its
// long-term twin, tests/data/hidden/viscoelastic.csv, is HiddenEffect.Viscoelastic
// (test_command.cpp), with every candidate. Measured (2026-11-27): NRMSE 0.2040 -> 0.0264 at a noise
// floor of 0.0053, gamma 0.495, tau 4.64 s; stiffness 0.0996 (scale 0.82), long-term creep 0.2040
// (at its lower bounds). The remainder is the reduced model's own error for creep under the
// overshooting inlet, as for the twin (0.023 there; ~1 % of the angle range), which is 5x this
// recording's floor: its creep enlarges the angle range the floor is relative to. Hence the bound on
// the error is relative to the baseline: below 0.2x (measured 0.13x; issue 35 asks <= 0.4x). gamma and
// tau trade off over 4 s holds: within 50 % and 30 % of the truth, as for the twin.
TEST(CreepConventions, ARecordingThatCreepsBeyondTheElasticModelIsInstantaneousCreep) {
  const std::vector<std::string> scene = {"geometry.chambers=5", "mesh.h_mm=6.0", "load.max_kPa=30.0",
                                          "load.step_kPa=10.0",  "load.hold_s=4.0", "load.trials=3"};
  DiagnoseOptions o;
  o.data_path = std::string(PNEUFEM_TEST_DATA_DIR) + "/hidden/viscoelastic_instantaneous.csv";
  o.out_dir = (std::filesystem::temp_directory_path() / "pneufem_diag_creep_conventions").string();
  std::filesystem::remove_all(o.out_dir);
  o.max_effects = 1;
  o.candidates = {"stiffness", "viscoelastic", "viscoelastic_instantaneous"};
  o.cache_dir = (std::filesystem::temp_directory_path() / "pneufem_diagnose_cache").string();  // as test_command's
  const DiagnosisResult r = run_diagnosis(Scene::load("", scene), o);
  for (const CandidateResult& c : r.candidates) {
    std::printf("%s NRMSE %.4f%s", c.effect.c_str(), c.nrmse, c.significant ? " (sig)" : "");
    for (std::size_t i = 0; i < c.params.size(); ++i) std::printf(" %s=%.4g", c.param_names[i].c_str(), c.params[i]);
    std::printf("; ");
  }
  std::printf("\nbaseline %.4f, floor %.4f, final %.4f\n", r.baseline_nrmse, r.noise_floor_nrmse, r.final_nrmse);
  EXPECT_EQ(r.missing_effect, "viscoelastic_instantaneous");
  EXPECT_LT(r.final_nrmse, 0.2 * r.baseline_nrmse);
  const CandidateEffect& truth = candidate_effect("viscoelastic_instantaneous");
  for (const CandidateResult& c : r.candidates) {
    if (c.effect == "viscoelastic") {
      EXPECT_FALSE(c.significant) << c.why;
    }
    if (c.effect != "viscoelastic_instantaneous") continue;
    ASSERT_EQ(c.params.size(), 2u);
    EXPECT_NEAR(c.params[0], truth.params[0].truth, 0.5 * truth.params[0].truth);
    EXPECT_NEAR(c.params[1], truth.params[1].truth, 0.3 * truth.params[1].truth);
  }
}

}  // namespace
}  // namespace pneufem
