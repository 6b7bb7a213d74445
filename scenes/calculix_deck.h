#pragma once
// A complete CalculiX (.inp) deck of a scene: the identical mesh, materials, boundary conditions
// and cavity pressure, in mm / N / MPa / tonne, as one NLGEOM static step whose step time equals
// the pressure in kPa (0 -> load.max_kPa), with displacements written every load.step_kPa.
// This is how pneufem is cross-checked against an independent solver (scripts/crosscheck_calculix.py).
#include <string>
#include <vector>

#include "scenes/build_model.h"

namespace pneufem {

/// The materials are written as the deck reader reads them back (scenes/inp/materials.h): a scene with
/// mesh.source = "inp" on this deck and no materials or parts of its own builds the same materials.
/// Effects with no Abaqus keyword (fatigue, registered effects) are not written; `notes` names them.
std::string calculix_deck(const Scene& scene, const BuiltModel& model, std::vector<std::string>* notes = nullptr);

}  // namespace pneufem
