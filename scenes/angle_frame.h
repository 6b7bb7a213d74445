#pragma once
// The bending angle's frame of a deck and what hangs on it: the free end's nodes, the fixed normal
// and bend direction taken from the mesh or checked against it, and the rig's gravity in that frame.
// Internal to scenes/: build_model (build_model.cpp) calls them in this order, once the boundary
// conditions and parts are set.
#include <string>
#include <vector>

#include "engine/model.h"
#include "scenes/scene.h"

namespace pneufem::detail {

/// The free end face of a deck: the node set mesh.tip_set; when the scene leaves that key at its
/// default and the deck has no such set, the boundary nodes farthest from the clamp, with a note. The
/// clamp's side is the outward normal of the clamped nodes' plane face (all three dofs fixed); the tip
/// face is then the set of boundary nodes within 0.1 % of the body's length of the farthest one along
/// the opposite direction, which must hold at least three nodes that are not on one line (a flat end
/// face; a rounded end gives its cap, whose fitted plane still turns with the tip).
std::vector<int> deck_tip_nodes(const Scene& s, const Model& model, std::vector<std::string>& warnings);

/// The angle's frame from the mesh, for decks oriented otherwise than the built-in actuator (whose
/// defaults the scene keys are). Two facts of the mesh fix it:
///  * the clamped nodes (all three dofs fixed) of a plane end face give the face's outward normal;
///    when they are not one plane face (a clamp over a length of the body), the direction from the
///    tip face's centroid to the clamped nodes' does;
///  * the inextensible (stiffest, 100x the softest) part lies on the side the actuator curls to.
/// With `from_mesh` (a deck whose scene leaves angle.fixed_normal / angle.bend_direction at their
/// defaults) the keys left at their defaults are taken from these, with a note naming the values (so a
/// deck along x, or tilted, needs no angle keys). Keys the user set are checked instead: a fixed normal
/// more than ~25 deg off the clamped face's would measure the rotation in a wrong plane, an error
/// naming the normal to use; a bend direction pointing away from the layer only flips the angle's
/// sign, a warning.
void resolve_angle_frame(const Scene& s, Model& model, bool from_mesh, std::vector<std::string>& warnings);

/// gravity.rig_angle_deg >= 0: the rig's orientation relative to the actuator, in its angle frame
/// (so a deck in any orientation, whose frame may come from the mesh, hangs the same way):
/// g = 9.81 (cos(phi) a + sin(phi) d), a = -angle.fixed_normal (along the actuator, away from the
/// clamp), d = the bend direction made perpendicular to a. For the built-in frame a = +y, d = -z, so
/// g = [0, 9.81 cos(phi), -9.81 sin(phi)] to the bit (components below 1e-12 g are exactly 0).
void set_rig_gravity(const Scene& s, Model& model);

}  // namespace pneufem::detail
