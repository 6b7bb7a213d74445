#pragma once
// A closed triangle surface of a solid from CAD: STL (binary or ASCII) or Wavefront OBJ, read into
// metres, welded into an indexed mesh, checked to be watertight and manifold, and oriented (every
// normal pointing out of the solid, the holes of nested shells included).
//
// Why watertight: inside/outside of a point is only defined for a closed surface; an open edge
// lets the "inside" leak to the outside. Every edge must be shared by exactly two triangles
// traversing it in opposite directions (a closed, orientable 2-manifold).
//
// Orientation: triangles are first made consistent with their neighbours (a breadth-first walk of
// each connected shell), then each shell is turned so that its normals point away from the solid:
// a shell nested inside an odd number of other shells bounds a void (a chamber), so its enclosed
// volume (divergence theorem, sum of signed tetrahedra to the origin) must be negative; an outer
// shell's positive. Each flip is reported as a note; nothing is silently changed.
//
// Self-intersections: pairs of triangles (without a common corner) whose edges cross each other's
// interior are an error with their count and a location; coplanar overlaps are not detected.
#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace pneufem {

struct TriSurface {
  std::vector<Eigen::Vector3d> V;        ///< welded vertices (m)
  std::vector<std::array<int, 3>> F;     ///< triangles, counter-clockwise seen from outside the solid
  std::vector<int> face_shell;           ///< per triangle: its shell (edge-connected component)
  std::vector<int> shell_depth;          ///< per shell: how many other shells enclose it (odd = a void)
  std::vector<std::string> notes;        ///< what was repaired (inverted normals, degenerate triangles)
  std::string path;                      ///< the file, for messages
  double unit_m = 1.0;                   ///< the file's length unit in metres (messages print file units)

  int shells() const { return static_cast<int>(shell_depth.size()); }
  Eigen::Vector3d normal(int f) const;   ///< unit outward normal of triangle f
  double area(int f) const;
};

/// Reads `path` (.stl binary or ASCII, .obj), scaling coordinates by `unit_m` (1e-3 for mm), welds
/// vertices with identical coordinates and drops triangles with a repeated vertex (noted). Throws
/// InputError naming the file and line for a malformed file. The result is not yet checked: call
/// close_and_orient().
TriSurface read_surface(const std::string& path, double unit_m);

/// The watertight, manifold and self-intersection checks, then the orientation (see above). Throws
/// InputError with the count and a location of open edges, non-manifold edges or crossing
/// triangles, and what to do.
void close_and_orient(TriSurface& s);

/// read_surface + close_and_orient.
TriSurface read_closed_surface(const std::string& path, double unit_m);

/// Whether shell `shell` encloses p (parity of a ray's crossings with it).
bool shell_encloses(const TriSurface& s, int shell, const Eigen::Vector3d& p);

/// A point (metres) for messages, in millimetres: "(x, y, z) mm", each coordinate as short_num.
std::string mm_point(const Eigen::Vector3d& p_m);

/// Writes `s` as a binary STL, coordinates divided by `unit_m` (1e-3: the file in mm).
void write_stl(const std::string& path, const TriSurface& s, double unit_m);

/// Appends the shells of `b` to `a` (a cavity given as its own file): vertices are not shared; with
/// `as_voids` every triangle of `b` is turned (a closed surface oriented as a solid becomes a void's
/// boundary). Call close_and_orient(a) again afterwards.
void append_surface(TriSurface& a, const TriSurface& b, bool as_voids = false);

}  // namespace pneufem
