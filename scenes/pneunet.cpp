#include "scenes/pneunet.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <limits>
#include <vector>

#include <Eigen/Geometry>
#include <openvdb/openvdb.h>

#include "core/errors.h"
#include "core/number_text.h"

// How the mesh is built
// ---------------------
// 1. Solid: an OpenVDB voxel solid (MaskGrid) made by CSG of boxes in index space,
//    (base U body) \ (chambers U channel), with Grid::topologyUnion / topologyDifference. A
//    voxel belongs to a box when its centre lies strictly inside the box.
// 2. Grid: a rectilinear grid whose lines include every feature plane (box faces and the fabric
//    faces); each interval between feature planes gets ceil(len / h) equal cells (the fabric
//    gets fabric_layers; a membrane fabric adds its mid-plane, see FabricModel). Inside one cell
//    the solid indicator is therefore constant.
// 3. Each cell is classified by the voxel nearest to its centre. The voxel size v is the
//    smallest distance from any cell centre to a box face, so that voxel's centre (within v/2
//    of the cell centre per axis) lies on the same side of every box face as the cell centre:
//    the classification is exact and the volumes are exact up to round-off.
// 4. Solid cells are split into 5 tetrahedra with alternating parity (see cell_splits()).
//
// Why a voxel mask and not narrow-band level sets (tools::createLevelSetBox + csgUnion /
// csgDifference): only the inside/outside bit at voxel centres is used, and both give the same
// bit under the rule of step 3; meshToVolume costs ~0.3 s of CPU per large box at the default
// v = 0.4 mm (about 1 s per build) and rounds box corners to float index coordinates, while
// CoordBBox fills are exact integer ranges that take milliseconds.
namespace pneufem {

namespace {

constexpr double kMaxCells = 5e6;  // refuse meshes larger than this (cells)
// Refuse voxel solids whose box surfaces cross more voxels than this: the mask tree then holds
// about 5e7 / 64 = 8e5 partially filled leaves (~100 MB).
constexpr double kMaxSurfaceVoxels = 5e7;

// ---------------------------------------------------------------------------------------------
// Feature planes and the rectilinear grid
// ---------------------------------------------------------------------------------------------

/// Feature planes of one axis, strictly increasing.
struct AxisPlanes {
  std::vector<double> at;
  std::vector<char> solid;        ///< per plane: the solid indicator may change across it
  std::vector<int> fixed_cells;   ///< per interval: forced cell count, 0 = ceil(len / h)
};

struct Box {
  std::array<double, 3> lo, hi;
  double area() const {
    const double a = hi[0] - lo[0], b = hi[1] - lo[1], c = hi[2] - lo[2];
    return 2.0 * (a * b + b * c + c * a);
  }
};

struct Plan {
  std::array<std::vector<double>, 3> lines;  ///< grid lines per axis (x, y, z)
  double voxel = 0.0;                        ///< OpenVDB voxel size (m)
  std::vector<Box> add, cut;                 ///< CSG: union of `add` minus union of `cut`
};

/// Chamber i spans y in [chamber_y0(i), chamber_y0(i) + chamber_length].
double chamber_y0(const PneuNetParams& p, int i) { return p.end_cap + i * (p.chamber_length + p.interior_wall); }

/// z of the fabric mid-plane, where FabricModel::Membrane puts the membrane.
double fabric_mid_plane(const PneuNetParams& p) { return p.fabric_z0 + 0.5 * p.fabric_thickness; }

std::array<AxisPlanes, 3> feature_planes(const PneuNetParams& p) {
  std::array<AxisPlanes, 3> ax;
  auto add = [](AxisPlanes& a, double v, bool solid) {
    a.at.push_back(v);
    a.solid.push_back(solid ? 1 : 0);
  };
  const double hw = 0.5 * p.width, hc = 0.5 * (p.width - 2.0 * p.side_wall), hch = 0.5 * p.channel_width;
  // x: the symmetry plane is a mesh boundary only; the OpenVDB solid continues across it.
  if (p.half) {
    add(ax[0], 0.0, false);
  } else {
    add(ax[0], -hw, true);
    add(ax[0], -hc, true);
    add(ax[0], -hch, true);
  }
  add(ax[0], hch, true);
  add(ax[0], hc, true);
  add(ax[0], hw, true);
  // y: the channel starts at the first chamber and ends at the last, so it adds no plane.
  add(ax[1], 0.0, true);
  for (int i = 0; i < p.chambers; ++i) {
    add(ax[1], chamber_y0(p, i), true);
    add(ax[1], chamber_y0(p, i) + p.chamber_length, true);
  }
  add(ax[1], p.length(), true);
  // z: the fabric faces bound a region, not the solid.
  const double hb = p.base_thickness;
  const bool membrane = p.fabric_model == FabricModel::Membrane;
  add(ax[2], 0.0, true);
  add(ax[2], p.fabric_z0, false);
  if (membrane) add(ax[2], fabric_mid_plane(p), false);
  add(ax[2], p.fabric_z0 + p.fabric_thickness, false);
  add(ax[2], hb, true);
  add(ax[2], hb + p.channel_height, true);
  add(ax[2], hb + p.body_height - p.roof, true);
  add(ax[2], hb + p.body_height, true);
  for (auto& a : ax) a.fixed_cells.assign(a.at.size() - 1, 0);
  if (membrane)
    ax[2].fixed_cells[1] = ax[2].fixed_cells[2] = (p.fabric_layers + 1) / 2;
  else
    ax[2].fixed_cells[1] = p.fabric_layers;
  // y intervals 2, 4, ..., 2(N-1) are the interior walls (0 is the end cap, odd ones chambers).
  if (p.wall_layers > 0)
    for (int i = 0; i + 1 < p.chambers; ++i) ax[1].fixed_cells[2 + 2 * i] = p.wall_layers;
  for (int d = 0; d < 3; ++d)
    for (std::size_t m = 0; m + 1 < ax[d].at.size(); ++m)
      if (!(ax[d].at[m + 1] > ax[d].at[m]))
        throw InputError("geometry: two feature planes along " + std::string(1, "xyz"[d]) +
                         " coincide (at " + short_num(ax[d].at[m]) +
                         " m); a length is too small relative to the others to be represented");
  return ax;
}

/// Cells in an interval of length len for target size h. The relative slack keeps
/// len/h = 3 * (1 + 1e-16) at 3 cells.
double cells_for(double len, double h) { return std::max(1.0, std::ceil(len / h * (1.0 - 1e-12))); }

double interval_cells(const AxisPlanes& a, std::size_t m, double h) {
  return a.fixed_cells[m] > 0 ? a.fixed_cells[m] : cells_for(a.at[m + 1] - a.at[m], h);
}

/// Smallest distance from a cell centre of `lines` to a plane of `a` flagged solid.
double min_centre_distance(const AxisPlanes& a, const std::vector<double>& lines) {
  std::vector<double> solid;
  for (std::size_t m = 0; m < a.at.size(); ++m)
    if (a.solid[m]) solid.push_back(a.at[m]);
  double d = std::numeric_limits<double>::infinity();
  for (std::size_t c = 0; c + 1 < lines.size(); ++c) {
    const double x = 0.5 * (lines[c] + lines[c + 1]);
    const auto it = std::lower_bound(solid.begin(), solid.end(), x);
    if (it != solid.end()) d = std::min(d, *it - x);
    if (it != solid.begin()) d = std::min(d, x - *std::prev(it));
  }
  return d;
}

/// Target cell size along axis d: h in plane (x, y), h_z vertically when given.
double axis_h(const PneuNetParams& p, int d) { return d == 2 && p.h_z > 0.0 ? p.h_z : p.h; }

/// Grid lines, voxel size and CSG boxes; throws InputError when the mesh or the OpenVDB solid
/// would be too large. Assumes check_params(p) passed.
Plan make_plan(const PneuNetParams& p) {
  const auto ax = feature_planes(p);
  double cells = 1.0;
  std::array<double, 3> per_axis{};
  for (int d = 0; d < 3; ++d) {
    for (std::size_t m = 0; m + 1 < ax[d].at.size(); ++m) per_axis[d] += interval_cells(ax[d], m, axis_h(p, d));
    cells *= per_axis[d];
  }
  if (cells > kMaxCells)
    throw InputError("mesh.h = " + short_num(p.h) + " m gives " + short_num(std::round(cells / 1e5) / 10) +
                     " million grid cells (limit " + short_num(kMaxCells / 1e6) +
                     " million); use a larger mesh.h (or fewer mesh.fabric_layers)");

  Plan plan;
  for (int d = 0; d < 3; ++d) {
    auto& L = plan.lines[d];
    for (std::size_t m = 0; m + 1 < ax[d].at.size(); ++m) {
      const double a = ax[d].at[m], b = ax[d].at[m + 1];
      const int n = static_cast<int>(interval_cells(ax[d], m, axis_h(p, d)));
      for (int s = 0; s < n; ++s) L.push_back(a + (b - a) * s / n);
    }
    L.push_back(ax[d].at.back());
  }

  // CSG boxes. The half model needs x >= 0 only: boxes are clipped a few voxels below x = 0
  // (sampled voxels have x >= -v/2).
  double v = std::numeric_limits<double>::infinity();
  for (int d = 0; d < 3; ++d) v = std::min(v, min_centre_distance(ax[d], plan.lines[d]));
  plan.voxel = v;
  const double hw = 0.5 * p.width, hc = 0.5 * (p.width - 2.0 * p.side_wall), hch = 0.5 * p.channel_width;
  const double x_lo = p.half ? -4.0 * v : -hw;
  const double hb = p.base_thickness, L = p.length();
  auto box = [&](double x0, double x1, double y0, double y1, double z0, double z1) {
    return Box{{std::max(x0, x_lo), y0, z0}, {x1, y1, z1}};
  };
  plan.add.push_back(box(-hw, hw, 0.0, L, 0.0, hb));
  plan.add.push_back(box(-hw, hw, 0.0, L, hb, hb + p.body_height));
  for (int i = 0; i < p.chambers; ++i)
    plan.cut.push_back(box(-hc, hc, chamber_y0(p, i), chamber_y0(p, i) + p.chamber_length, hb,
                           hb + p.body_height - p.roof));
  plan.cut.push_back(box(-hch, hch, chamber_y0(p, 0), chamber_y0(p, p.chambers - 1) + p.chamber_length, hb,
                         hb + p.channel_height));

  // Filled boxes are stored as tiles inside and partial leaves along their surfaces.
  double area = 0.0;
  for (const auto* list : {&plan.add, &plan.cut})
    for (const Box& b : *list) area += b.area();
  const double voxels = area / (v * v);
  if (voxels > kMaxSurfaceVoxels)
    throw InputError("geometry: a cell centre lies only " + short_num(v) +
                     " m from a face of the solid, so the OpenVDB solid would need voxels of that size (about " +
                     short_num(std::round(voxels / 1e5) / 10) + " million surface voxels, limit " +
                     short_num(kMaxSurfaceVoxels / 1e6) +
                     " million); avoid very thin gaps between feature planes (e.g. fabric top just below "
                     "geometry.base_thickness, channel almost as wide as the chamber) or increase mesh.h");
  return plan;
}

void check_positive(double v, const std::string& key, const char* what) {
  if (!(std::isfinite(v) && v > 0.0))
    throw InputError(key + " must be a positive length in metres (got " + short_num(v) + "); it is the " + what);
}

void check_params(const PneuNetParams& p) {
  check_positive(p.width, "geometry.width", "actuator width (x)");
  check_positive(p.base_thickness, "geometry.base_thickness", "base slab thickness (z)");
  check_positive(p.body_height, "geometry.body_height", "body height above the base (z)");
  check_positive(p.chamber_length, "geometry.chamber_length", "chamber length (y)");
  check_positive(p.interior_wall, "geometry.interior_wall", "wall thickness between chambers (y)");
  check_positive(p.side_wall, "geometry.side_wall", "side wall thickness (x)");
  check_positive(p.roof, "geometry.roof", "roof thickness above the chambers (z)");
  check_positive(p.end_cap, "geometry.end_cap", "end wall thickness (y)");
  check_positive(p.channel_width, "geometry.channel_width", "air channel width (x)");
  check_positive(p.channel_height, "geometry.channel_height", "air channel height (z)");
  check_positive(p.fabric_z0, "geometry.fabric_z0", "height of the fabric layer bottom above z = 0");
  check_positive(p.fabric_thickness, "geometry.fabric_thickness", "fabric layer thickness (z)");
  if (p.chambers < 1)
    throw InputError("geometry.chambers must be >= 1 (got " + std::to_string(p.chambers) + ")");
  const double chamber_width = p.width - 2.0 * p.side_wall;
  if (!(chamber_width > 0.0))
    throw InputError("geometry.side_wall: 2 * side_wall (" + short_num(2.0 * p.side_wall) +
                     " m) must be less than geometry.width (" + short_num(p.width) +
                     " m) to leave room for the chambers; thin the side walls or widen the actuator");
  if (!(p.channel_width < chamber_width))
    throw InputError("geometry.channel_width (" + short_num(p.channel_width) +
                     " m) must be less than the chamber width width - 2 * side_wall (" + short_num(chamber_width) +
                     " m); narrow the channel or thin the side walls");
  if (!(p.roof < p.body_height))
    throw InputError("geometry.roof (" + short_num(p.roof) + " m) must be less than geometry.body_height (" +
                     short_num(p.body_height) + " m) to leave room for the chambers");
  if (!(p.channel_height < p.body_height - p.roof))
    throw InputError("geometry.channel_height (" + short_num(p.channel_height) +
                     " m) must be less than the chamber height body_height - roof (" +
                     short_num(p.body_height - p.roof) + " m)");
  if (!(p.fabric_z0 + p.fabric_thickness < p.base_thickness))
    throw InputError("geometry.fabric_thickness: the fabric layer [fabric_z0, fabric_z0 + fabric_thickness] = [" +
                     short_num(p.fabric_z0) + ", " + short_num(p.fabric_z0 + p.fabric_thickness) +
                     "] m must lie strictly inside the base (below geometry.base_thickness = " +
                     short_num(p.base_thickness) + " m); lower geometry.fabric_z0, thin the fabric or thicken the base");
  if (!(std::isfinite(p.h) && p.h > 0.0))
    throw InputError("mesh.h must be a positive element size in metres (got " + short_num(p.h) + "), e.g. 2e-3");
  if (p.fabric_layers < 1)
    throw InputError("mesh.fabric_layers must be >= 1 (got " + std::to_string(p.fabric_layers) + ")");
}

// ---------------------------------------------------------------------------------------------
// OpenVDB solid
// ---------------------------------------------------------------------------------------------

openvdb::MaskGrid::Ptr make_solid(const Plan& plan) {
  openvdb::initialize();
  const auto xform = openvdb::math::Transform::createLinearTransform(plan.voxel);
  // Voxel i (centre at world i * v) is in the box iff lo < i v < hi.
  auto voxels_of = [&](const Box& b) {
    const openvdb::Vec3d lo = xform->worldToIndex(openvdb::Vec3d(b.lo[0], b.lo[1], b.lo[2]));
    const openvdb::Vec3d hi = xform->worldToIndex(openvdb::Vec3d(b.hi[0], b.hi[1], b.hi[2]));
    auto grid = openvdb::MaskGrid::create();
    grid->setTransform(xform);
    const openvdb::Coord first(static_cast<int>(std::floor(lo[0])) + 1, static_cast<int>(std::floor(lo[1])) + 1,
                               static_cast<int>(std::floor(lo[2])) + 1);
    const openvdb::Coord last(static_cast<int>(std::ceil(hi[0])) - 1, static_cast<int>(std::ceil(hi[1])) - 1,
                              static_cast<int>(std::ceil(hi[2])) - 1);
    const openvdb::CoordBBox bbox(first, last);
    if (!bbox.empty()) grid->fill(bbox, true, true);
    return grid;
  };
  auto solid = voxels_of(plan.add.front());
  for (std::size_t i = 1; i < plan.add.size(); ++i) solid->topologyUnion(*voxels_of(plan.add[i]));
  auto cavity = voxels_of(plan.cut.front());
  for (std::size_t i = 1; i < plan.cut.size(); ++i) cavity->topologyUnion(*voxels_of(plan.cut[i]));
  solid->topologyDifference(*cavity);
  return solid;
}

// ---------------------------------------------------------------------------------------------
// Hex -> tet split
// ---------------------------------------------------------------------------------------------

// Cell corner c = a + 2 b + 4 c' with (a, b, c') in {0,1}^3 the local (x, y, z) offsets.
//
// Choice: the 5-tet split with alternating parity. Every cell is cut into the tetrahedron of its
// four corners with even global parity (i + j + k + a + b + c' even) plus the four corner
// tetrahedra at the odd corners. Each hex face is thus split along the diagonal joining its two
// even corners, the same from both sides, so the mesh is conforming. Compared with the 6-tet
// Kuhn split it has 5/6 of the elements, no cell-diagonal edges (about 6 instead of 7 edges per
// grid node, i.e. ~12 % fewer Tet10 nodes), and better shapes: on a cube the radius ratio is 1
// (central tet) and 0.73 (corner tets) versus 0.72 for every Kuhn tet.
struct CellSplit {
  std::array<std::array<int, 4>, 5> tet;        ///< local corners, positive volume
  std::array<std::array<int, 4>, 5> face_dir;   ///< per Abaqus face: hex face 2*axis+side or -1
};

const std::array<CellSplit, 2>& cell_splits() {
  static const std::array<CellSplit, 2> splits = [] {
    std::array<CellSplit, 2> s{};
    auto bit = [](int c, int axis) { return (c >> axis) & 1; };
    for (int q = 0; q < 2; ++q) {
      int t = 1;
      std::array<int, 4> central{};
      int n = 0;
      for (int c = 0; c < 8; ++c) {
        if ((std::popcount(static_cast<unsigned>(c)) + q) % 2 == 0)
          central[n++] = c;
        else
          s[q].tet[t++] = {c, c ^ 1, c ^ 2, c ^ 4};
      }
      s[q].tet[0] = central;
      for (auto& tet : s[q].tet) {
        // Signed volume on the unit cube; cells are positive axis scalings of it.
        auto edge = [&](int k) {
          return Eigen::Vector3d(bit(tet[k], 0) - bit(tet[0], 0), bit(tet[k], 1) - bit(tet[0], 1),
                                 bit(tet[k], 2) - bit(tet[0], 2));
        };
        if (edge(1).cross(edge(2)).dot(edge(3)) < 0) std::swap(tet[1], tet[2]);
      }
      for (int e = 0; e < 5; ++e)
        for (int f = 0; f < 4; ++f) {
          const int* fn = face_local_nodes(ElementType::Tet4, f);
          const int c0 = s[q].tet[e][fn[0]], c1 = s[q].tet[e][fn[1]], c2 = s[q].tet[e][fn[2]];
          s[q].face_dir[e][f] = -1;
          for (int axis = 0; axis < 3; ++axis)
            if (bit(c0, axis) == bit(c1, axis) && bit(c1, axis) == bit(c2, axis))
              s[q].face_dir[e][f] = 2 * axis + bit(c0, axis);
        }
    }
    return s;
  }();
  return splits;
}

/// The plan's grid: nx x ny x nz cells between its grid lines, cells and nodes numbered y
/// outermost, then z, then x.
struct CellGrid {
  const std::vector<double>& gx;
  const std::vector<double>& gy;
  const std::vector<double>& gz;
  int nx, ny, nz;
  explicit CellGrid(const Plan& plan)
      : gx(plan.lines[0]), gy(plan.lines[1]), gz(plan.lines[2]), nx(static_cast<int>(gx.size()) - 1),
        ny(static_cast<int>(gy.size()) - 1), nz(static_cast<int>(gz.size()) - 1) {}
  std::size_t cell(int i, int j, int k) const { return (static_cast<std::size_t>(j) * nz + k) * nx + i; }
  int node(int i, int j, int k) const { return (j * (nz + 1) + k) * (nx + 1) + i; }
};

/// Per cell of the grid: 1 where its centre is inside the OpenVDB solid of the plan.
std::vector<char> solid_cells(const Plan& plan, const CellGrid& g) {
  std::vector<char> solid(static_cast<std::size_t>(g.nx) * g.ny * g.nz, 0);
  const auto grid = make_solid(plan);
  const auto acc = grid->getConstAccessor();
  const auto& xform = grid->transform();
  for (int j = 0; j < g.ny; ++j)
    for (int k = 0; k < g.nz; ++k)
      for (int i = 0; i < g.nx; ++i) {
        const openvdb::Vec3d c(0.5 * (g.gx[i] + g.gx[i + 1]), 0.5 * (g.gy[j] + g.gy[j + 1]), 0.5 * (g.gz[k] + g.gz[k + 1]));
        solid[g.cell(i, j, k)] = acc.isValueOn(openvdb::Coord::round(xform.worldToIndex(c)));
      }
  return solid;
}

/// The region of a solid cell from its centre: fabric (when solid), base, end cap, roof, side
/// wall, else interior wall. Cell centres are at least half a cell from every feature plane, so
/// strict comparisons are safe.
struct RegionOfCell {
  std::uint16_t base, fabric, cap, side, roof, wall;
  bool solid_fabric;
  double hb, L, z_roof, x_side, z_fab0, z_fab1, end_cap;
  RegionOfCell(Mesh& m, const PneuNetParams& p)
      // Fixed region order, independent of which regions a parameter set produces first.
      : base(m.region_id(regions::kBase)), fabric(m.region_id(regions::kFabric)), cap(m.region_id(regions::kEndCap)),
        side(m.region_id(regions::kSideWall)), roof(m.region_id(regions::kRoof)),
        wall(m.region_id(regions::kInteriorWall)), solid_fabric(p.fabric_model == FabricModel::Solid),
        hb(p.base_thickness), L(p.length()), z_roof(hb + p.body_height - p.roof), x_side(0.5 * p.width - p.side_wall),
        z_fab0(p.fabric_z0), z_fab1(p.fabric_z0 + p.fabric_thickness), end_cap(p.end_cap) {}
  std::uint16_t operator()(double x, double y, double z) const {
    if (solid_fabric && z > z_fab0 && z < z_fab1) return fabric;
    if (z < hb) return base;
    if (y < end_cap || y > L - end_cap) return cap;
    if (z > z_roof) return roof;
    if (std::abs(x) > x_side) return side;
    return wall;
  }
};

/// Element sets FABRIC (exists, empty for a membrane fabric) and SILICONE, node sets FIXED (y = 0),
/// TIP (the last y line) and, for a half model, SYMMETRY (x = 0), from the grid indices (exact).
void add_pneunet_sets(Mesh& m, const CellGrid& g, bool half, std::uint16_t r_fabric) {
  m.element_sets["FABRIC"];
  for (int e = 0; e < m.num_elements(); ++e) m.element_sets[m.region[e] == r_fabric ? "FABRIC" : "SILICONE"].push_back(e);
  auto& fixed = m.node_sets["FIXED"];
  auto& tip = m.node_sets["TIP"];
  for (int k = 0; k <= g.nz; ++k)
    for (int i = 0; i <= g.nx; ++i) {
      fixed.push_back(g.node(i, 0, k));
      tip.push_back(g.node(i, g.ny, k));
    }
  if (half) {
    auto& sym = m.node_sets["SYMMETRY"];
    for (int j = 0; j <= g.ny; ++j)
      for (int k = 0; k <= g.nz; ++k) sym.push_back(g.node(0, j, k));
  }
  for (auto& [name, nodes] : m.node_sets) std::sort(nodes.begin(), nodes.end());
}

}  // namespace

void PneuNetParams::validate() const {
  check_params(*this);
  (void)make_plan(*this);
}

Mesh build_pneunet(const PneuNetParams& p) {
  check_params(p);
  const Plan plan = make_plan(p);
  const CellGrid g(plan);
  const auto& gx = g.gx;
  const auto& gy = g.gy;
  const auto& gz = g.gz;
  const int nx = g.nx, ny = g.ny, nz = g.nz;
  // Classify cells (y outermost, then z, then x) by the OpenVDB solid.
  const std::vector<char> solid = solid_cells(plan, g);

  Mesh m;
  m.type = ElementType::Tet4;
  const RegionOfCell region_of(m, p);
  const bool solid_fabric = region_of.solid_fabric;

  m.X.resize(static_cast<std::size_t>(nx + 1) * (ny + 1) * (nz + 1));
  for (int j = 0; j <= ny; ++j)
    for (int k = 0; k <= nz; ++k)
      for (int i = 0; i <= nx; ++i) m.X[g.node(i, j, k)] = Eigen::Vector3d(gx[i], gy[j], gz[k]);

  const auto& splits = cell_splits();
  std::vector<FaceRef> cavity, membrane;
  // Membrane fabric: the top faces (hex face z+ = 5) of the cells just below the mid-plane grid
  // line, so each face on the plane is taken once. -1 = solid fabric.
  const int k_membrane =
      solid_fabric ? -1
                   : static_cast<int>(std::find(gz.begin(), gz.end(), fabric_mid_plane(p)) - gz.begin()) - 1;
  assert(solid_fabric || (k_membrane >= 0 && k_membrane < nz));  // the mid-plane is a grid line
  // Hex face 2*axis+side -> neighbour offset.
  static constexpr int kStep[6][3] = {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}};
  for (int j = 0; j < ny; ++j)
    for (int k = 0; k < nz; ++k)
      for (int i = 0; i < nx; ++i) {
        if (!solid[g.cell(i, j, k)]) continue;
        const std::uint16_t r = region_of(0.5 * (gx[i] + gx[i + 1]), 0.5 * (gy[j] + gy[j + 1]), 0.5 * (gz[k] + gz[k + 1]));
        const CellSplit& s = splits[(i + j + k) % 2];
        for (int t = 0; t < 5; ++t) {
          const int e = m.num_elements();
          for (int c : s.tet[t]) m.conn.push_back(g.node(i + (c & 1), j + ((c >> 1) & 1), k + ((c >> 2) & 1)));
          m.region.push_back(r);
          for (int f = 0; f < 4; ++f) {
            const int d = s.face_dir[t][f];
            if (d < 0) continue;
            if (k == k_membrane && d == 5) membrane.push_back({e, f});
            const int ii = i + kStep[d][0], jj = j + kStep[d][1], kk = k + kStep[d][2];
            // Every void cell of the grid is cavity: the grid spans the actuator's bounding box
            // (or its x >= 0 half), and the cavity is enclosed by end caps, side walls, roof and base.
            if (ii < 0 || ii >= nx || jj < 0 || jj >= ny || kk < 0 || kk >= nz) continue;
            if (!solid[g.cell(ii, jj, kk)]) cavity.push_back({e, f});
          }
        }
      }
  m.surfaces["CAVITY"] = std::move(cavity);
  if (!solid_fabric) m.surfaces["FABRIC_MEMBRANE"] = std::move(membrane);
  add_pneunet_sets(m, g, p.half, region_of.fabric);

  // promote_to_tet10 adds a mid-edge node to a node set when both corners are in it, which is
  // exact here because the sets are planes.
  if (p.element == ElementType::Tet10) m = promote_to_tet10(m);
  renumber_nodes_by_first_use(m);
  m.ensure_ids();
  return m;
}

}  // namespace pneufem
