#pragma once
// Parametric slow pneu-net geometry, built as a solid with OpenVDB (voxel CSG of boxes) and
// meshed into conforming tetrahedra with region tags, named node sets and the cavity surface:
// a rectilinear grid through every feature plane, each solid cell split into 5 tetrahedra
// (scenes/pneunet.cpp explains the choices). Volumes and areas are exact; the build is
// deterministic, elements are ordered along y and nodes by first use.
//
// Frame (as the CalculiX reference, bench/calculix/README.md): x = width (centred on 0),
// y = length (0 at the fixed inlet end), z = up (0 at the bottom of the base). SI units (m).
#include <cstdint>
#include <string>

#include "engine/mesh.h"

namespace pneufem {

/// How the fabric strain-limiting layer is represented.
///  Solid:    its cells are elements of region "fabric" (element set FABRIC), a layer with the
///            bending stiffness of a 0.4 mm plate.
///  Membrane: its cells are base silicone (element set SILICONE), a grid plane is added at the
///            layer's mid-plane, and the element faces on that plane form the surface
///            FABRIC_MEMBRANE, each once, for a membrane (engine/membrane.h): no bending stiffness.
///            Each half of the layer gets ceil(fabric_layers / 2) cells; FABRIC is present but empty.
enum class FabricModel : std::uint8_t { Solid, Membrane };

struct PneuNetParams {
  // Geometry (m). Defaults: the default actuator of the engine issue (= CalculiX reference).
  double width = 22e-3;            ///< x
  double base_thickness = 3e-3;    ///< base slab, z in [0, base_thickness]
  double body_height = 15e-3;      ///< body above the base
  int chambers = 15;
  double chamber_length = 6e-3;    ///< y extent of a chamber
  double interior_wall = 2e-3;     ///< y thickness of the walls between chambers
  double side_wall = 7e-3;         ///< x thickness of the side walls (chamber width = width - 2 side)
  double roof = 7e-3;              ///< z thickness above the chambers (chamber height = body - roof)
  double end_cap = 4e-3;           ///< y thickness of the end walls
  double channel_width = 2e-3;     ///< air channel, x-centred
  double channel_height = 2e-3;    ///< from the base top face
  double fabric_z0 = 1.8e-3;       ///< fabric layer bottom
  double fabric_thickness = 0.4e-3;
  // Mesh.
  double h = 2e-3;                 ///< target element size in plane (x, y) (m)
  double h_z = 0.0;                ///< target element size along z (m); 0 = same as h
  int fabric_layers = 1;           ///< elements through the fabric thickness
  FabricModel fabric_model = FabricModel::Solid;  ///< scene key mesh.fabric_model
  int wall_layers = 0;             ///< cells through each interior wall (y); 0 = from h
  bool half = true;                ///< model x >= 0 only, symmetry plane x = 0
  ElementType element = ElementType::Tet10;

  double length() const { return 2 * end_cap + chambers * chamber_length + (chambers - 1) * interior_wall; }
  /// Throws InputError naming the offending parameter (scene key "geometry.<name>").
  void validate() const;
};

/// Builds the mesh. Node sets: "FIXED" (face y = 0), "TIP" (face y = L), "SYMMETRY" (x = 0,
/// half model only). Element sets: "SILICONE", "FABRIC". Surface "CAVITY": every face bounding
/// the chambers and the channel (including the cavity floor on the base); with
/// FabricModel::Membrane also "FABRIC_MEMBRANE" (faces on the fabric mid-plane). Region tags:
/// interior_wall, roof, side_wall, end_cap, base, fabric (mesh.h).
Mesh build_pneunet(const PneuNetParams& p);

}  // namespace pneufem
