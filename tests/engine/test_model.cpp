// engine/model.h: validate() - a model the solvers can run, or an InputError saying what is wrong
// with it: no mesh, a connectivity or a face or a tip node outside the mesh, an element without a
// material, a density that is not > 0, nothing fixed. (The membranes' checks are tested with the
// membranes, tests/engine/test_membrane.cpp.)
#include "engine/model.h"

#include <algorithm>
#include <string>

#include <gtest/gtest.h>

#include "tests/engine/test_meshes.h"
#include "tests/support/input_error.h"

namespace pneufem {
namespace {

using pneufem::test::error_of;

Model valid() {
  Model m = testing::single_part_model(testing::box(0.01, 0.02, 0.01, 1, 2, 1, ElementType::Tet4), testing::ecoflex());
  testing::fix(m, testing::nodes_on_plane(m.mesh, 1, 0.0), {true, true, true});
  m.pressure_faces.push_back({0, 3});
  m.angle.tip_nodes = testing::nodes_on_plane(m.mesh, 1, 0.02);
  return m;
}

bool says(const std::string& e, const std::string& what) { return e.find(what) != std::string::npos; }

TEST(Model, AValidModelPasses) { EXPECT_EQ(error_of([] { validate(valid()); }), "(no error)"); }

TEST(Model, EachBrokenPartIsNamed) {
  Model m = valid();
  m.mesh.conn[5] = m.mesh.num_nodes();
  EXPECT_TRUE(says(error_of([&] { validate(m); }), "connectivity refers to a node index outside the mesh"));

  m = valid();
  m.element_part[1] = 7;  // no such part
  std::string e = error_of([&] { validate(m); });
  EXPECT_TRUE(says(e, "1 element(s) have no material, e.g. ")) << e;
  EXPECT_TRUE(says(e, "[[parts]]")) << e;  // what to do

  m = valid();
  m.parts[0].density_kg_m3 = 0.0;
  EXPECT_TRUE(says(error_of([&] { validate(m); }), "density must be > 0 kg/m^3"));

  m = valid();
  std::fill(m.fixed.begin(), m.fixed.end(), 0);
  e = error_of([&] { validate(m); });
  EXPECT_TRUE(says(e, "no degree of freedom is fixed")) << e;
  EXPECT_TRUE(says(e, "fixed_set")) << e;

  m = valid();
  m.pressure_faces.push_back({0, 4});  // a tetrahedron has faces 0..3
  EXPECT_TRUE(says(error_of([&] { validate(m); }), "a pressure face refers to an element or face number outside"));

  m = valid();
  m.angle.tip_nodes.push_back(-1);
  EXPECT_TRUE(says(error_of([&] { validate(m); }), "a tip node index is outside the mesh"));

  m = valid();
  m.mesh = Mesh{};
  EXPECT_TRUE(says(error_of([&] { validate(m); }), "the model has no nodes or no elements"));
}

}  // namespace
}  // namespace pneufem
