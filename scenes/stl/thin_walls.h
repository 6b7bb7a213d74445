#pragma once
// Thin walls (and thin gaps) of a closed surface, measured from the exact signed distance, as the
// cell sizes per axis that put at least `cells` background cells across each of them
// (StuffingOptions::sizes, graded by scenes/stl/stuffing.h's subdivide_interval).
//
// Thickness: from sample points on every triangle (a barycentric lattice of spacing ~ h/2), a ray
// goes into the solid along the inward normal -n, marched by sphere tracing on the signed distance
// phi (Hart, "Sphere tracing", The Visual Computer 12(10), 1996): inside the solid |phi| is the
// radius of a ball free of the surface, so a step of |phi| never passes the far face. Where phi
// changes sign the exit is bisected; the wall's thickness t is the distance travelled. The same
// march along +n through a void gives a gap's width (a chamber or channel thinner than the cells).
//
// Requirement: a wall of thickness t with unit normal n spans t / |n_d| along axis d, so cells of
// size s_d <= t / (cells |n_d|) along d put `cells` cells across it along every axis it crosses.
// A wall whose two faces are both grid planes along d (CAD faces kept as feature planes, or forced
// planes) is meshed exactly by the cells between them and needs none: it is left out, so the
// built-in pneu-net's STL keeps the built-in mesh.
//
// Limits: thickness is measured along the normal of the sampled face, so a wedge's tip (faces
// meeting at an acute angle) reads as its local thickness only where the samples reach it. Cells
// are not made smaller than h / 8 (a note says where a wall needed finer ones): a thinner wall is
// a CAD defect or needs a smaller h, and the mesher's volume check refuses what the cells lose.
#include <array>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "scenes/stl/distance.h"
#include "scenes/stl/stuffing.h"

namespace pneufem {

struct ThinWalls {
  std::array<std::vector<AxisSize>, 3> sizes;   ///< per axis, merged runs of one required size
  int samples = 0;                              ///< rays cast
  int thin = 0;                                 ///< rays that found a wall or gap needing refinement
  double thinnest = 0.0;                        ///< m; 0 = none found
  Eigen::Vector3d thinnest_at = Eigen::Vector3d::Zero();
  bool thinnest_is_gap = false;
  std::vector<std::string> notes;               ///< walls that needed cells below h / 8
};

/// Where a ray from surface point p along unit `dir` first reaches the other side (phi changes
/// sign from `inside_sign`: -1 through the solid, +1 through a void), within `t_max`; the distance
/// travelled, or none (thicker, or out of the distance's band).
std::optional<double> ray_thickness(const SurfaceDistance& dist, const Eigen::Vector3d& p, const Eigen::Vector3d& dir,
                                    double inside_sign, double t_max, double h);

/// Samples every triangle of `surface` and returns the sizes that give `cells` cells across each
/// wall and gap thinner than cells * h (skipping walls bounded by grid planes of `opt`). `dist`
/// must answer within cells * max(h, h_z) / 2 of the surface (half the thickest wall refined).
ThinWalls measure_thin_walls(const TriSurface& surface, const SurfaceDistance& dist, const StuffingOptions& opt, int cells);

}  // namespace pneufem
