// [[mesh.region_boxes]] (scenes/build_model.cpp): a user's correction of the region tags that a
// mesh's rules gave (the built-in mesher's, an STL mesh's, a deck's element sets). The expected
// tags are computed here from the definition (the element's corner-node centroid in the box, box
// after box), on the mesh the same scene builds without boxes.
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <vector>

#include "core/errors.h"
#include "scenes/build_model.h"

namespace pneufem {
namespace {

const std::vector<std::string> kSmall = {"geometry.chambers=2", "mesh.h_mm=6.0"};

std::vector<std::string> with(std::vector<std::string> sets, const std::string& more) {
  sets.push_back(more);
  return sets;
}

Eigen::Vector3d centroid(const Mesh& m, int e) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (int a = 0; a < 4; ++a) c += m.X[static_cast<std::size_t>(m.element(e)[a])];
  return c / 4.0;
}

bool in_box(const Eigen::Vector3d& c, const Eigen::Vector3d& lo_mm, const Eigen::Vector3d& hi_mm) {
  return ((1e3 * c).array() >= lo_mm.array()).all() && ((1e3 * c).array() <= hi_mm.array()).all();
}

std::string message_of(const std::vector<std::string>& sets) {
  try {
    build_model(Scene::load("", sets));
  } catch (const InputError& e) {
    return e.what();
  }
  return "no error";
}

// Two overlapping boxes: the elements in the first take its tag, those in the second (the overlap
// too) the second's, every other element keeps the built-in mesher's tag; the new tags are regions
// like any other ([regions.TAG] stiffness_scale makes their own part).
TEST(RegionBoxes, ElementsWhoseCentroidLiesInABoxTakeItsTagALaterBoxWins) {
  const auto plain = build_model(Scene::load("", kSmall));
  const Mesh& m0 = plain->model.mesh;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e9), hi = -lo;
  for (const Eigen::Vector3d& x : m0.X) lo = lo.cwiseMin(1e3 * x), hi = hi.cwiseMax(1e3 * x);
  // Box A: the upper half in z; box B: the far half in y of box A's z range (overlaps A).
  const Eigen::Vector3d a_lo(lo.x() - 1, lo.y() - 1, 0.5 * (lo.z() + hi.z())), a_hi(hi.x() + 1, hi.y() + 1, hi.z() + 1);
  const Eigen::Vector3d b_lo(lo.x() - 1, 0.5 * (lo.y() + hi.y()), a_lo.z()), b_hi = a_hi;
  auto v = [](const Eigen::Vector3d& x) {  // piece by piece: GCC 12's -Wrestrict false positive on "[" + std::string
    std::string s = "[";
    s += std::to_string(x.x()) + ", " + std::to_string(x.y()) + ", " + std::to_string(x.z());
    s += "]";
    return s;
  };
  const std::string boxes = "mesh.region_boxes=[{region = \"upper\", min_mm = " + v(a_lo) + ", max_mm = " + v(a_hi) +
                            "}, {region = \"upper_far\", min_mm = " + v(b_lo) + ", max_mm = " + v(b_hi) + "}]";
  const auto boxed = build_model(Scene::load("", with(with(kSmall, boxes), "regions.upper_far.stiffness_scale=0.5")));
  const Mesh& m1 = boxed->model.mesh;
  ASSERT_EQ(m1.num_elements(), m0.num_elements());
  int n_upper = 0, n_far = 0, n_kept = 0;
  for (int e = 0; e < m0.num_elements(); ++e) {
    const Eigen::Vector3d c = centroid(m0, e);
    const std::string expected = in_box(c, b_lo, b_hi)   ? "upper_far"
                                 : in_box(c, a_lo, a_hi) ? "upper"
                                                         : m0.region_names[m0.region[e]];
    const std::string& got = m1.region_names[m1.region[e]];
    ASSERT_EQ(got, expected) << "element " << e;
    n_upper += got == "upper", n_far += got == "upper_far", n_kept += got == expected && got != "upper" && got != "upper_far";
  }
  EXPECT_GT(n_upper, 0);
  EXPECT_GT(n_far, 0);
  EXPECT_GT(n_kept, 0);
  int scaled_part = 0;
  for (const Part& p : boxed->model.parts) scaled_part += p.name.find("@upper_far") != std::string::npos;
  EXPECT_EQ(scaled_part, 1) << "the box's tag takes its region's stiffness scale";
}

// Bad boxes: each names its key and what to do.
TEST(RegionBoxes, AnEmptyOrInvertedBoxOrAnUnknownKeyIsAClearError) {
  std::string m = message_of(with(kSmall, "mesh.region_boxes=[{region = \"x\", min_mm = [500, 500, 500], max_mm = [600, 600, 600]}]"));
  EXPECT_NE(m.find("mesh.region_boxes[0]"), std::string::npos) << m;
  EXPECT_NE(m.find("holds no element's centroid; the mesh spans"), std::string::npos) << m;
  m = message_of(with(kSmall, "mesh.region_boxes=[{region = \"x\", min_mm = [0, 0, 5], max_mm = [10, 10, 1]}]"));
  EXPECT_NE(m.find("mesh.region_boxes[0].max_mm"), std::string::npos) << m;
  EXPECT_NE(m.find("must be above min_mm"), std::string::npos) << m;
  m = message_of(with(kSmall, "mesh.region_boxes=[{regoin = \"x\", min_mm = [0, 0, 0], max_mm = [1, 1, 1]}]"));
  EXPECT_NE(m.find("'mesh.region_boxes.regoin': unknown key"), std::string::npos) << m;
  // In a scene file: the unknown key's file and line.
  const std::filesystem::path file = std::filesystem::temp_directory_path() / "pneufem_region_boxes.toml";
  std::ofstream(file) << "[geometry]\nchambers = 2\n[mesh]\nh_mm = 6.0\n[[mesh.region_boxes]]\nregion = \"x\"\n"
                         "min_mm = [0, 0, 0]\nmax_mm = [1, 1, 1]\nmax = [2, 2, 2]\n";
  try {
    Scene::load(file.string(), {});
    m = "no error";
  } catch (const InputError& e) {
    m = e.what();
  }
  std::filesystem::remove(file);
  EXPECT_NE(m.find("pneufem_region_boxes.toml:9: key 'mesh.region_boxes.max': unknown key"), std::string::npos) << m;
  m = message_of(with(kSmall, "mesh.region_boxes=[{region = \"x\", min_mm = [0, 0], max_mm = [1, 1, 1]}]"));
  EXPECT_NE(m.find("mesh.region_boxes[0].min_mm"), std::string::npos) << m;
  m = message_of(with(kSmall, "mesh.region_boxes=[{region = \"\", min_mm = [0, 0, 0], max_mm = [1, 1, 1]}]"));
  EXPECT_NE(m.find("mesh.region_boxes[0].region"), std::string::npos) << m;
}

}  // namespace
}  // namespace pneufem
