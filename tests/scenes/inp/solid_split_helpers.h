#pragma once
// Helpers shared by the solid-split tests (test_solid_split*.cpp): triangle geometry of a
// tetrahedral mesh, the test elements (frusta), generated blocks of hexahedra written as decks
// (HexBlock), and the SolidDecks fixture, which writes decks to a temporary directory and reads them.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <functional>
#include <numeric>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "core/errors.h"
#include "scenes/inp/deck.h"
#include "tests/scenes/inp/deck_files.h"

namespace pneufem::test {

using Vec = Eigen::Vector3d;
using Map = std::function<Vec(const Vec&)>;

/// Area of the triangle a b c.
inline double area(const Vec& a, const Vec& b, const Vec& c) { return 0.5 * (b - a).cross(c - a).norm(); }

/// Area of a (corner) triangle of the mesh.
inline double face_area(const Mesh& m, const FaceRef& f) {
  const int* ln = face_local_nodes(m.type, f.local_face);
  const int* n = m.element(f.element);
  return area(m.X[n[ln[0]]], m.X[n[ln[1]]], m.X[n[ln[2]]]);
}

/// Outward unit normal (the Abaqus face order's right-hand normal points into the element).
inline Vec outward(const Mesh& m, const FaceRef& f) {
  const int* ln = face_local_nodes(m.type, f.local_face);
  const int* n = m.element(f.element);
  return -(m.X[n[ln[1]]] - m.X[n[ln[0]]]).cross(m.X[n[ln[2]]] - m.X[n[ln[0]]]).normalized();
}

/// Corners of the test elements: convex, with planar faces, not affine images of the reference
/// element (frusta), so that a wrong diagonal or orientation shows in volumes and areas.
inline std::vector<Vec> frustum_hex() {  // square 2 x 2 at z = 0, 1 x 1 at z = 1.2, centred
  return {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}, {-.5, -.5, 1.2}, {.5, -.5, 1.2}, {.5, .5, 1.2}, {-.5, .5, 1.2}};
}
inline std::vector<Vec> frustum_wedge() {  // triangle (0,0) (2,0) (0,2) at z = 0, scaled by 1/2 about its centroid at z = 1
  const Vec g(2.0 / 3, 2.0 / 3, 0);
  std::vector<Vec> X = {{0, 0, 0}, {2, 0, 0}, {0, 2, 0}};
  for (int a = 0; a < 3; ++a) X.push_back(g + 0.5 * (X[a] - g) + Vec(0, 0, 1));
  return X;
}
inline std::vector<Vec> skew_pyramid() { return {{0, 0, 0}, {2, 0, 0}, {2, 1, 0}, {0, 1, 0}, {0.3, 0.8, 1.5}}; }

/// A block of nx x ny x nz C3D8 or C3D20 cells: reference s in [0,1]^3 mapped by `map`, node ids a
/// seeded random permutation (so the cut diagonals vary), element ids 1.. in cell order.
class HexBlock {
 public:
  HexBlock(int nx, int ny, int nz, bool quadratic, unsigned seed, Map map)
      : nx_(nx), ny_(ny), nz_(nz), f_(quadratic ? 2 : 1), map_(std::move(map)) {
    const int total = (f_ * nx + 1) * (f_ * ny + 1) * (f_ * nz + 1);
    id_.resize(static_cast<std::size_t>(total));
    std::iota(id_.begin(), id_.end(), 1L);
    std::mt19937 rng(seed);
    std::shuffle(id_.begin(), id_.end(), rng);
  }
  bool quadratic() const { return f_ == 2 && !corners_only_; }
  /// The same block as C3D8 (same corner ids and geometry) when this one is C3D20.
  HexBlock corners_only() const {
    HexBlock b = *this;
    b.corners_only_ = true;
    return b;
  }
  /// Cells to leave out (a cavity).
  void remove_cells(std::function<bool(int, int, int)> removed) { removed_ = std::move(removed); }
  /// Nodes written by nodes() (a split appends its new nodes after them).
  int node_count() const {
    int n = 0;
    for_nodes([&](int, int, int) { ++n; });
    return n;
  }
  /// Reference point of fine-grid node (i, j, k).
  Vec s(int i, int j, int k) const { return Vec(double(i) / (f_ * nx_), double(j) / (f_ * ny_), double(k) / (f_ * nz_)); }
  long node(int i, int j, int k) const { return id_[static_cast<std::size_t>(index(i, j, k))]; }
  long element(int i, int j, int k) const { return 1 + i + nx_ * (j + ny_ * k); }
  /// Whether a fine-grid node belongs to an element (C3D20 has no face or cell centres).
  bool used(int i, int j, int k) const {
    const int odd = (i % 2) + (j % 2) + (k % 2);
    return f_ == 1 || odd == 0 || (odd == 1 && !corners_only_);
  }

  std::string nodes() const {
    std::ostringstream os;
    os.precision(17);
    os << "*NODE\n";
    for_nodes([&](int i, int j, int k) {
      const Vec x = map_(s(i, j, k));
      os << node(i, j, k) << ", " << x.x() << ", " << x.y() << ", " << x.z() << "\n";
    });
    return os.str();
  }
  /// Nodes of cell (i, j, k) in the Abaqus order of C3D8/C3D20 (solid_split.h).
  std::vector<long> cell(int i, int j, int k) const {
    const int f = f_;
    auto c = [&](int a) {  // corner a: 1-2-3-4 at k, 5-8 at k + 1
      static constexpr int dx[8] = {0, 1, 1, 0, 0, 1, 1, 0}, dy[8] = {0, 0, 1, 1, 0, 0, 1, 1}, dz[8] = {0, 0, 0, 0, 1, 1, 1, 1};
      return std::array<int, 3>{f * (i + dx[a]), f * (j + dy[a]), f * (k + dz[a])};
    };
    std::vector<long> out;
    for (int a = 0; a < 8; ++a) out.push_back(node(c(a)[0], c(a)[1], c(a)[2]));
    if (quadratic()) {
      static constexpr int E[12][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6}, {6, 7}, {7, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
      for (const auto& e : E)
        out.push_back(node((c(e[0])[0] + c(e[1])[0]) / 2, (c(e[0])[1] + c(e[1])[1]) / 2, (c(e[0])[2] + c(e[1])[2]) / 2));
    }
    return out;
  }
  std::string elements(const std::string& header) const {
    std::ostringstream os;
    os << header << "\n";
    for (int k = 0; k < nz_; ++k)
      for (int j = 0; j < ny_; ++j)
        for (int i = 0; i < nx_; ++i) {
          if (removed_ && removed_(i, j, k)) continue;
          const std::vector<long> n = cell(i, j, k);
          os << element(i, j, k);
          for (std::size_t a = 0; a < n.size(); ++a) os << (a == 10 ? ",\n" : ", ") << n[a];
          os << "\n";
        }
    return os.str();
  }
  /// *NSET of the nodes whose reference point satisfies `pred`.
  std::string nset(const std::string& name, const std::function<bool(const Vec&)>& pred) const {
    std::ostringstream os;
    os << "*NSET, NSET=" << name << "\n";
    int count = 0;
    for_nodes([&](int i, int j, int k) {
      if (pred(s(i, j, k))) os << node(i, j, k) << (++count % 16 ? ", " : "\n");
    });
    return os.str() + "\n";
  }
  template <class F>
  void for_nodes(F&& f) const {
    for (int k = 0; k <= f_ * nz_; ++k)
      for (int j = 0; j <= f_ * ny_; ++j)
        for (int i = 0; i <= f_ * nx_; ++i)
          if (used(i, j, k)) f(i, j, k);
  }
  int nx_, ny_, nz_, f_;

 private:
  int index(int i, int j, int k) const { return i + (f_ * nx_ + 1) * (j + (f_ * ny_ + 1) * k); }
  Map map_;
  std::vector<long> id_;
  bool corners_only_ = false;
  std::function<bool(int, int, int)> removed_;
};

/// Tests on decks (InpFiles: a temporary directory of their own, expect_error() of a bad deck's
/// bad.inp:line and hints), with read() of a deck's text; lengths in metres.
class SolidDecks : public InpFiles {
 protected:
  SolidDecks() { error_length_to_m_ = 1.0; }
  InpDeck read(const std::string& text, double length_to_m = 1.0) const { return read_inp(write("deck.inp", text), length_to_m); }
};

/// The sheared unit cube (planar faces): volume det A, boundary = the six parallelograms.
inline Eigen::Matrix3d shear() {
  Eigen::Matrix3d A;
  A << 1.0, 0.2, 0.1, 0.0, 0.9, -0.15, 0.05, 0.0, 1.1;
  return A;
}

/// The unit cube's nodes (a deck's lines 1-9).
inline const std::string kCube =
    "*NODE\n1, 0, 0, 0\n2, 1, 0, 0\n3, 1, 1, 0\n4, 0, 1, 0\n5, 0, 0, 1\n6, 1, 0, 1\n7, 1, 1, 1\n8, 0, 1, 1\n";  // lines 1-9

}  // namespace pneufem::test
