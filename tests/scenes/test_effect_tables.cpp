// The default scene's effect tables come from the effect registry (scenes/effect_tables.h): every
// built-in effect constant is declared once, in damage/registry.cpp, and the default scene, the
// scene reader and `pneufem scene --defaults` all show that one value.
#include <functional>

#include <gtest/gtest.h>

#include "core/errors.h"
#include "damage/effects.h"
#include "damage/registry.h"
#include "materials/hyperelastic.h"
#include "scenes/build_model.h"
#include "scenes/effect_tables.h"
#include "scenes/scene.h"

namespace pneufem {
namespace {

TEST(EffectTables, DefaultSceneHoldsEveryBuiltInConstantAtItsRegisteredDefault) {
  const Scene s = Scene::load("");
  int checked = 0;
  for (const MaterialEffect* fx : material_effects()) {
    if (!is_builtin_effect(fx->name)) continue;
    const std::string K = "materials.silicone." + fx->name;
    EXPECT_FALSE(s.boolean(K + ".enabled")) << K;
    for (const EffectParameter& p : fx->params) {
      if (p.per_term)
        EXPECT_EQ(s.numbers(K + "." + p.name), std::vector<double>{p.default_value}) << K << "." << p.name;
      else
        EXPECT_EQ(s.number(K + "." + p.name), p.default_value) << K << "." << p.name;
      ++checked;
    }
    for (const EffectChoice& c : fx->choices) EXPECT_EQ(s.string(K + "." + c.name), c.values.front()) << K;
    // Nothing else in the table: a constant the registry does not declare would be a second source.
    EXPECT_EQ(s.table_keys(K).size(), 1 + fx->params.size() + fx->choices.size()) << K;
  }
  EXPECT_EQ(checked, 3 + 7 + 2);  // mullins r, m, beta; fatigue's seven; the Prony gamma and tau
}

// The defaults the default scene file and the registry disagreed on until 2026-11-27. The scene
// file's values won (damage/registry.cpp says why): they are what every run used, so pinning them
// here also pins that no scene's result changed when the registry became the one source.
TEST(EffectTables, DisagreeingDefaultsWereResolvedToTheValuesRunsUsed) {
  EXPECT_EQ(builtin_effect("mullins").param("r").default_value, 8.0);      // not 3.0 (registry) nor 5.0 (calibration start)
  EXPECT_EQ(builtin_effect("fatigue").param("lambda_th").default_value, 1.6);  // not 1.5
  EXPECT_EQ(builtin_effect("viscoelastic").param("tau_s").default_value, 6.0);  // not 1.0
  const Scene s = Scene::load("");
  EXPECT_EQ(s.number("materials.silicone.mullins.r"), 8.0);
  EXPECT_EQ(s.number("materials.silicone.fatigue.lambda_th"), 1.6);
  EXPECT_EQ(s.numbers("materials.silicone.viscoelastic.tau_s"), std::vector<double>{6.0});
}

TEST(EffectTables, DefaultTextShowsTheTablesWithTheirDocsAndRanges) {
  const std::string& t = Scene::default_text();
  EXPECT_EQ(t.find("# @effect-tables"), std::string::npos) << "the marker line must be expanded";
  for (const char* table :
       {"\n[materials.silicone.mullins]", "\n[materials.silicone.fatigue]", "\n[materials.silicone.viscoelastic]"}) {
    const std::size_t at = t.find(table);
    ASSERT_NE(at, std::string::npos) << table;
    EXPECT_EQ(t.find(table, at + 1), std::string::npos) << table << " appears twice";
  }
  EXPECT_NE(t.find("r = 8.0"), std::string::npos);
  EXPECT_NE(t.find("> 1; maximum softening fraction 1/r (calibrated in 1.1 .. 20, log scale)"), std::string::npos);
  EXPECT_NE(t.find("driver = \"energy\""), std::string::npos);
  EXPECT_NE(t.find("gamma = [0.1]"), std::string::npos);
  EXPECT_NE(t.find("tau_s = [6.0]"), std::string::npos);
  // The tables sit where the marker was: after the silicone's own keys, before the fabric.
  EXPECT_LT(t.find("stiffness_scale = 1.0"), t.find("\n[materials.silicone.mullins]"));
  EXPECT_LT(t.find("\n[materials.silicone.viscoelastic]"), t.find("\n[materials.fabric]"));
}

TEST(EffectTables, ExpandReplacesOnlyTheMarkerLines) {
  const std::string out = expand_effect_tables("a = 1\n# @effect-tables materials.rubber\nb = 2");
  EXPECT_EQ(out.rfind("a = 1\n[materials.rubber.mullins]", 0), 0u) << out;
  EXPECT_NE(out.find("[materials.rubber.viscoelastic]"), std::string::npos);
  EXPECT_EQ(out.substr(out.size() - 7), "\nb = 2\n");
  EXPECT_EQ(expand_effect_tables("# @effect-table x\n"), "# @effect-table x\n");
}

TEST(EffectTables, FloatsReadBackAsTomlFloats) {
  EXPECT_EQ(toml_float(8.0), "8.0");
  EXPECT_EQ(toml_float(1000.0), "1000.0");
  EXPECT_EQ(toml_float(0.01), "0.01");
  EXPECT_EQ(toml_float(1e-5), "1e-05");
  EXPECT_EQ(toml_float(-4.75e-6), "-4.75e-06");
  EXPECT_EQ(toml_float(0.1 + 0.2), "0.30000000000000004");
}

// A material of the user's own, with Mullins on and only r given: m and beta are the registry's
// defaults (before 2026-11-27 the scene reader failed with "missing key" for them).
TEST(EffectTables, ATableThatLeavesAConstantOutTakesTheRegisteredDefault) {
  const Scene s = Scene::load("", {"materials.rubber={model=\"neo_hookean\", C10_MPa=0.02, K_over_mu=100.0, density_kg_m3=1000.0}",
                                   "materials.rubber.mullins.enabled=true", "materials.rubber.mullins.r=2.0",
                                   "materials.rubber.viscoelastic.enabled=true"});
  const MaterialPtr m = make_material(s, "rubber");
  EXPECT_EQ(m->name(), "viscoelastic(mullins(neo_hookean))");
  const auto* visco = dynamic_cast<const Viscoelastic*>(m.get());
  ASSERT_NE(visco, nullptr);
  const auto* mullins = dynamic_cast<const Mullins*>(visco->base().get());
  ASSERT_NE(mullins, nullptr);
  EXPECT_EQ(mullins->params().r, 2.0);
  EXPECT_EQ(mullins->params().m_Pa, builtin_effect("mullins").param("m_MPa").default_value * 1e6);
  EXPECT_EQ(mullins->params().beta, builtin_effect("mullins").param("beta").default_value);
}

TEST(EffectTables, ChoicesAndKeysComeFromTheRegistry) {
  auto error_of = [](const std::function<void()>& f) {
    try {
      f();
    } catch (const InputError& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  const Scene bad_driver = Scene::load("", {"materials.silicone.fatigue.enabled=true", "materials.silicone.fatigue.driver=strain"});
  EXPECT_NE(error_of([&] { make_material(bad_driver, "silicone"); })
                .find("key 'materials.silicone.fatigue.driver': must be \"energy\" or \"max_principal_stretch\""),
            std::string::npos);
  const Scene typo = Scene::load("", {"materials.silicone.mullins.enabled=true", "materials.silicone.mullins.rr=2.0"});
  EXPECT_NE(error_of([&] { make_material(typo, "silicone"); }).find("allowed: beta, enabled, m_MPa, r"), std::string::npos);
}

// materials.NAME.viscoelastic.moduli (issue 35): whether the hyperelastic constants are the
// instantaneous response (the default, as Abaqus) or the long-term one; declared once, in the registry.
TEST(EffectTables, ViscoelasticModuliDefaultToInstantaneousAsAbaqus) {
  const MaterialEffect& fx = builtin_effect("viscoelastic");
  ASSERT_EQ(fx.choices.size(), 1u);
  EXPECT_EQ(fx.choices[0].name, "moduli");
  EXPECT_EQ(fx.choices[0].values, (std::vector<std::string>{"instantaneous", "long_term"}));
  EXPECT_EQ(Scene::load("").string("materials.silicone.viscoelastic.moduli"), "instantaneous");
  auto moduli_of = [](const std::vector<std::string>& sets) {
    std::vector<std::string> all{"materials.silicone.viscoelastic.enabled=true"};
    all.insert(all.end(), sets.begin(), sets.end());
    const MaterialPtr m = make_material(Scene::load("", all), "silicone");
    const auto* v = dynamic_cast<const Viscoelastic*>(m.get());
    EXPECT_NE(v, nullptr);
    return v ? v->moduli() : ViscoModuli::long_term;
  };
  EXPECT_EQ(moduli_of({}), ViscoModuli::instantaneous);
  EXPECT_EQ(moduli_of({"materials.silicone.viscoelastic.moduli=long_term"}), ViscoModuli::long_term);
  EXPECT_EQ(moduli_of({"materials.silicone.viscoelastic.moduli=\"instantaneous\""}), ViscoModuli::instantaneous);
  // A user's own material table without the key takes the registry's default too.
  const Scene rubber = Scene::load("", {"materials.rubber={model=\"neo_hookean\", C10_MPa=0.02, K_over_mu=100.0, density_kg_m3=1000.0}",
                                        "materials.rubber.viscoelastic.enabled=true"});
  EXPECT_EQ(dynamic_cast<const Viscoelastic&>(*make_material(rubber, "rubber")).moduli(), ViscoModuli::instantaneous);
  try {
    make_material(Scene::load("", {"materials.silicone.viscoelastic.enabled=true", "materials.silicone.viscoelastic.moduli=relaxed"}),
                  "silicone");
    ADD_FAILURE() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("key 'materials.silicone.viscoelastic.moduli': must be \"instantaneous\" or \"long_term\""),
              std::string::npos)
        << e.what();
  }
}

TEST(EffectTables, RegistryParameterLookupNamesTheValidOnes) {
  try {
    builtin_effect("mullins").param("q");
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("has no parameter 'q'; it has r, m_MPa, beta"), std::string::npos) << e.what();
  }
  EXPECT_THROW(builtin_effect("constant_softening"), std::logic_error);
}

}  // namespace
}  // namespace pneufem
