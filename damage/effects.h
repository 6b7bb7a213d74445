#pragma once
// Factory for the inelastic effects of damage/: each wraps a split base law (yeoh, neo_hookean,
// mooney_rivlin, ogden) and modifies its isochoric response only.
//
// Why viscoelasticity lives in damage/. The folder holds the inelastic decorators, of which two are
// damage (Mullins, fatigue) and one is not (Prony viscoelasticity); all three are the same kind of
// object: a Material wrapping a base law, with its own committed/trial history in front of the
// base's (damage/decorator.h), one entry of the effect registry (damage/registry.h) and one derivative
// battery (tests/damage/), so they are kept together under the name of the majority, as FEBio's
// damage materials (FEDamageMaterial) wrap an elastic base the same way. Renaming the folder and the
// pneufem::damage target would touch every include for no change in what the code does.
//
//   make_mullins      Ogden-Roxburgh Mullins softening (mullins.h): depends on the peak energy only.
//   make_fatigue      progressive, irreversible fatigue damage driven by time above a threshold (fatigue.h).
//   make_viscoelastic Prony-series finite-strain viscoelasticity; the base is the instantaneous or the
//                     long-term law (ViscoParams::moduli, viscoelastic.h).
//
// Order. Mullins and fatigue are driven by the base's isochoric energy and need it to be a potential
// of the base's stress, so they reject a fatigue or viscoelastic base; decorate() applies the effects
// in the one order that always works: viscoelastic(fatigue(mullins(base))).
#include <optional>

#include "damage/fatigue.h"
#include "damage/mullins.h"
#include "damage/viscoelastic.h"

namespace pneufem {

/// Each throws InputError (message naming the effect and the parameter) for bad parameters or bases.
MaterialPtr make_mullins(MaterialPtr base, const MullinsParams& p);
MaterialPtr make_fatigue(MaterialPtr base, const FatigueParams& p);
MaterialPtr make_viscoelastic(MaterialPtr base, const ViscoParams& p);

/// Which effects to switch on (a scene's material block); absent = off.
struct EffectParams {
  std::optional<MullinsParams> mullins;
  std::optional<FatigueParams> fatigue;
  std::optional<ViscoParams> viscoelastic;
};

/// Applies the requested effects in the canonical order viscoelastic(fatigue(mullins(base))).
/// With no effect requested, returns `base` itself.
MaterialPtr decorate(MaterialPtr base, const EffectParams& effects);

}  // namespace pneufem
