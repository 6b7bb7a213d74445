#include "damage/decorator.h"

#include "damage/fatigue.h"
#include "damage/viscoelastic.h"

namespace pneufem::detail {

void require_potential_base(const MaterialPtr& base, const std::string& effect) {
  if (dynamic_cast<const FatigueDamage*>(base.get()) || dynamic_cast<const Viscoelastic*>(base.get()))
    throw InputError(effect + ": cannot wrap '" + base->name() + "': " + effect +
                     " is driven by the base's isochoric energy, which must be a potential of its stress; "
                     "apply the effects in the order viscoelastic(fatigue(mullins(base)))");
}

}  // namespace pneufem::detail
