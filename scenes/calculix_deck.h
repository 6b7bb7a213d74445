#pragma once
// A complete CalculiX (.inp) deck of a scene: the identical mesh, materials, boundary conditions
// and cavity pressure, in mm / N / MPa / tonne, as one NLGEOM static step whose step time equals
// the pressure in kPa (0 -> load.max_kPa), with displacements written every load.step_kPa.
// This is how pneufem is cross-checked against an independent solver (scripts/crosscheck_calculix.py).
#include <string>

#include "scenes/build_model.h"

namespace pneufem {

std::string calculix_deck(const Scene& scene, const BuiltModel& model);

}  // namespace pneufem
