// engine/mesh.h's mesh operations on meshes small enough to know by hand: the boundary faces of two
// tetrahedra sharing a face, Tet4 -> Tet10 promotion (one mid-node per edge, shared by neighbours,
// node sets growing by the mid-nodes of their edges), the statistics every output records (volume,
// edges, the radius-ratio quality: 1 for the regular tetrahedron, sqrt(3) - 1 for a corner one), and
// renumbering by first use.
#include "engine/mesh.h"

#include <algorithm>
#include <cmath>
#include <set>
#include <vector>

#include <gtest/gtest.h>

namespace {

using namespace pneufem;

/// The corner tetrahedron (0,1,2,3) and its mirror (0,2,1,4) below the face {0,1,2}; both positive.
Mesh two_corner_tets() {
  Mesh m;
  m.type = ElementType::Tet4;
  m.X = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0, 1}, {0, 0, -1}};
  m.conn = {0, 1, 2, 3, 0, 2, 1, 4};
  m.region_names = {"roof", "base"};
  m.region = {0, 1};
  m.node_sets["plane"] = {0, 1, 2};
  m.node_sets["tip"] = {3};
  return m;
}

TEST(Mesh, BoundaryFacesLeaveOutTheSharedFace) {
  const Mesh m = two_corner_tets();
  const std::vector<FaceRef> faces = boundary_faces(m);
  ASSERT_EQ(faces.size(), 6u);  // 4 + 4 faces, the shared one twice
  for (const FaceRef& f : faces) {
    const int* local = face_local_nodes(m.type, f.local_face);
    std::set<int> corners;
    for (int k = 0; k < 3; ++k) corners.insert(m.element(f.element)[local[k]]);
    EXPECT_NE(corners, (std::set<int>{0, 1, 2})) << "element " << f.element << " face " << f.local_face;
  }
  EXPECT_TRUE(std::is_sorted(faces.begin(), faces.end(),
                             [](const FaceRef& a, const FaceRef& b) { return a.element < b.element; }));
}

TEST(Mesh, PromotionAddsOneMidNodePerEdgeSharedByNeighbours) {
  const Mesh m = promote_to_tet10(two_corner_tets());
  EXPECT_EQ(m.type, ElementType::Tet10);
  EXPECT_EQ(m.num_nodes(), 5 + 9);  // 6 + 6 edges, 3 of them shared
  // Mid-edge nodes in Abaqus order: 4 = (0,1), 5 = (1,2), 6 = (2,0), 7 = (0,3), 8 = (1,3), 9 = (2,3).
  constexpr int kEdge[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};
  for (int e = 0; e < 2; ++e)
    for (int k = 0; k < 6; ++k) {
      const int* n = m.element(e);
      EXPECT_EQ(m.X[n[4 + k]], 0.5 * (m.X[n[kEdge[k][0]]] + m.X[n[kEdge[k][1]]])) << e << " " << k;
    }
  // The shared face's edges (0,1), (1,2), (2,0) are edges of both elements (element 1 walks them the
  // other way round): one mid-node each, in both.
  const std::set<int> mids0(m.element(0) + 4, m.element(0) + 10), mids1(m.element(1) + 4, m.element(1) + 10);
  std::vector<int> shared;
  std::set_intersection(mids0.begin(), mids0.end(), mids1.begin(), mids1.end(), std::back_inserter(shared));
  EXPECT_EQ(shared.size(), 3u);
  // A node set takes the mid-nodes of the edges between its nodes: the plane its 3, the tip none.
  EXPECT_EQ(m.node_sets.at("plane").size(), 6u);
  for (int n : m.node_sets.at("plane")) EXPECT_EQ(m.X[n].z(), 0.0) << n;
  EXPECT_EQ(m.node_sets.at("tip"), (std::vector<int>{3}));
  EXPECT_EQ(promote_to_tet10(m).conn, m.conn);  // a Tet10 mesh is left as it is
}

TEST(Mesh, StatisticsAreTheHandCountedOnes) {
  const MeshStats s = compute_stats(two_corner_tets());
  EXPECT_EQ(s.nodes, 5);
  EXPECT_EQ(s.elements, 2);
  EXPECT_EQ(s.element_type, "C3D4");
  EXPECT_NEAR(s.volume_m3, 2.0 / 6.0, 1e-15);
  EXPECT_DOUBLE_EQ(s.min_edge_m, 1.0);
  EXPECT_DOUBLE_EQ(s.max_edge_m, std::sqrt(2.0));
  EXPECT_NEAR(s.min_quality, std::sqrt(3.0) - 1.0, 1e-14);  // 3 r_in / r_circ of a corner tetrahedron
  EXPECT_EQ(s.elements_per_region, (std::map<std::string, int>{{"base", 1}, {"roof", 1}}));
  EXPECT_EQ(s.bbox_min, Eigen::Vector3d(0, 0, -1));
  EXPECT_EQ(s.bbox_max, Eigen::Vector3d(1, 1, 1));

  Mesh regular;
  regular.type = ElementType::Tet4;
  regular.X = {{1, 1, 1}, {-1, 1, -1}, {1, -1, -1}, {-1, -1, 1}};
  regular.conn = {0, 1, 2, 3};
  EXPECT_GT(corner_volume(regular, 0), 0.0);
  EXPECT_NEAR(compute_stats(regular).min_quality, 1.0, 1e-14);
}

TEST(Mesh, RenumberingByFirstUseDropsUnusedNodesAndSetsFollow) {
  Mesh m = two_corner_tets();
  m.X.push_back({9, 9, 9});  // node 5, in no element
  m.node_sets["tip"] = {3, 5};
  m.node_ids = {1, 2, 3, 4, 5, 6};
  m.conn = {4, 2, 0, 1, 3, 0, 2, 1};  // first use: 4, 2, 0, 1, 3
  const std::vector<Eigen::Vector3d> X = m.X;
  renumber_nodes_by_first_use(m);
  EXPECT_EQ(m.conn, (std::vector<int>{0, 1, 2, 3, 4, 2, 1, 3}));
  ASSERT_EQ(m.num_nodes(), 5);
  EXPECT_EQ(m.X[0], X[4]);
  EXPECT_EQ(m.X[4], X[3]);
  EXPECT_EQ(m.node_sets.at("plane"), (std::vector<int>{1, 2, 3}));  // {0, 1, 2} renumbered, sorted
  EXPECT_EQ(m.node_sets.at("tip"), (std::vector<int>{4}));          // the unused node dropped
  EXPECT_TRUE(m.node_ids.empty());
}

}  // namespace
