#pragma once
// Elastic response curves for diagnose: the bending angle of a history-free scene as a function of
// the chamber pressure, from static FEM equilibria, and its interpolation over the rig angle (the
// direction of gravity), which lets diagnose calibrate the rig angle on five FEM sweeps.
#include <array>
#include <cstddef>
#include <vector>

namespace pneufem {

struct BuiltModel;

/// Angles (deg, unwrapped) of the static FEM equilibria at p = hi_Pa i / n, i = 0..n (gravity and
/// every other load of the model on; internal variables are not evolved: elastic models only).
/// Throws PhysicsError when an equilibrium cannot be found.
std::vector<double> static_angle_curve(const BuiltModel& bm, double hi_Pa, int n);

/// Rig angle phi: gravity g = |g| (0, cos phi, -sin phi) in the scene frame (y along the actuator,
/// z up); 0 = hanging tip-down, pi/2 = horizontal with the fabric side down.
constexpr int kRigAngleNodes = 5;
/// Node j = 0..4 of the interpolation: j pi / 4 (0, 45, 90, 135, 180 deg).
double rig_angle_node_rad(int j);
/// Weights w_j with f(phi) = sum_j w_j f(phi_j) for every trigonometric polynomial
/// f = a0 + a1 cos phi + b1 sin phi + a2 cos 2phi + b2 sin 2phi (exact at the nodes).
/// Why this basis: the angle is a smooth function of the load direction; its first harmonic is the
/// linear response to the actuator's weight and the second the leading nonlinearity in it.
std::array<double, kRigAngleNodes> rig_angle_weights(double phi_rad);

/// Polynomial interpolation of degree kSmoothNodes - 1 on [0, 1] for a smooth response in a
/// calibration coordinate (e.g. log of a stiffness scale): Chebyshev-Lobatto nodes
/// x_j = (1 - cos(j pi / (kSmoothNodes - 1))) / 2, which include the ends and keep the Lebesgue
/// constant small (no Runge oscillation near the bounds).
constexpr int kSmoothNodes = 7;
double smooth_node(int j);
/// Lagrange weights w_j(x), sum_j w_j f(x_j) = f(x) for every polynomial of degree <= kSmoothNodes - 1.
std::array<double, kSmoothNodes> smooth_weights(double x);
/// Lagrange weights on any distinct nodes (diagnose drops nodes the FEM cannot reach).
std::vector<double> lagrange_weights(const std::vector<double>& nodes, double x);

/// The nodes diagnose interpolates between when some are unreachable for the FEM (a softened
/// actuator past its limit point): the longest run of consecutive reachable nodes (the first on a
/// tie), or none (count 0) when it is shorter than `min_count`. Values outside the run are then
/// simulated one by one. Why consecutive: interpolating across a gap would bridge a parameter range
/// where the model does not exist.
struct NodeRun {
  std::size_t first = 0, count = 0;
};
NodeRun longest_reachable_run(const std::vector<bool>& reachable, std::size_t min_count);

}  // namespace pneufem
