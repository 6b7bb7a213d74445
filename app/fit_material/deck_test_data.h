#pragma once
// Test data inside an Abaqus deck: a *MATERIAL whose *HYPERELASTIC has TEST DATA INPUT, followed by
// *UNIAXIAL TEST DATA, *BIAXIAL TEST DATA, *PLANAR TEST DATA (data lines: nominal stress, nominal
// strain) and *VOLUMETRIC TEST DATA (pressure, volume ratio J), as the Abaqus Analysis User's Guide
// ("Hyperelastic behavior of rubberlike materials", test data) and its keywords reference write them.
// The law named on the *HYPERELASTIC line (YEOH, NEO HOOKE, MOONEY-RIVLIN, OGDEN with N = 1..3, or
// POLYNOMIAL / REDUCED POLYNOMIAL with N = 1, i.e. Mooney-Rivlin / neo-Hookean) is what Abaqus would
// fit. Deck numbers carry no unit: the deck's length unit says which consistent system it is, mm
// (N, MPa; pneufem's exported decks and mesh.length_unit's default) or m (N, Pa). *INCLUDE is followed
// (the deck text layer of scenes/inp).
#include <string>
#include <vector>

#include "fit/fit.h"
#include "fit/volumetric.h"

namespace pneufem {

struct DeckTestData {
  std::string material;  ///< NAME= of the *MATERIAL, as written
  std::string law;       ///< the --model word for the *HYPERELASTIC line ("yeoh", "ogden3", ...; none named: mooney_rivlin, Abaqus's default POLYNOMIAL N=1)
  std::string where;     ///< "<file>:<line>" of the *HYPERELASTIC line
  std::vector<fit::TestCurve> tests;
  std::vector<fit::VolumetricCurve> volumetric;
};

/// Every *MATERIAL of the deck with TEST DATA INPUT, in order. `length_unit` "mm" (stresses in MPa)
/// or "m" (Pa). Throws InputError "<file>:<line>: ..." for a malformed data line, a test data block
/// outside a *HYPERELASTIC, TEST DATA INPUT, or a law pneufem has not (e.g. ARRUDA-BOYCE).
std::vector<DeckTestData> read_deck_test_data(const std::string& path, const std::string& length_unit);

}  // namespace pneufem
