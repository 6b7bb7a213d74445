// The material-effect registry (damage/registry.h): a user-defined effect registered by name is
// checked by the derivative battery, switched on from a scene, and validated with actionable errors.
//
// The example effect is the one docs/adding_an_effect.md walks through: "constant_softening",
// psi -> (1 - a) psi (the whole energy, so it equals stiffness_scale = 1 - a), a in [0, 0.9].
#include <cmath>
#include <functional>
#include <limits>
#include <random>

#include <gtest/gtest.h>

#include "core/errors.h"
#include "damage/effects.h"
#include "damage/registry.h"
#include "engine/quasi_static.h"
#include "materials/hyperelastic.h"
#include "scenes/build_model.h"
#include "tests/support/input_error.h"

namespace pneufem {
namespace {

// ---- The example effect (the doc's listing) ----

/// psi = (1 - a) psi_base, P = (1 - a) P_base, A = (1 - a) A_base; no state of its own.
class ConstantSoftening final : public Material {
 public:
  ConstantSoftening(MaterialPtr base, double a) : base_(std::move(base)), a_(a) {
    if (!base_) throw InputError("constant_softening: no base material");
    if (!(a_ >= 0.0 && a_ < 1.0)) throw InputError("constant_softening: a must lie in [0, 1), got " + std::to_string(a_));
  }
  std::string name() const override { return "constant_softening(" + base_->name() + ")"; }
  int state_size() const override { return base_->state_size(); }
  void init_state(std::span<double> s) const override { base_->init_state(s); }
  void evaluate(std::span<const Mat3> F, const TimeStep& step, std::span<const double> state_old,
                std::span<double> state_new, std::span<PointResponse> out, bool tangent) const override {
    base_->evaluate(F, step, state_old, state_new, out, tangent);
    const double k = 1.0 - a_;
    for (PointResponse& r : out) {
      r.psi_iso *= k;
      r.psi_vol *= k;
      r.P_iso *= k;
      r.P_vol *= k;
      if (tangent) {
        r.A_iso *= k;
        r.A_vol *= k;
      }
    }
  }
  PointFields fields(std::span<const double> s) const override { return base_->fields(s); }
  double initial_shear_modulus() const override { return (1.0 - a_) * base_->initial_shear_modulus(); }
  double initial_bulk_modulus() const override { return (1.0 - a_) * base_->initial_bulk_modulus(); }
  bool is_split() const override { return base_->is_split(); }

 private:
  MaterialPtr base_;
  double a_;
};

void register_example_once() {
  static const bool done = [] {
    MaterialEffect e;
    e.name = "constant_softening";
    e.doc = "uniform softening of the whole energy, psi -> (1 - a) psi";
    e.params = {{"a", "1", "softened fraction of the energy", 0.0, 0.0, 0.9, false}};
    e.decorate = [](MaterialPtr base, const std::map<std::string, double>& v) {
      return std::make_shared<const ConstantSoftening>(std::move(base), v.at("a"));
    };
    e.history = false;
    register_material_effect(e);
    return true;
  }();
  (void)done;
}

using pneufem::test::error_of;

PointResponse eval(const Material& m, const Mat3& F, bool tangent = true) {
  PointResponse r;
  m.evaluate(std::span<const Mat3>(&F, 1), TimeStep{}, {}, {}, std::span<PointResponse>(&r, 1), tangent);
  return r;
}

MaterialPtr ecoflex() { return std::make_shared<InvariantMaterial<Yeoh>>(Yeoh(0.019e6, 900.0, -4.75, 100 * 0.038e6)); }

// ---- Registry contents and validation ----

TEST(Registry, ListsTheBuiltInsFirstInTheirOrder) {
  const auto all = material_effects();
  ASSERT_GE(all.size(), 3u);
  EXPECT_EQ(all[0]->name, "mullins");
  EXPECT_EQ(all[1]->name, "fatigue");
  EXPECT_EQ(all[2]->name, "viscoelastic");
  EXPECT_LT(all[0]->order, all[1]->order);
  EXPECT_LT(all[1]->order, all[2]->order);
  for (const MaterialEffect* e : all)
    for (const EffectParameter& p : e->params) {
      EXPECT_LT(p.lo, p.hi) << e->name << "." << p.name;
      EXPECT_GE(p.default_value, p.lo) << e->name << "." << p.name;
      EXPECT_LE(p.default_value, p.hi) << e->name << "." << p.name;
    }
  // The registry's decorate builds the same law as the factory.
  const MaterialEffect* m = find_material_effect("mullins");
  ASSERT_NE(m, nullptr);
  const MaterialPtr a = m->decorate(ecoflex(), {{"r", 3.0}, {"m_MPa", 0.01}, {"beta", 0.1}});
  const MaterialPtr b = make_mullins(ecoflex(), MullinsParams{3.0, 0.01e6, 0.1});
  EXPECT_EQ(a->name(), b->name());
  const Mat3 F = Vec3(1.3, 0.9, 0.85).asDiagonal();
  EXPECT_EQ(eval(*a, F).P(), eval(*b, F).P());
  EXPECT_EQ(find_material_effect("no_such_effect"), nullptr);
}

TEST(Registry, RejectsBadRegistrations) {
  register_example_once();
  MaterialEffect good;
  good.name = "test_effect_x";
  good.params = {{"k", "1", "", 0.5, 0.0, 1.0, false}};
  good.decorate = [](MaterialPtr b, const std::map<std::string, double>&) { return b; };
  auto err = [](MaterialEffect e) { return error_of([&] { register_material_effect(e); }); };
  MaterialEffect e = good;
  e.name = "constant_softening";
  EXPECT_NE(err(e).find("already registered"), std::string::npos);
  e = good;
  e.name = "Bad-Name";
  EXPECT_NE(err(e).find("[a-z][a-z0-9_]*"), std::string::npos);
  e = good;
  e.params[0].lo = 2.0;
  EXPECT_NE(err(e).find("lo < hi"), std::string::npos);
  e = good;
  e.params[0].default_value = 3.0;
  EXPECT_NE(err(e).find("outside"), std::string::npos);
  e = good;
  e.params[0].log = true;
  EXPECT_NE(err(e).find("lo > 0"), std::string::npos);
  e = good;
  e.params[0].name = "enabled";
  EXPECT_NE(err(e).find("'enabled'"), std::string::npos);
  e = good;
  e.params.push_back(e.params[0]);
  EXPECT_NE(err(e).find("twice"), std::string::npos);
  e = good;
  e.decorate = nullptr;
  EXPECT_NE(err(e).find("no decorate"), std::string::npos);
  EXPECT_EQ(find_material_effect("test_effect_x"), nullptr);  // nothing half-registered
}

// ---- The derivative battery for the registered effect ----
// Central differences with h = cbrt(eps) |F|/sqrt(3): truncation h^2/6 |P'''| plus round-off
// eps |P| / h, both below 1e-7 of the tangent scale M = max(|A|, mu0) for Yeoh at these stretches
// (the bound tests/materials derives for the base law; the effect multiplies by a constant).
TEST(Registry, ExampleEffectPassesTheDerivativeBattery) {
  register_example_once();
  const MaterialPtr m = find_material_effect("constant_softening")->decorate(ecoflex(), {{"a", 0.3}});
  const double mu0 = 0.038e6, tol = 1e-7, h0 = std::cbrt(std::numeric_limits<double>::epsilon());
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(0.75, 1.4), q(-1.0, 1.0);
  for (int n = 0; n < 6; ++n) {
    const Eigen::Quaterniond R1(q(rng), q(rng), q(rng), q(rng)), R2(q(rng), q(rng), q(rng), q(rng));
    const Mat3 F = R1.normalized().toRotationMatrix() * Vec3(u(rng), u(rng), u(rng)).asDiagonal() *
                   R2.normalized().toRotationMatrix().transpose();
    const PointResponse r = eval(*m, F);
    const double h = h0 * F.norm() / std::sqrt(3.0);
    Mat3 P_fd;
    Mat9 A_fd;
    for (int k = 0; k < 3; ++k)
      for (int L = 0; L < 3; ++L) {
        Mat3 Fp = F, Fm = F;
        Fp(k, L) += h;
        Fm(k, L) -= h;
        const PointResponse rp = eval(*m, Fp), rm = eval(*m, Fm);
        P_fd(k, L) = (rp.psi() - rm.psi()) / (2 * h);
        A_fd.col(flat(k, L)) = flatten(rp.P() - rm.P()) / (2 * h);
      }
    const double M = std::max(r.A().cwiseAbs().maxCoeff(), mu0);
    EXPECT_LE((P_fd - r.P()).cwiseAbs().maxCoeff(), tol * std::max(r.P().cwiseAbs().maxCoeff(), mu0));
    EXPECT_LE((A_fd - r.A()).cwiseAbs().maxCoeff(), tol * M);
    // Guard against a vacuous pass: the response is really (1 - a) times the base.
    EXPECT_NEAR(r.P().norm(), 0.7 * eval(*ecoflex(), F).P().norm(), 1e-12 * r.P().norm());
    // Objectivity.
    const Mat3 Q = Eigen::Quaterniond(q(rng), q(rng), q(rng), q(rng)).normalized().toRotationMatrix();
    EXPECT_LE((eval(*m, Q * F).P() - Q * r.P()).cwiseAbs().maxCoeff(), 1e-10 * std::max(r.P().norm(), mu0));
  }
  const PointResponse r0 = eval(*m, Mat3::Identity());
  EXPECT_LE(r0.P().cwiseAbs().maxCoeff(), 1e-10 * mu0);
  EXPECT_NE(error_of([&] { find_material_effect("constant_softening")->decorate(ecoflex(), {{"a", 1.5}}); })
                .find("a must lie in [0, 1)"),
            std::string::npos);
}

// ---- In scenes ----

const std::vector<std::string> kTiny = {"geometry.chambers=3", "mesh.h_mm=6.0", "load.max_kPa=6",
                                        "load.step_kPa=3",     "load.hold_s=1", "load.ramp_s=0.5",
                                        "load.mark_s=0.5"};

std::vector<double> angles(const std::vector<std::string>& more) {
  std::vector<std::string> sets = kTiny;
  sets.insert(sets.end(), more.begin(), more.end());
  auto bm = build_model(Scene::load("", sets));
  Assembler A(bm->model);
  QuasiStaticRun run(A, bm->solver.quasi_static);
  std::vector<double> out;
  run.run(bm->load, [&](const StateRecord& r, const Eigen::VectorXd&, const std::vector<double>&) { out.push_back(r.angle_deg); });
  return out;
}

// constant_softening a scales the silicone's whole energy by 1 - a, exactly what stiffness_scale
// = 1 - a does: the same equilibria. 1 - 0.2 and 0.8 may differ by one ulp, so the angles agree to
// rounding of the Newton solve (1e-10 relative), not bit for bit.
TEST(Registry, SceneEffectEqualsTheStiffnessScale) {
  register_example_once();
  const std::vector<double> fx = angles({"materials.silicone.constant_softening.enabled=true",
                                         "materials.silicone.constant_softening.a=0.2"});
  const std::vector<double> sc = angles({"materials.silicone.stiffness_scale=0.8"});
  const std::vector<double> ref = angles({});
  ASSERT_EQ(fx.size(), sc.size());
  for (std::size_t i = 0; i < fx.size(); ++i) EXPECT_NEAR(fx[i], sc[i], 1e-10 * std::abs(sc.back())) << i;
  EXPECT_GT(fx.back(), ref.back() * 1.05);  // and it softens: the silicone bends clearly more
  // Missing parameters take the registry default (a = 0): the unchanged law.
  EXPECT_EQ(angles({"materials.silicone.constant_softening.enabled=true"}), ref);
}

TEST(Registry, SceneOrdersEffectsAndRejectsBadParameters) {
  register_example_once();
  const Scene s = Scene::load("", {"materials.silicone.constant_softening.enabled=true",
                                   "materials.silicone.constant_softening.a=0.2", "materials.silicone.mullins.enabled=true"});
  EXPECT_EQ(make_material(s, "silicone")->name(), "mullins(constant_softening(yeoh))");  // order 0 < mullins' 100
  std::string e = error_of([] {
    make_material(Scene::load("", {"materials.silicone.constant_softening.enabled=true",
                                   "materials.silicone.constant_softening.b=0.2"}),
                  "silicone");
  });
  EXPECT_NE(e.find("materials.silicone.constant_softening.b"), std::string::npos) << e;
  EXPECT_NE(e.find("allowed: a, enabled"), std::string::npos) << e;
  e = error_of([] {
    make_material(Scene::load("", {"materials.silicone.constant_softening.enabled=true",
                                   "materials.silicone.constant_softening.a=1.5"}),
                  "silicone");
  });
  EXPECT_NE(e.find("materials.silicone.constant_softening"), std::string::npos) << e;
  EXPECT_NE(e.find("a must lie in [0, 1)"), std::string::npos) << e;
  e = error_of([] { make_material(Scene::load("", {"materials.silicone.softening.enabled=true"}), "silicone"); });
  EXPECT_NE(e.find("constant_softening"), std::string::npos) << e;  // the unknown table lists the effects
}

// A non-local fatigue driver (materials.NAME.fatigue.nonlocal_radius_mm) reaches the engine through
// every layer wrapped around fatigue: the built-ins forward it; an effect registered in C++ that does
// not (ConstantSoftening, registered here outside fatigue) is refused rather than silently local.
TEST(Registry, ANonlocalFatigueDriverPassesThroughTheLayersOrIsRefused) {
  const std::vector<std::string> story = {"materials.silicone.mullins.enabled=true", "materials.silicone.fatigue.enabled=true",
                                          "materials.silicone.viscoelastic.enabled=true",
                                          "materials.silicone.fatigue.driver=\"max_principal_stretch\"",
                                          "materials.silicone.fatigue.nonlocal_radius_mm=1.5"};
  const MaterialPtr m = make_material(Scene::load("", story), "silicone");
  EXPECT_EQ(m->name(), "viscoelastic(fatigue(mullins(yeoh)))");
  EXPECT_DOUBLE_EQ(m->nonlocal().radius_m, 1.5e-3);
  EXPECT_EQ(m->nonlocal().kind, "fatigue:stretch");
  EXPECT_EQ(make_material(Scene::load("", {"materials.silicone.fatigue.enabled=true"}), "silicone")->nonlocal().radius_m, 0.0);
  std::string e = error_of([] {
    make_material(Scene::load("", {"materials.silicone.fatigue.enabled=true", "materials.silicone.fatigue.nonlocal_radius_mm=-1.0"}),
                  "silicone");
  });
  EXPECT_NE(e.find("materials.silicone.fatigue.nonlocal_radius_mm"), std::string::npos) << e;
  EXPECT_NE(e.find("must be >= 0 mm"), std::string::npos) << e;
  static const bool registered = [] {
    MaterialEffect fx;
    fx.name = "outer_softening";
    fx.doc = "constant_softening wrapped around the history effects";
    fx.params = {{"a", "1", "softened fraction", 0.1, 0.0, 0.9, false}};
    fx.order = 400;
    fx.decorate = [](MaterialPtr base, const std::map<std::string, double>& v) {
      return std::make_shared<const ConstantSoftening>(std::move(base), v.at("a"));
    };
    register_material_effect(fx);
    return true;
  }();
  (void)registered;
  std::vector<std::string> outer = story;
  outer.push_back("materials.silicone.outer_softening.enabled=true");
  e = error_of([&] { make_material(Scene::load("", outer), "silicone"); });
  EXPECT_NE(e.find("does not forward the non-local driver"), std::string::npos) << e;
  EXPECT_NE(e.find("constant_softening(viscoelastic(fatigue(mullins(yeoh))))"), std::string::npos) << e;
  outer.back() = "materials.silicone.fatigue.nonlocal_radius_mm=0.0";
  outer.push_back("materials.silicone.outer_softening.enabled=true");
  EXPECT_NO_THROW(make_material(Scene::load("", outer), "silicone"));  // local: nothing to forward
}

}  // namespace
}  // namespace pneufem
