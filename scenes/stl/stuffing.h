#pragma once
// Tetrahedra of the solid bounded by a closed surface: a background grid of tetrahedra cut to
// the surface by isosurface stuffing (Labelle & Shewchuk, "Isosurface stuffing: fast tetrahedral
// meshes with good dihedral angles", ACM TOG 26(3), 2007), simplified.
//
// 1. Background grid: a rectilinear grid over the surface's bounding box (one padding cell beyond
//    it), whose lines include every axis-aligned plane that carries facets of the surface (CAD
//    actuators are mostly boxes: those faces are then meshed exactly, as the built-in mesher
//    does) and the forced planes (fabric slab, symmetry plane x = 0, the clamped face and the tip
//    when they are normal to an axis); each interval between
//    planes gets ceil(length / h) cells. Each cell is split into 5 tetrahedra with alternating
//    parity (as scenes/pneunet.cpp), which conform across cells.
// 2. phi at the grid vertices: the exact signed distance (scenes/stl/distance.h) within the band,
//    its sign carried to the far vertices by a flood fill along grid edges (an edge longer than
//    its distance to the surface cannot cross it).
// 3. Cut points: where phi changes sign strictly along a tetrahedron edge, found by regula falsi
//    on the exact distance.
// 4. Warping (L&S sec. 3): a vertex closer to a cut point on one of its edges than alpha times
//    that edge's length moves onto the closest such cut point and gets phi = 0; cut points on its
//    edges are dropped. Vertices on a forced plane only move within it.
// 4b. Creases (an addition for CAD parts): a vertex on the surface whose edge runs along the
//    surface and leaves it within alpha of the edge moves to where it leaves (onto the crease).
// 5. Stencils (L&S fig. 3): each background tetrahedron keeps its part with phi <= 0: a whole
//    tetrahedron, one tetrahedron, a pyramid (2 tetrahedra) or a prism (3). A tetrahedron whose
//    four vertices all have phi = 0 is kept when its centroid is inside.
//
// 6. Sharp edges (an addition for CAD parts): surface nodes within 0.9 h of an edge where facets
//    meet at more than 30 degrees move onto it, nearest first, unless that would leave a
//    tetrahedron around them with a dihedral angle below 5 degrees. Stencils alone cut such edges
//    with a chamfer about a cell wide.
//
// 7. Smoothing (an addition): the tetrahedra steps 3-6 made with a dihedral angle below
//    smooth_target_deg have their vertices moved to raise it (scenes/stl/smoothing.h); the grid's
//    own tetrahedra, where nothing was cut, are left as they are.
//
// What is simplified (and so not proven): L&S's grid is the body-centred cubic lattice, with
// alpha_long = 0.24999 and alpha_short = 0.41189 and a parity rule for the prisms' diagonals, which
// together bound every dihedral angle to [10.7, 164.8] degrees. Here the grid is rectilinear (to
// conform to CAD faces and the fabric slab), alpha is one number for all edges, and the quadrilateral
// faces of pyramids and prisms are split on the diagonal through their lowest-numbered vertex
// (Dompierre et al., 8th International Meshing Roundtable, 1999), which keeps neighbours
// conforming. The dihedral angles reached are measured and reported instead (docs/verification.md).
#include <array>
#include <vector>

#include <Eigen/Core>

#include "scenes/stl/distance.h"
#include "scenes/stl/stuffed_tets.h"

namespace pneufem {

/// Cells along one axis no longer than `spacing` within [lo, hi] (m): a thin wall's requirement
/// (scenes/stl/thin_walls.h). Away from [lo, hi] the bound grows by `grading` per unit distance.
struct AxisSize {
  double lo = 0.0, hi = 0.0, spacing = 0.0;
};

struct StuffingOptions {
  double h = 2e-3;                   ///< target cell size in x and y (m)
  double h_z = 0.0;                  ///< along z (m); 0 = h
  bool feature_planes = true;        ///< grid lines through the axis-aligned faces of the surface
  bool half = false;                 ///< only x >= 0 (the grid starts at the plane x = 0)
  bool has_slab = false;             ///< a slab z0 < z < z1 whose faces are grid planes
  double slab_z0 = 0.0, slab_z1 = 0.0;
  int slab_cells = 1;                ///< grid cells through the slab
  /// A membrane fabric: the slab's mid-plane is a grid plane too, and each half of the slab gets
  /// (slab_cells + 1) / 2 cells (as the built-in mesher); the mesher puts the membrane on it.
  bool slab_mid = false;
  /// Planes forced into the grid along each axis (m): the clamped face and the tip when they are
  /// normal to an axis, so that they are meshed exactly (no chamfer at their edges) also when
  /// feature_planes is off. They must be faces of the surface.
  std::array<std::vector<double>, 3> end_planes;
  double alpha = 0.25;               ///< warping threshold, a fraction of the edge length
  /// Graded refinement per axis (empty: every interval between planes gets ceil(length / h)
  /// cells). Within an interval the cell size follows s(x) = min(h, min_k spacing_k + grading *
  /// dist(x, [lo_k, hi_k])), and the lines equidistribute the integral of 1/s (de Boor's
  /// equidistribution; the interval gets ceil of that integral cells, each no longer than s).
  std::array<std::vector<AxisSize>, 3> sizes;
  double grading = 0.4;              ///< growth of the cell size per unit distance (neighbours differ by <= ~1.4x)
  /// Step 7: tetrahedra the cut made with a dihedral angle below this are improved by vertex
  /// smoothing (scenes/stl/smoothing.h); 0 = none.
  double smooth_target_deg = 15.0;
};

/// Steps 1-5 above. `dist` must answer within a band of at least max_cell_diagonal(opt, surface).
StuffedTets stuff_surface(const TriSurface& surface, const SurfaceDistance& dist, const StuffingOptions& opt);

/// The grid lines of step 1 (for the band the distance needs: the longest cell diagonal).
std::array<std::vector<double>, 3> stuffing_grid(const TriSurface& surface, const StuffingOptions& opt);

/// The planes of step 1 before subdivision, per axis and increasing: the two ends (padding
/// beyond the surface), the forced planes and the feature planes. stuffing_grid subdivides
/// every interval between them.
std::array<std::vector<double>, 3> stuffing_planes(const TriSurface& surface, const StuffingOptions& opt);

/// The forced planes z = const of the slab: its faces and, with slab_mid, its mid-plane (empty
/// without a slab). Grid vertices on them move only within them.
std::vector<double> slab_planes(const StuffingOptions& opt);

/// Lines from a to b (both included) with cells no longer than the graded size of `sizes` (and h);
/// without a size below h in reach, ceil((b - a) / h) equal cells.
std::vector<double> subdivide_interval(double a, double b, double h, const std::vector<AxisSize>& sizes, double grading);

}  // namespace pneufem
