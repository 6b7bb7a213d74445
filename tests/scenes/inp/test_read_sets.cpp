// The deck reader's sets (scenes/inp/read_sets.cpp): GENERATE over undefined ids, and the errors of
// a set that is unknown or of the wrong kind, with file, line and hint. The sets of hand-written decks
// are checked whole in test_reader.cpp.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "tests/scenes/inp/deck_files.h"

namespace pneufem {
namespace {

using namespace pneufem::test;

TEST_F(InpFiles, GenerateSkipsUndefinedIdsWithAWarning) {
  const InpDeck d = read_inp(write("gen.inp",
                                   "*NODE\n1,0,0,0\n2,1,0,0\n3,0,1,0\n5,0,0,1\n*ELEMENT,TYPE=C3D4\n1,1,2,3,5\n"
                                   "*NSET,NSET=N,GENERATE\n1,5\n*NSET,NSET=HUGE,GENERATE\n2,900000000,3\n"),
                             1.0);
  EXPECT_EQ(ids_of(d.mesh.node_sets.at("N"), d.mesh.node_ids), (std::vector<long>{1, 2, 3, 5}));
  EXPECT_EQ(ids_of(d.mesh.node_sets.at("HUGE"), d.mesh.node_ids), (std::vector<long>{2, 5}));
  EXPECT_EQ(count_containing(d.warnings, "gen.inp:9: GENERATE 1, 5, 1 of N: 1 undefined node id(s) skipped"), 1);
}

TEST_F(InpFiles, UnknownSetNameInSurface) {
  expect_error(kNodes + "*ELEMENT, TYPE=C3D4, ELSET=BODY\n1, 1, 2, 3, 4\n*SURFACE, NAME=S\nbody, S1\nnope, S2\n", 10,
               {"unknown element set 'nope' in *SURFACE S", "define it with *ELSET"});
}

TEST_F(InpFiles, NodeSetWhereAnElementSetIsDue) {
  expect_error(kNodes + "*NSET, NSET=N\n1\n*ELEMENT, TYPE=C3D4\n1, 1, 2, 3, 4\n*ELSET, ELSET=E\nN\n", 11,
               {"is a node set, not an element set"});
}

}  // namespace
}  // namespace pneufem
