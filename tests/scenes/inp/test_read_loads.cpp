// The deck reader's loads and boundary conditions (scenes/inp/read_loads.cpp): the errors of a bad
// element face in *SURFACE or *DLOAD and of a non-homogeneous or unknown *BOUNDARY, with file, line
// and hint. The loads of hand-written decks are checked whole in test_reader.cpp.
#include <gtest/gtest.h>

#include <string>

#include "tests/scenes/inp/deck_files.h"

namespace pneufem {
namespace {

using namespace pneufem::test;

TEST_F(InpFiles, BadSurfaceFaceAndDloadFace) {
  const std::string head = kNodes + "*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n";
  expect_error(head + "*SURFACE, NAME=S\n1, S5\n", 9, {"S5 names face 5 of element 1, a C3D4 with faces 1-4", "use S1..S4"});
  expect_error(head + "*SURFACE, NAME=S\n1, S7\n", 9, {"'S7' is not an element face", "S1..S6 (hexahedra)"});
  expect_error(head + "*DLOAD\n1, P6, 1.0\n", 9, {"faces 1-4", "P1..P4"});
  expect_error(head + "*DLOAD\n1, P2\n", 9, {"without a magnitude"});
}

TEST_F(InpFiles, NonzeroBoundaryValue) {
  expect_error(kNodes + "*NSET, NSET=FIX\n1, 2\n*BOUNDARY\nFIX, 1, 3\nFIX, 3, 3, 0.5\n", 10,
               {"value 0.5 is not zero", "only homogeneous conditions"});
  expect_error(kNodes + "*BOUNDARY\n1, XASYMM\n", 7, {"'XASYMM'", "ENCASTRE"});
}

}  // namespace
}  // namespace pneufem
