#pragma once
// Local improvement of the worst tetrahedra that isosurface stuffing leaves where it cut the
// grid: vertex smoothing by the smallest dihedral angle (Freitag & Ollivier-Gooch, "Tetrahedral
// mesh improvement using swapping and smoothing", IJNME 40(21), 1997; here without swapping).
//
// For each tetrahedron whose smallest dihedral angle is below `target_deg` and which has a vertex
// made by the cut (a cut point, or a grid vertex warped, creased or snapped onto the surface),
// each of its vertices is moved by a pattern search to raise the smallest dihedral angle over the
// tetrahedra around it: steps along the directions it may move in, a quarter of its shortest edge
// halved five times, a step kept only when the star's worst angle rises. What may move:
//  * a vertex inside the solid: anywhere;
//  * a vertex on the surface whose boundary faces are coplanar (inside a flat face): within that
//    plane, only while it stays on the surface with the same normal (so it never leaves the face
//    nor rounds an edge); on a sharp edge or a curved face it stays;
//  * a vertex on a forced plane (x = 0 of a half model, a face of the fabric slab): within it;
//    on the surface and a forced plane, or on two forced planes, it stays.
// Every accepted step keeps every tetrahedron around the vertex positively oriented (an inverted
// one scores 0). Deterministic: the elements are visited worst first, ties by index.
#include <vector>

#include <Eigen/Core>

#include "scenes/stl/distance.h"
#include "scenes/stl/stuffed_tets.h"

namespace pneufem {

/// Smallest dihedral angle (degrees) of tetrahedron (a, b, c, d); 0 when it is flat or inverted.
double tet_min_dihedral_deg(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& c,
                            const Eigen::Vector3d& d);

struct SmoothingOptions {
  double target_deg = 15.0;  ///< elements below it are improved
  int sweeps = 3;            ///< passes over them
  std::vector<double> forced_z;  ///< forced planes z = const (the fabric slab's, slab_planes())
  double zero_tol = 0.0;     ///< |phi| within which a point is on the surface (m)
};

/// Improves `st` in place; `from_cut` flags the nodes the cut made or moved. Returns the vertex moves made.
int smooth_cut_elements(StuffedTets& st, const std::vector<char>& from_cut, const SurfaceDistance& dist,
                        const SmoothingOptions& opt);

}  // namespace pneufem
