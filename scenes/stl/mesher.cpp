#include "scenes/stl/mesher.h"

#include <algorithm>
#include <chrono>
#include <limits>
#include <memory>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <map>
#include <set>

#include <Eigen/Geometry>

#include "core/errors.h"
#include "core/number_text.h"
#include "engine/tet_element.h"
#include "scenes/stl/distance.h"
#include "scenes/stl/thin_walls.h"

namespace pneufem {

namespace {

/// The shells whose boundary faces are the cavity (see mesher.h).
std::vector<char> cavity_shells(const TriSurface& s, const StlMeshSpec& spec) {
  std::vector<char> cav(s.shells(), 0);
  if (spec.cavity_first_shell >= 0) {
    for (int sh = spec.cavity_first_shell; sh < s.shells(); ++sh) cav[sh] = 1;
    return cav;
  }
  std::vector<int> voids;
  for (int sh = 0; sh < s.shells(); ++sh)
    if (s.shell_depth[sh] % 2 == 1) voids.push_back(sh);
  if (voids.empty())
    throw InputError(s.path + ": cavity not found: the surface has no closed interior void (" + std::to_string(s.shells()) +
                     " shell(s), none inside another), so there is no chamber to pressurise; pneu-net chambers must be "
                     "voids enclosed by the solid: cap the inlet in CAD, or give the chambers as their own closed "
                     "surface in mesh.cavity_file");
  if (!spec.cavity_inlet) {
    for (int sh : voids) cav[sh] = 1;
    return cav;
  }
  const Eigen::Vector3d& p = *spec.cavity_inlet;
  int depth = 0, innermost = -1;
  for (int sh = 0; sh < s.shells(); ++sh)
    if (shell_encloses(s, sh, p)) {
      ++depth;
      if (innermost < 0 || s.shell_depth[sh] > s.shell_depth[innermost]) innermost = sh;
    }
  if (depth % 2 == 1)
    throw InputError("mesh.cavity_inlet_mm: cavity not found: the point " + mm_point(p) +
                     " lies in the solid (silicone), not in a chamber; give a point inside the chamber network the "
                     "inlet feeds");
  if (innermost < 0)
    throw InputError("mesh.cavity_inlet_mm: cavity not found: the point " + mm_point(p) +
                     " lies outside the actuator, in the air; give a point inside a chamber (if the chambers open to "
                     "the outside through the inlet, cap the inlet in CAD or give the chambers as their own closed "
                     "surface in mesh.cavity_file)");
  cav[innermost] = 1;
  return cav;
}

struct FacePlane {
  Eigen::Vector3d point, normal;  ///< outward unit normal
};

/// The fixed plane and the tip plane (the opposite end) of the spec.
std::pair<FacePlane, FacePlane> end_planes(const TriSurface& s, const StlMeshSpec& spec) {
  Eigen::Vector3d lo = s.V.front(), hi = s.V.front();
  for (const auto& p : s.V) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  const std::string& f = spec.fixed_face;
  if (f.size() == 2 && f[0] >= 'x' && f[0] <= 'z' && (f[1] == '-' || f[1] == '+')) {
    const int d = f[0] - 'x';
    const double sgn = f[1] == '-' ? -1.0 : 1.0;
    FacePlane fixed{sgn < 0 ? lo : hi, sgn * Eigen::Vector3d::Unit(d)};
    FacePlane tip{sgn < 0 ? hi : lo, -sgn * Eigen::Vector3d::Unit(d)};
    return {fixed, tip};
  }
  if (f != "plane")
    throw InputError("mesh.fixed_face must be \"x-\", \"x+\", \"y-\", \"y+\", \"z-\", \"z+\" (the extreme face along that "
                     "axis) or \"plane\" (mesh.fixed_point_mm, mesh.fixed_normal), got \"" + f + "\"");
  if (!(spec.fixed_normal.norm() > 0.0)) throw InputError("mesh.fixed_normal must be a nonzero vector");
  const Eigen::Vector3d n = spec.fixed_normal.normalized();
  double far = -std::numeric_limits<double>::infinity();
  Eigen::Vector3d at = spec.fixed_point;
  for (const auto& p : s.V)
    if ((spec.fixed_point - p).dot(n) > far) far = (spec.fixed_point - p).dot(n), at = p;
  return {{spec.fixed_point, n}, {at, -n}};
}

/// Nodes of the boundary faces lying on `plane` (all corners within tol); empty if none.
std::vector<int> nodes_on_plane(const Mesh& m, const std::vector<FaceRef>& boundary, const FacePlane& plane, double tol) {
  std::set<int> nodes;
  for (const FaceRef& fr : boundary) {
    const int* fn = face_local_nodes(m.type, fr.local_face);
    const int* el = m.element(fr.element);
    bool on = true;
    for (int k = 0; k < 3 && on; ++k) on = std::abs((m.X[el[fn[k]]] - plane.point).dot(plane.normal)) <= tol;
    if (on)
      for (int k = 0; k < 3; ++k) nodes.insert(el[fn[k]]);
  }
  return {nodes.begin(), nodes.end()};
}

std::string plane_text(const FacePlane& p, const StlMeshSpec& spec) {
  if (spec.fixed_face != "plane")
    for (int d = 0; d < 3; ++d)
      if (std::abs(p.normal[d]) == 1.0)
        return std::string(1, "xyz"[d]) + " = " + short_num(p.point[d] * 1e3) + " mm";
  return "the plane through " + mm_point(p.point) + " with normal (" + short_num(p.normal.x()) + ", " +
         short_num(p.normal.y()) + ", " + short_num(p.normal.z()) + ")";
}

/// Moves the mid-nodes of boundary edges onto the surface; an element whose scaled Jacobian would
/// fall below kMinScaledJacobian gets its moved mid-nodes back at their edges' midpoints.
void curve_boundary(Mesh& m, const std::vector<char>& corner_on_surface, const std::vector<char>& on_symmetry,
                    const SurfaceDistance& dist, StlMeshReport& rep) {
  constexpr double kMinScaledJacobian = 0.5;  // the reader refuses < 0.1; keep a wide margin
  static constexpr int kEdge[6][2] = {{0, 1}, {1, 2}, {2, 0}, {0, 3}, {1, 3}, {2, 3}};
  const int ncorner = static_cast<int>(corner_on_surface.size());
  std::vector<Eigen::Vector3d> straight(m.X);
  std::vector<char> moved(m.X.size(), 0);
  for (const FaceRef& fr : boundary_faces(m)) {
    const int* el = m.element(fr.element);
    const int* fn = face_local_nodes(m.type, fr.local_face);
    for (int k = 3; k < 6; ++k) {
      const int mid = el[fn[k]];
      if (moved[mid]) continue;
      const int local = fn[k];
      const int a = el[kEdge[local - 4][0]], b = el[kEdge[local - 4][1]];
      if (a >= ncorner || b >= ncorner || !corner_on_surface[a] || !corner_on_surface[b]) continue;
      SurfacePoint sp;
      if (!dist.nearest(m.X[mid], sp)) continue;
      Eigen::Vector3d q = sp.point;
      if (on_symmetry[a] && on_symmetry[b]) q.x() = 0.0;
      const double len = (m.X[a] - m.X[b]).norm(), move = (q - m.X[mid]).norm();
      if (move > 0.25 * len || move <= 1e-9 * len) continue;  // too far to be this edge's surface; or already on it
      m.X[mid] = q;
      moved[mid] = 1;
    }
  }
  for (bool changed = true; changed;) {
    changed = false;
    for (int e = 0; e < m.num_elements(); ++e) {
      const int* el = m.element(e);
      bool any = false;
      for (int k = 4; k < 10; ++k) any = any || moved[el[k]];
      if (!any || tet10_distortion(m, e).min_scaled_jacobian >= kMinScaledJacobian) continue;
      for (int k = 4; k < 10; ++k)
        if (moved[el[k]]) {
          m.X[el[k]] = straight[el[k]];
          moved[el[k]] = 2;  // kept straight
          ++rep.midnodes_kept_straight;
        }
      changed = true;
    }
  }
  rep.midnodes_on_surface = static_cast<int>(std::count(moved.begin(), moved.end(), 1));
}

/// The meshed volume against the surface's (divergence theorem; half of it for a half model): a
/// wall or chamber thinner than the cells is lost to the stencils (a thin wall where both faces
/// warp onto one grid plane, a slit of a chamber that no grid vertex sees), which moves the volume.
/// Over 5 % is an error, over 1 % a note.
void check_volume(const TriSurface& s, const Mesh& m, const StuffingOptions& opt, StlMeshReport& rep) {
  double enclosed = 0.0, meshed = 0.0;
  for (const auto& t : s.F) enclosed += s.V[t[0]].dot(s.V[t[1]].cross(s.V[t[2]])) / 6.0;
  if (opt.half) enclosed *= 0.5;
  for (int e = 0; e < m.num_elements(); ++e) meshed += corner_volume(m, e);
  rep.volume_error = meshed / enclosed - 1.0;
  const std::string what = "the mesh's volume differs from the surface's by " + short_num(100.0 * rep.volume_error) +
                           " % at mesh.h_mm = " + short_num(opt.h * 1e3) +
                           ": walls, chambers or channels thinner than about one element were lost or merged";
  if (std::abs(rep.volume_error) > 0.05)
    throw InputError("mesh.h_mm: " + what + "; use a smaller mesh.h_mm (two elements across the thinnest wall)");
  if (std::abs(rep.volume_error) > 0.01) rep.notes.push_back(what + "; a smaller mesh.h_mm resolves them better");
}

/// The mesh keeps the surface's shells: its boundary faces (the symmetry plane's left out), joined
/// across shared edges, form as many pieces as the surface has shells in the meshed part (x > 0 for
/// a half model). A wall thinner than the cells can be lost without moving the volume much (a
/// 0.05 mm lid over a chamber is 0.9 % of a small part): the chamber then opens to the outside and
/// its boundary joins the outer skin, one piece fewer; a chamber thinner than the cells that closes
/// up loses its piece too. Either is refused, with the thinnest wall the rays measured.
void check_shells_kept(const TriSurface& s, const Mesh& m, const StuffedTets& st, const StuffingOptions& opt,
                       const std::vector<FaceRef>& boundary, double thinnest, const Eigen::Vector3d& thinnest_at) {
  Eigen::Vector3d lo = s.V.front(), hi = lo;
  for (const auto& v : s.V) lo = lo.cwiseMin(v), hi = hi.cwiseMax(v);
  const double tol = 1e-9 * (hi - lo).norm();
  std::vector<char> meshed(s.shells(), opt.half ? 0 : 1);
  if (opt.half)
    for (int f = 0; f < static_cast<int>(s.F.size()); ++f)
      for (int v : s.F[f])
        if (s.V[v].x() > tol) meshed[s.face_shell[f]] = 1;
  const int expected = static_cast<int>(std::count(meshed.begin(), meshed.end(), 1));
  // Union-find over the boundary faces, joined across shared corner edges.
  std::vector<int> parent(boundary.size());
  for (std::size_t i = 0; i < parent.size(); ++i) parent[i] = static_cast<int>(i);
  auto root = [&](int i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  std::map<std::pair<int, int>, int> edge_face;
  std::vector<char> kept(boundary.size(), 0);
  for (std::size_t i = 0; i < boundary.size(); ++i) {
    const int* fn = face_local_nodes(m.type, boundary[i].local_face);
    const int* el = m.element(boundary[i].element);
    const int c[3] = {el[fn[0]], el[fn[1]], el[fn[2]]};
    if (opt.half && st.on_symmetry[c[0]] && st.on_symmetry[c[1]] && st.on_symmetry[c[2]]) continue;
    kept[i] = 1;
    for (int k = 0; k < 3; ++k) {
      const std::pair<int, int> e = std::minmax(c[k], c[(k + 1) % 3]);
      const auto [it, fresh] = edge_face.try_emplace(e, static_cast<int>(i));
      if (!fresh) parent[root(static_cast<int>(i))] = root(it->second);
    }
  }
  int pieces = 0;
  for (std::size_t i = 0; i < boundary.size(); ++i) pieces += kept[i] && root(static_cast<int>(i)) == static_cast<int>(i);
  if (pieces >= expected) return;
  std::string where = thinnest > 0.0 ? "; the thinnest wall or gap the rays measured is " + short_num(thinnest * 1e3) +
                                           " mm thick at " + mm_point(thinnest_at)
                                     : "";
  throw InputError("mesh.h_mm: a wall or chamber thinner than the elements was lost at mesh.h_mm = " + short_num(opt.h * 1e3) +
                   ": the surface has " + std::to_string(expected) + " closed shell(s) (the outer skin and the chambers)" +
                   (opt.half ? " in x >= 0" : "") + " but the mesh's boundary has " + std::to_string(pieces) +
                   " (a chamber opened to the outside or into another, or closed up)" + where +
                   "; thicken the wall in CAD or use a smaller mesh.h_mm (the cells go down to mesh.h_mm / 8, and "
                   "a wall needs at least one cell across it)");
}

}  // namespace

std::pair<double, double> dihedral_range_deg(const Mesh& m, int e) {
  const int* n = m.element(e);
  double lo = 180.0, hi = 0.0;
  // Dihedral angle at edge (i, j): between the faces (i, j, k) and (i, j, l).
  static constexpr int kPairs[6][4] = {{0, 1, 2, 3}, {0, 2, 1, 3}, {0, 3, 1, 2}, {1, 2, 0, 3}, {1, 3, 0, 2}, {2, 3, 0, 1}};
  for (const auto& p : kPairs) {
    const Eigen::Vector3d a = m.X[n[p[0]]], b = m.X[n[p[1]]], c = m.X[n[p[2]]], d = m.X[n[p[3]]];
    const Eigen::Vector3d e_ab = (b - a).normalized();
    Eigen::Vector3d u = c - a, w = d - a;
    u -= u.dot(e_ab) * e_ab;
    w -= w.dot(e_ab) * e_ab;
    const double ang = std::acos(std::clamp(u.normalized().dot(w.normalized()), -1.0, 1.0)) * 180.0 / std::numbers::pi;
    lo = std::min(lo, ang);
    hi = std::max(hi, ang);
  }
  return {lo, hi};
}

namespace {

/// The OpenVDB band must hold every background edge that can cross the surface: the longest cell
/// diagonal of the grid, plus a margin of voxels. Voxels of h/3.
/// The thin-wall rays (scenes/stl/thin_walls.h) need half the thickest wall they refine,
/// wall_cells * h / 2; refinement only shortens the cells, so the band of the uniform grid holds
/// the graded one's.
std::unique_ptr<SurfaceDistance> distance_for(const TriSurface& surface, const StuffingOptions& opt, int wall_cells,
                                              StlMeshReport& rep) {
  const auto lines = stuffing_grid(surface, opt);
  double diag2 = 0.0;
  for (int d = 0; d < 3; ++d) {
    double longest = 0.0;
    for (std::size_t i = 0; i + 1 < lines[d].size(); ++i) longest = std::max(longest, lines[d][i + 1] - lines[d][i]);
    diag2 += longest * longest;
  }
  const double h_max = std::max(opt.h, opt.h_z > 0.0 ? opt.h_z : opt.h);
  rep.voxel_m = std::min(opt.h, opt.h_z > 0.0 ? opt.h_z : opt.h) / 3.0;
  const double band = std::max(std::sqrt(diag2), 0.5 * wall_cells * h_max) + 3.0 * rep.voxel_m;
  auto dist = std::make_unique<SurfaceDistance>(surface, rep.voxel_m, band);
  rep.band_voxels = dist->voxels();
  return dist;
}

/// The axis (0 = x, 1 = y) along which the actuator lies when its fixed face is normal to x or y
/// ("x-", "x+", "y-", "y+", or a "plane" whose normal is within 1 degree of one of them); -1 else.
int horizontal_length_axis(const StlMeshSpec& spec) {
  const std::string& f = spec.fixed_face;
  if (f == "x-" || f == "x+") return 0;
  if (f == "y-" || f == "y+") return 1;
  if (f == "plane" && spec.fixed_normal.norm() > 0.0) {
    const Eigen::Vector3d n = spec.fixed_normal.normalized();
    for (int d = 0; d < 2; ++d)
      if (std::abs(n[d]) > std::cos(std::numbers::pi / 180.0)) return d;
  }
  return -1;
}

/// The Tet4 mesh of the stuffed tetrahedra with region tags, element sets SILICONE and FABRIC,
/// and its dihedral angles in the report. Tags, by the element's centroid against the bounding
/// box of the cavity (the built-in pneu-net's rules, scenes/pneunet.cpp, when the actuator lies
/// along y as it does, or along x; z up): fabric (in the slab), base (below the cavity), end_cap
/// (beyond it along the length), roof (above it), side_wall (beside it across the width),
/// interior_wall (the walls between chambers); another frame tags all but the fabric "body".
Mesh tagged_tet4(const StuffedTets& st, const TriSurface& surface, const std::vector<char>& cavity, const StlMeshSpec& spec,
                 StlMeshReport& rep) {
  const StuffingOptions& opt = spec.stuffing;
  Mesh m;
  m.type = ElementType::Tet4;
  m.X = st.X;
  Eigen::Vector3d clo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), chi = -clo;
  for (int f = 0; f < static_cast<int>(surface.F.size()); ++f)
    if (cavity[surface.face_shell[f]])
      for (int v : surface.F[f]) clo = clo.cwiseMin(surface.V[v]), chi = chi.cwiseMax(surface.V[v]);
  const int length_axis = horizontal_length_axis(spec);
  const bool along_y = length_axis >= 0;  // an actuator lying along x or y, z up
  const int width_axis = 1 - std::max(length_axis, 0);
  const std::uint16_t r_base = m.region_id(regions::kBase), r_fabric = m.region_id(regions::kFabric);
  std::uint16_t r_cap = 0, r_side = 0, r_roof = 0, r_wall = 0, r_body = 0;
  if (along_y) {
    r_cap = m.region_id(regions::kEndCap), r_side = m.region_id(regions::kSideWall);
    r_roof = m.region_id(regions::kRoof), r_wall = m.region_id(regions::kInteriorWall);
  } else {
    r_body = m.region_id("body");
  }
  auto region_of = [&](const Eigen::Vector3d& c) {
    if (opt.has_slab && !opt.slab_mid && c.z() > opt.slab_z0 && c.z() < opt.slab_z1) return r_fabric;
    if (!along_y) return r_body;
    if (c.z() < clo.z()) return r_base;
    if (c[length_axis] < clo[length_axis] || c[length_axis] > chi[length_axis]) return r_cap;
    if (c.z() > chi.z()) return r_roof;
    if (c[width_axis] < clo[width_axis] || c[width_axis] > chi[width_axis]) return r_side;
    return r_wall;
  };
  for (const auto& t : st.tets) {
    m.conn.insert(m.conn.end(), t.begin(), t.end());
    m.region.push_back(region_of(0.25 * (st.X[t[0]] + st.X[t[1]] + st.X[t[2]] + st.X[t[3]])));
  }
  m.element_sets["FABRIC"];
  for (int e = 0; e < m.num_elements(); ++e) m.element_sets[m.region[e] == r_fabric ? "FABRIC" : "SILICONE"].push_back(e);
  rep.dihedral_histogram.assign(18, 0);
  rep.min_dihedral_deg = 180.0;
  for (int e = 0; e < m.num_elements(); ++e) {
    const auto [lo, hi] = dihedral_range_deg(m, e);
    rep.min_dihedral_deg = std::min(rep.min_dihedral_deg, lo);
    rep.max_dihedral_deg = std::max(rep.max_dihedral_deg, hi);
    ++rep.dihedral_histogram[std::min(17, static_cast<int>(lo / 10.0))];
  }
  return m;
}

/// Surface CAVITY: boundary faces on the surface (not on the symmetry plane) whose closest
/// triangle belongs to a cavity shell.
void cavity_faces(Mesh& m, const StuffedTets& st, const TriSurface& surface, const std::vector<char>& cavity,
                  const SurfaceDistance& dist, const std::vector<FaceRef>& boundary, double h) {
  auto& cav = m.surfaces["CAVITY"];
  for (const FaceRef& fr : boundary) {
    const int* fn = face_local_nodes(m.type, fr.local_face);
    const int* el = m.element(fr.element);
    bool surf = true, sym = true;
    for (int k = 0; k < 3; ++k) {
      surf = surf && st.on_surface[el[fn[k]]];
      sym = sym && st.on_symmetry[el[fn[k]]];
    }
    if (!surf || sym) continue;
    SurfacePoint sp;
    const Eigen::Vector3d c = (m.X[el[fn[0]]] + m.X[el[fn[1]]] + m.X[el[fn[2]]]) / 3.0;
    if (dist.nearest(c, sp) && cavity[surface.face_shell[sp.face]]) cav.push_back(fr);
  }
  if (cav.empty())
    throw InputError(surface.path + ": cavity not found in the mesh: no element face lies on the chamber surface at "
                     "mesh.h_mm = " + short_num(h * 1e3) +
                     " (the chambers are smaller than the elements); use a smaller mesh.h_mm");
}

/// Surface FABRIC_MEMBRANE of a membrane fabric (slab_mid): the element faces on the slab's
/// mid-plane, each taken once, from the element below it (as the built-in mesher).
void membrane_faces(Mesh& m, const StuffingOptions& opt) {
  const double zm = slab_planes(opt)[1];
  auto& faces = m.surfaces["FABRIC_MEMBRANE"];
  for (int e = 0; e < m.num_elements(); ++e) {
    const int* el = m.element(e);
    for (int f = 0; f < 4; ++f) {
      const int* fn = face_local_nodes(m.type, f);
      bool on = true;
      for (int k = 0; k < 3 && on; ++k) on = m.X[el[fn[k]]].z() == zm;
      int apex = 0;
      while (apex == fn[0] || apex == fn[1] || apex == fn[2]) ++apex;
      if (on && m.X[el[apex]].z() < zm) faces.push_back({e, f});
    }
  }
  if (faces.empty())
    throw InputError("mesh.fabric_slab_mm: no element face lies on the fabric's mid-plane z = " + short_num(zm * 1e3) +
                     " mm, where mesh.fabric_model = \"membrane\" puts the membrane; the slab must lie inside the solid");
}

/// Node sets FIXED and TIP (the boundary faces on the two end planes) and SYMMETRY.
void end_and_symmetry_sets(Mesh& m, const StuffedTets& st, const StlMeshSpec& spec, const FacePlane& fixed_plane,
                           const FacePlane& tip_plane, const std::vector<FaceRef>& boundary) {
  Eigen::Vector3d lo = m.X.front(), hi = m.X.front();
  for (const auto& p : m.X) lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  // 1e-6 of the part's size: an STL stores float coordinates (7 digits), so a flat end face that is
  // not normal to an axis (an actuator turned in CAD) lies on its plane only to ~1e-7 of the
  // coordinates; faces on grid planes are exact, and no other face of the part comes this close.
  const double tol = 1e-6 * (hi - lo).norm();
  m.node_sets["FIXED"] = nodes_on_plane(m, boundary, fixed_plane, tol);
  if (m.node_sets["FIXED"].empty())
    throw InputError("mesh.fixed_face = \"" + spec.fixed_face + "\": fixed face not found: no face of the mesh lies on " +
                     plane_text(fixed_plane, spec) +
                     "; the clamped end must be a flat face of the actuator: name the axis along which it is the "
                     "extreme face (\"y-\" = the lowest y), or with \"plane\" a point on it and its outward normal");
  m.node_sets["TIP"] = nodes_on_plane(m, boundary, tip_plane, tol);
  if (m.node_sets["TIP"].empty())
    throw InputError("mesh.fixed_face = \"" + spec.fixed_face + "\": the tip (the end opposite the fixed face) is not a "
                     "flat face: no face of the mesh lies on " + plane_text(tip_plane, spec) +
                     "; the bending angle is measured on a flat free end: flatten it in CAD");
  if (spec.stuffing.half) {
    auto& sym = m.node_sets["SYMMETRY"];
    for (int n = 0; n < m.num_nodes(); ++n)
      if (st.on_symmetry[n]) sym.push_back(n);
  }
}

}  // namespace

Mesh mesh_closed_surface(const TriSurface& surface, const StlMeshSpec& spec, StlMeshReport* report) {
  const auto t0 = std::chrono::steady_clock::now();
  StlMeshReport rep;
  rep.notes = surface.notes;
  const StuffingOptions& opt = spec.stuffing;
  if (!(opt.h > 0.0 && std::isfinite(opt.h))) throw InputError("mesh.h_mm must be a positive element size");
  const std::vector<char> cavity = cavity_shells(surface, spec);
  const auto [fixed_plane, tip_plane] = end_planes(surface, spec);
  if (spec.wall_cells < 0) throw InputError("mesh.wall_cells must be >= 0 (0 = no refinement across thin walls)");
  StuffingOptions graded = opt;
  for (const FacePlane& p : {fixed_plane, tip_plane})
    for (int d = 0; d < 3; ++d)
      if (std::abs(p.normal[d]) == 1.0) graded.end_planes[d].push_back(p.point[d]);
  const std::unique_ptr<SurfaceDistance> dist = distance_for(surface, graded, spec.wall_cells, rep);
  Eigen::Vector3d thinnest_at = Eigen::Vector3d::Zero();
  {
    ThinWalls thin = measure_thin_walls(surface, *dist, graded, spec.wall_cells);
    graded.sizes = std::move(thin.sizes);
    rep.thin_rays = thin.samples;
    rep.thin_found = thin.thin;
    rep.thinnest_m = thin.thinnest;
    thinnest_at = thin.thinnest_at;
    rep.notes.insert(rep.notes.end(), thin.notes.begin(), thin.notes.end());
  }

  const StuffedTets st = stuff_surface(surface, *dist, graded);
  for (int d = 0; d < 3; ++d) rep.grid_lines[d] = static_cast<int>(st.lines[d].size());
  rep.warped = st.warped;
  rep.creased = st.creased;
  rep.on_sharp_edges = st.on_sharp_edges;
  rep.cut_points = st.cut_points;
  rep.flat_dropped = st.flat_dropped;
  rep.smoothed = st.smoothed;

  Mesh m = tagged_tet4(st, surface, cavity, spec, rep);
  check_volume(surface, m, opt, rep);
  const std::vector<FaceRef> boundary = boundary_faces(m);
  check_shells_kept(surface, m, st, opt, boundary, rep.thinnest_m, thinnest_at);
  cavity_faces(m, st, surface, cavity, *dist, boundary, opt.h);
  end_and_symmetry_sets(m, st, spec, fixed_plane, tip_plane, boundary);
  if (opt.has_slab && opt.slab_mid) membrane_faces(m, opt);
  if (spec.element == ElementType::Tet10) {
    m = promote_to_tet10(m);
    curve_boundary(m, st.on_surface, st.on_symmetry, *dist, rep);
  }
  renumber_nodes_by_first_use(m);
  m.ensure_ids();
  const MeshStats stats = compute_stats(m);
  rep.min_radius_ratio = stats.min_quality;
  rep.tets = stats.elements;
  rep.nodes = stats.nodes;
  rep.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  if (report) *report = rep;
  return m;
}

std::string describe(const StlMeshReport& r) {
  char buf[640];
  std::snprintf(buf, sizeof buf,
                "background grid %d x %d x %d lines (%d of %d thin-wall rays refined it, thinnest %.3g mm); OpenVDB band %ld voxels of %.3g mm; %d cut points, %d vertices warped "
                "onto the surface, %d onto creases, %d onto sharp edges, %d flat stencil tets dropped, %d smoothing moves\n%d elements, %d nodes; dihedral angles %.1f to %.1f deg, "
                "min radius ratio %.3f; volume %+.2f %% of the surface's; %d mid-nodes on the surface, %d kept straight; %.2f s\n",
                r.grid_lines[0], r.grid_lines[1], r.grid_lines[2], r.thin_found, r.thin_rays, r.thinnest_m * 1e3, r.band_voxels, r.voxel_m * 1e3, r.cut_points, r.warped, r.creased, r.on_sharp_edges,
                r.flat_dropped, r.smoothed, r.tets, r.nodes, r.min_dihedral_deg, r.max_dihedral_deg, r.min_radius_ratio,
                100.0 * r.volume_error, r.midnodes_on_surface, r.midnodes_kept_straight, r.seconds);
  std::string s = buf;
  s += "min dihedral angle per element (10-degree bins from 0):";
  for (int c : r.dihedral_histogram) {
    s += ' ';
    s += std::to_string(c);
  }
  s += '\n';
  return s;
}

}  // namespace pneufem
