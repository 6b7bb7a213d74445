#include "damage/effects.h"

#include <memory>

namespace pneufem {

MaterialPtr make_mullins(MaterialPtr base, const MullinsParams& p) {
  return std::make_shared<const Mullins>(std::move(base), p);
}

MaterialPtr make_fatigue(MaterialPtr base, const FatigueParams& p) {
  return std::make_shared<const FatigueDamage>(std::move(base), p);
}

MaterialPtr make_viscoelastic(MaterialPtr base, const ViscoParams& p) {
  return std::make_shared<const Viscoelastic>(std::move(base), p);
}

MaterialPtr decorate(MaterialPtr base, const EffectParams& effects) {
  if (effects.mullins) base = make_mullins(std::move(base), *effects.mullins);
  if (effects.fatigue) base = make_fatigue(std::move(base), *effects.fatigue);
  if (effects.viscoelastic) base = make_viscoelastic(std::move(base), *effects.viscoelastic);
  return base;
}

}  // namespace pneufem
