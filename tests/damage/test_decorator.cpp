// damage/decorator.h: the plumbing the decorators share - the layout of a point's state block
// [own | base], the batched call of the base (stress_base: the base's slices gathered into consecutive
// blocks and scattered back), the check that a base's energy is a potential, and the two scalar
// helpers, and the forwarding of MaterialDecorator. The decorators' physics is tested by their own
// files and the derivative battery.
#include "damage/decorator.h"

#include <span>
#include <string>
#include <type_traits>
#include <vector>

#include <gtest/gtest.h>

#include "damage/effects.h"
#include "damage/fatigue.h"
#include "damage/fatigue_uniform.h"
#include "damage/mullins.h"
#include "damage/viscoelastic.h"
#include "materials/hyperelastic.h"
#include "tests/support/input_error.h"

namespace pneufem {
namespace {

MaterialPtr yeoh() { return std::make_shared<InvariantMaterial<Yeoh>>(Yeoh(0.02e6, 0.001e6, 0.0, 2e6)); }

TEST(Decorator, PointStateIsOwnThenBaseInConsecutiveBlocks) {
  std::vector<double> old(15), fresh(15);
  for (int i = 0; i < 15; ++i) old[i] = i;
  // 3 points of [own 2 | base 3]: point 1 is old[5..9].
  const detail::PointState p = detail::point_state(old, fresh, 1, 2, 3);
  ASSERT_EQ(p.own_old.size(), 2u);
  ASSERT_EQ(p.base_old.size(), 3u);
  EXPECT_EQ(p.own_old[0], 5.0);
  EXPECT_EQ(p.base_old[0], 7.0);
  EXPECT_EQ(p.base_old[2], 9.0);
  EXPECT_EQ(p.own_new.data(), fresh.data() + 5);
  EXPECT_EQ(p.base_new.data(), fresh.data() + 7);
  // Empty spans stay empty: the virgin state, and no trial state wanted.
  const detail::PointState v = detail::point_state({}, {}, 2, 2, 3);
  EXPECT_TRUE(v.own_old.empty() && v.base_old.empty() && v.own_new.empty() && v.base_new.empty());
}

TEST(Decorator, StressBaseGathersAndScattersTheBaseState) {
  // The base is a Mullins-softened Yeoh (2 doubles per point); the pretend decorator owns 3 more.
  const MaterialPtr base = make_mullins(yeoh(), {2.0, 1e3, 0.1});
  const std::size_t own = 3, nb = static_cast<std::size_t>(base->state_size()), ss = own + nb;
  ASSERT_EQ(nb, 2u);
  const int n = 5;
  StressBatch b, ref;
  b.n = ref.n = n;
  for (int l = 0; l < n; ++l) {
    Mat3 F = Mat3::Identity();
    F(0, 0) = 1.1 + 0.05 * l;
    F(0, 1) = 0.02 * l;
    b.set_F(l, F);
    ref.set_F(l, F);
  }
  b.pad();
  ref.pad();
  const TimeStep step{1.0, 1.0};
  // From the virgin state: the base's trial blocks land in the base slots, the own slots keep their values.
  std::vector<double> state_new(n * ss, -7.0), ref_new(n * nb, 0.0);
  ASSERT_TRUE(detail::stress_base(*base, b, step, {}, state_new, own));
  base->stress(ref, step, {}, ref_new);
  for (int l = 0; l < n; ++l) {
    EXPECT_EQ(b.psi_iso[l], ref.psi_iso[l]) << l;  // the same call of the base: bit for bit
    EXPECT_EQ(b.P_iso[0][l], ref.P_iso[0][l]) << l;
    for (std::size_t i = 0; i < own; ++i) EXPECT_EQ(state_new[l * ss + i], -7.0) << l;
    for (std::size_t i = 0; i < nb; ++i) EXPECT_EQ(state_new[l * ss + own + i], ref_new[l * nb + i]) << l;
  }
  // From a committed state: the base sees its own slices of it (consecutive), not the decorator's.
  std::vector<double> state_old = state_new, again(n * ss, 0.0), ref_again(n * nb, 0.0);
  for (int l = 0; l < n; ++l) state_old[l * ss + own] *= 1.5;  // a larger W_max than the trial wrote
  std::vector<double> ref_old(n * nb);
  for (int l = 0; l < n; ++l)
    for (std::size_t i = 0; i < nb; ++i) ref_old[l * nb + i] = state_old[l * ss + own + i];
  ASSERT_TRUE(detail::stress_base(*base, b, step, state_old, again, own));
  base->stress(ref, step, ref_old, ref_again);
  for (int l = 0; l < n; ++l) {
    EXPECT_EQ(b.psi_iso[l], ref.psi_iso[l]) << l;
    for (std::size_t i = 0; i < nb; ++i) EXPECT_EQ(again[l * ss + own + i], ref_again[l * nb + i]) << l;
  }
}

TEST(Decorator, AnEffectOfTheEnergyNeedsABaseWhoseEnergyIsAPotential) {
  EXPECT_EQ(pneufem::test::error_of([] { detail::require_potential_base(yeoh(), "mullins"); }), "(no error)");
  const MaterialPtr visco = make_viscoelastic(yeoh(), {{0.5}, {10.0}, ViscoModuli::long_term});
  const std::string e = pneufem::test::error_of([&] { detail::require_potential_base(visco, "mullins"); });
  EXPECT_NE(e.find("mullins: cannot wrap '" + visco->name() + "'"), std::string::npos) << e;
  EXPECT_NE(e.find("viscoelastic(fatigue(mullins(base)))"), std::string::npos) << e;
}

TEST(Decorator, CombinedDamageAndMacaulayBracket) {
  EXPECT_DOUBLE_EQ(detail::combine_damage(0.2, 0.5), 0.6);  // 1 - 0.8 * 0.5
  // No damage is the identity, to the rounding of 1 - (1 - d) (0.3 comes back as 0.30000000000000004).
  EXPECT_DOUBLE_EQ(detail::combine_damage(0.0, 0.3), 0.3);
  EXPECT_DOUBLE_EQ(detail::combine_damage(0.3, 0.0), 0.3);
  EXPECT_EQ(detail::combine_damage(0.0, 0.0), 0.0);
  EXPECT_EQ(detail::combine_damage(1.0, 0.4), 1.0);  // a failed point stays failed
  EXPECT_EQ(detail::macaulay(-1.0), 0.0);
  EXPECT_EQ(detail::macaulay(2.5), 2.5);
}

TEST(Decorator, ForwardsWhatTheLayerDoesNotChangeButNotCycleJumping) {
  const MaterialPtr base = yeoh();
  const auto mullins = std::make_shared<const Mullins>(base, MullinsParams{2.0, 1e3, 0.1});
  const auto fatigue = std::make_shared<const FatigueDamage>(mullins, FatigueParams{100.0, 10.0});
  const auto uniform = std::make_shared<const UniformFatigue>(base, UniformFatigueParams{0.05, 2.0});
  EXPECT_EQ(mullins->name(), "mullins(" + base->name() + ")");
  EXPECT_EQ(fatigue->name(), "fatigue(mullins(" + base->name() + "))");
  EXPECT_EQ(uniform->name(), "fatigue_uniform(" + base->name() + ")");
  // [own | base], each layer's own doubles at the head of its block.
  EXPECT_EQ(mullins->own_state_size(), Mullins::kOwnState);
  EXPECT_EQ(fatigue->own_state_size(), 1);
  EXPECT_EQ(fatigue->state_size(), 1 + Mullins::kOwnState);
  EXPECT_EQ(uniform->state_size(), UniformFatigue::kOwnState);
  EXPECT_EQ(fatigue->base(), mullins);
  for (const MaterialPtr& m : {MaterialPtr(mullins), MaterialPtr(fatigue), MaterialPtr(uniform)}) {
    EXPECT_EQ(m->initial_shear_modulus(), base->initial_shear_modulus()) << m->name();
    EXPECT_EQ(m->initial_bulk_modulus(), base->initial_bulk_modulus()) << m->name();
    EXPECT_EQ(m->linear_drive(), base->linear_drive()) << m->name();
    EXPECT_EQ(m->nonlocal().radius_m, 0.0) << m->name();
  }
  // Only a layer that says how its own history extrapolates jumps (decorator.h): Mullins and fatigue
  // do, the uniform fatigue law does not, whatever its base can do.
  EXPECT_TRUE(mullins->jumps_cycles());
  EXPECT_TRUE(fatigue->jumps_cycles());
  EXPECT_TRUE(base->jumps_cycles());
  EXPECT_FALSE(uniform->jumps_cycles());
  // The shared constructor's check names the layer.
  EXPECT_NE(pneufem::test::error_of([] { Mullins(nullptr, MullinsParams{2.0, 1e3, 0.1}); }).find("mullins: no base material"),
            std::string::npos);
}

// Viscoelastic is on the same base (decorator.h): the shared forwarding (the name, the [own | base]
// sizes with own = 6 (1 + terms), the bulk modulus, the non-local driver of a fatigue law inside, reading
// and writing the base's slice, base()) and its own overrides (the instantaneous shear modulus, its
// branches' linear drive rather than the base's, cycle jumping as the base's).
TEST(Decorator, ViscoelasticForwardsTheNonlocalDriverButNotItsDriveOrShearModulus) {
  static_assert(std::is_base_of_v<MaterialDecorator, Viscoelastic>);
  const MaterialPtr base = yeoh();
  FatigueParams fp{100.0, 10.0};
  fp.nonlocal_radius_m = 0.004;
  const auto fatigue = std::make_shared<const FatigueDamage>(base, fp);
  const auto visco =
      std::make_shared<const Viscoelastic>(fatigue, ViscoParams{{0.5, 0.25}, {1.0, 10.0}, ViscoModuli::long_term});
  EXPECT_EQ(visco->name(), "viscoelastic(fatigue(" + base->name() + "))");
  EXPECT_EQ(visco->own_state_size(), 6 * (1 + 2));
  EXPECT_EQ(visco->state_size(), 18 + fatigue->state_size());
  EXPECT_EQ(visco->base(), fatigue);
  EXPECT_EQ(visco->initial_bulk_modulus(), base->initial_bulk_modulus());
  EXPECT_EQ(visco->initial_shear_modulus(), 1.75 * base->initial_shear_modulus());  // (1 + sum gamma) mu
  EXPECT_EQ(visco->linear_drive().terms, 2);  // its own branches; the fatigue law inside has none
  EXPECT_EQ(fatigue->linear_drive().terms, 0);
  EXPECT_EQ(visco->nonlocal().radius_m, 0.004);
  EXPECT_EQ(visco->nonlocal().kind, fatigue->nonlocal().kind);
  std::vector<double> state(static_cast<std::size_t>(visco->state_size()), -1.0);
  visco->init_state(state);
  const std::span<double> base_slice = std::span<double>(state).subspan(18);
  Mat3 F = Mat3::Identity();
  F(0, 0) = 1.3;
  F(0, 1) = 0.1;
  EXPECT_EQ(visco->nonlocal_driver(F, state), fatigue->nonlocal_driver(F, base_slice));
  EXPECT_GT(visco->nonlocal_driver(F, state), 0.0);
  visco->set_nonlocal_driver(state, 2.0 * fp.W_th_Pa, fp.W_th_Pa);  // rho = 0.5 into the fatigue law's slice
  EXPECT_EQ(base_slice[1], 0.5);
  for (std::size_t i = 0; i < 18; ++i) EXPECT_EQ(state[i], 0.0) << i;  // its own block untouched (virgin)
  EXPECT_EQ(visco->jumps_cycles(), fatigue->jumps_cycles());
  EXPECT_NE(pneufem::test::error_of([] { Viscoelastic(nullptr, ViscoParams{{0.5}, {1.0}}); })
                .find("viscoelastic: no base material"),
            std::string::npos);
}

}  // namespace
}  // namespace pneufem
