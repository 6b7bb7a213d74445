#pragma once
// A closed surface (scenes/stl/surface.h) to the engine's mesh, with the structure the built-in
// pneu-net mesher gives (scenes/pneunet.h): element sets SILICONE and FABRIC, node sets FIXED, TIP
// and, for a half model, SYMMETRY, the surface CAVITY, and region tags (fabric, base, end_cap,
// roof, side_wall, interior_wall, by the built-in mesher's rules against the cavity's bounding box,
// when the actuator lies along y or x with z up, by its fixed face; else fabric and body).
//
//  * Grid: graded so that at least wall_cells cells lie across every wall and gap the grid cuts
//    (scenes/stl/thin_walls.h).
//  * Tetrahedra: isosurface stuffing of the solid (scenes/stl/stuffing.h), promoted to Tet10 with
//    the mid-nodes of boundary edges moved onto the surface (closest point); a mid-node whose move
//    would leave an element's scaled Jacobian (engine/tet_element.h) below 0.5 stays straight.
//  * CAVITY: the boundary faces whose closest triangle belongs to a cavity shell: the void (a shell
//    nested in the solid) that contains the inlet point, every void when no point is given, or
//    every shell of a separate cavity file.
//  * FIXED: the nodes of the boundary faces on the fixed plane, the extreme face of the surface
//    along an axis ("y-": lowest y) or a plane through a point; TIP: the opposite end face.
//  * FABRIC: the elements whose centroid lies in the slab z0 < z < z1 (its faces are grid planes);
//    with a membrane fabric (StuffingOptions::slab_mid) FABRIC is empty and the surface
//    FABRIC_MEMBRANE holds the element faces on the slab's mid-plane.
//  * Thin features: a meshed volume more than 5 % off the surface's is an error (walls or chambers
//    thinner than the elements were lost), more than 1 % a note.
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "engine/mesh.h"
#include "scenes/stl/stuffing.h"
#include "scenes/stl/surface.h"

namespace pneufem {

struct StlMeshSpec {
  StuffingOptions stuffing;
  ElementType element = ElementType::Tet10;
  std::optional<Eigen::Vector3d> cavity_inlet;  ///< m; none = every void is cavity
  int cavity_first_shell = -1;                  ///< >= 0: shells from here on are the cavity (a cavity file)
  /// Fixed face: "x-", "x+", "y-", "y+", "z-", "z+" (the extreme face along that axis) or "plane"
  /// (through fixed_point with outward normal fixed_normal).
  std::string fixed_face = "y-";
  Eigen::Vector3d fixed_point = Eigen::Vector3d::Zero();   ///< m
  Eigen::Vector3d fixed_normal = Eigen::Vector3d(0, -1, 0);
  /// Fewest background cells across every wall and gap the grid cuts (scenes/stl/thin_walls.h);
  /// walls between two grid planes are meshed exactly and keep ceil(t / h) cells. 0 = uniform h.
  int wall_cells = 2;
};

struct StlMeshReport {
  int grid_lines[3] = {0, 0, 0};
  int thin_rays = 0, thin_found = 0;    ///< rays cast for thin walls and gaps; those that refined the grid
  double thinnest_m = 0.0;              ///< the thinnest wall or gap refined (0 = none)
  long band_voxels = 0;
  double voxel_m = 0.0;
  int warped = 0, creased = 0, on_sharp_edges = 0, cut_points = 0, flat_dropped = 0, smoothed = 0;
  int tets = 0, nodes = 0;
  double min_dihedral_deg = 0.0, max_dihedral_deg = 0.0;
  std::vector<int> dihedral_histogram;  ///< counts per 10 degrees, 0-10 ... 170-180 (corner tetrahedra)
  double volume_error = 0.0;            ///< meshed (straight-sided) / enclosed volume - 1
  double min_radius_ratio = 0.0;        ///< normalised (1 = regular), as MeshStats::min_quality
  int midnodes_on_surface = 0, midnodes_kept_straight = 0;
  double seconds = 0.0;
  std::vector<std::string> notes;       ///< the surface's repairs
};

/// Meshes `surface` (closed and oriented). Throws InputError naming the scene key when the cavity
/// or a face is not found.
Mesh mesh_closed_surface(const TriSurface& surface, const StlMeshSpec& spec, StlMeshReport* report = nullptr);

/// Smallest and largest dihedral angle (degrees) of the corner tetrahedron of element e.
std::pair<double, double> dihedral_range_deg(const Mesh& mesh, int e);

/// One line per quantity, for the CLI and the benchmarks.
std::string describe(const StlMeshReport& r);

}  // namespace pneufem
