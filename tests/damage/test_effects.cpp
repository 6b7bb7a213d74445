// damage/effects.h: the factories of the built-in effects and decorate(), which applies the requested
// ones in the canonical order viscoelastic(fatigue(mullins(base))) whatever order they are given in.
#include "damage/effects.h"

#include <string>

#include <gtest/gtest.h>

#include "materials/hyperelastic.h"

namespace pneufem {
namespace {

MaterialPtr yeoh() { return std::make_shared<InvariantMaterial<Yeoh>>(Yeoh(0.02e6, 0.001e6, 0.0, 2e6)); }

FatigueParams fatigue() {
  FatigueParams f;
  f.W_th_Pa = 500.0;
  f.tau_s = 100.0;
  return f;
}

TEST(Effects, DecorateAppliesTheEffectsInTheCanonicalOrder) {
  const MaterialPtr base = yeoh();
  EffectParams all;
  all.viscoelastic = ViscoParams{{0.5}, {10.0}, ViscoModuli::long_term};
  all.fatigue = fatigue();
  all.mullins = MullinsParams{2.0, 1e3, 0.1};
  const MaterialPtr m = decorate(base, all);
  EXPECT_EQ(m->name(), "viscoelastic(fatigue(mullins(" + base->name() + ")))");
  // Each layer's state in front of its base's: 2 (Mullins) + fatigue's + viscoelasticity's.
  EXPECT_EQ(m->state_size(), make_viscoelastic(make_fatigue(make_mullins(base, *all.mullins), *all.fatigue),
                                               *all.viscoelastic)->state_size());
  EXPECT_GT(m->state_size(), 2);
}

TEST(Effects, DecorateOnlyWhatIsRequested) {
  const MaterialPtr base = yeoh();
  EXPECT_EQ(decorate(base, {}), base);  // no effect: the base itself, not a copy
  EffectParams some;
  some.fatigue = fatigue();
  some.viscoelastic = ViscoParams{{0.5}, {10.0}, ViscoModuli::long_term};
  EXPECT_EQ(decorate(base, some)->name(), "viscoelastic(fatigue(" + base->name() + "))");
  EXPECT_EQ(make_mullins(base, {2.0, 1e3, 0.1})->name(), "mullins(" + base->name() + ")");
}

}  // namespace
}  // namespace pneufem
