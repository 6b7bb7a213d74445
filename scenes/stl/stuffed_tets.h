#pragma once
// The tetrahedra isosurface stuffing makes (scenes/stl/stuffing.h) and vertex smoothing improves
// (scenes/stl/smoothing.h): nodes, elements and what each step did. Apart from both so that the
// smoothing reads the mesh without depending on the stuffing.
#include <array>
#include <vector>

#include <Eigen/Core>

namespace pneufem {

struct StuffedTets {
  std::vector<Eigen::Vector3d> X;            ///< nodes (m)
  std::vector<std::array<int, 4>> tets;      ///< positive volume
  std::vector<char> on_surface;              ///< per node: phi = 0 (a cut point or a warped vertex)
  std::vector<char> on_symmetry;             ///< per node: on the plane x = 0 (half)
  std::vector<char> from_cut;                ///< per node: a cut point, or a grid vertex the cut moved
  std::array<std::vector<double>, 3> lines;  ///< the grid lines
  int warped = 0;                            ///< vertices moved onto the surface
  int cut_points = 0;
  int on_sharp_edges = 0;                    ///< surface nodes moved onto a sharp edge (step 6)
  int creased = 0;                           ///< surface vertices moved onto a crease (step 4b)
  int flat_dropped = 0;                      ///< stencil tetrahedra of no volume, left out
  int smoothed = 0;                          ///< vertex moves of step 7
};

}  // namespace pneufem
