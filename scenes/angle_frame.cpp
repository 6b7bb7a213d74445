// The angle frame of scenes/angle_frame.h: a deck's tip nodes, the fixed normal and bend direction
// from the mesh (clamped face, stiff layer), and gravity from the rig angle.
#include "scenes/angle_frame.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <numbers>

#include <Eigen/Eigenvalues>

#include "scenes/scene_keys.h"

namespace pneufem::detail {

namespace {

/// Vector text for messages, e.g. "[0.0, -1.0, 0.0]" (rounded to 3 decimals: a hint, not data).
std::string vec_text(const Eigen::Vector3d& v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "[%.3f, %.3f, %.3f]", v.x() + 0.0, v.y() + 0.0, v.z() + 0.0);
  return buf;
}

}  // namespace

std::vector<int> deck_tip_nodes(const Scene& s, const Model& model, std::vector<std::string>& warnings) {
  const Mesh& mesh = model.mesh;
  const std::string name = s.string("mesh.tip_set");
  std::string upper = name;
  std::transform(upper.begin(), upper.end(), upper.begin(), ::toupper);
  if (s.origin("mesh.tip_set") != "default scene" || mesh.node_sets.count(name) || mesh.node_sets.count(upper))
    return node_set(s, mesh, "mesh.tip_set");
  auto give_up = [&](const std::string& why) -> std::vector<int> {
    std::string avail;
    for (const auto& [k, v] : mesh.node_sets) avail += (avail.empty() ? "" : ", ") + k;
    s.fail("mesh.tip_set", "node set '" + name + "' not found in the mesh (available: " + (avail.empty() ? "(none)" : avail) +
                               ") and the free end face cannot be found from the mesh: " + why +
                               "; name the node set of the free end face in mesh.tip_set");
  };
  std::vector<Eigen::Vector3d> clamped;
  for (int n = 0; n < mesh.num_nodes(); ++n)
    if (model.fixed[3 * n] && model.fixed[3 * n + 1] && model.fixed[3 * n + 2]) clamped.push_back(mesh.X[n]);
  if (clamped.size() < 3) return give_up("fewer than three clamped nodes");
  Eigen::Vector3d c = Eigen::Vector3d::Zero(), body = Eigen::Vector3d::Zero();
  for (const auto& x : clamped) c += x;
  c /= static_cast<double>(clamped.size());
  for (const auto& x : mesh.X) body += x;
  body /= static_cast<double>(mesh.num_nodes());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& x : clamped) cov += (x - c) * (x - c).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);  // ascending eigenvalues
  if (!(es.eigenvalues()[0] <= 1e-4 * es.eigenvalues()[2] && es.eigenvalues()[1] > 0.0))
    return give_up("the clamped nodes are not one plane face");
  Eigen::Vector3d axis = -es.eigenvectors().col(0);  // into the body, towards the tip
  if (axis.dot(body - c) < 0.0) axis = -axis;
  std::vector<char> on_boundary(mesh.num_nodes(), 0);
  for (const FaceRef& f : boundary_faces(mesh)) {
    const int* local = face_local_nodes(mesh.type, f.local_face);
    for (int a = 0; a < nodes_per_face(mesh.type); ++a) on_boundary[mesh.element(f.element)[local[a]]] = 1;
  }
  double lo = INFINITY, hi = -INFINITY;
  for (int n = 0; n < mesh.num_nodes(); ++n) {
    const double t = axis.dot(mesh.X[n] - c);
    lo = std::min(lo, t);
    hi = std::max(hi, t);
  }
  std::vector<int> tip;
  for (int n = 0; n < mesh.num_nodes(); ++n)
    if (on_boundary[n] && axis.dot(mesh.X[n] - c) >= hi - 1e-3 * (hi - lo)) tip.push_back(n);
  Eigen::Vector3d t0 = Eigen::Vector3d::Zero();
  for (int n : tip) t0 += mesh.X[n];
  t0 /= std::max<double>(1.0, static_cast<double>(tip.size()));
  Eigen::Matrix3d tcov = Eigen::Matrix3d::Zero();
  for (int n : tip) tcov += (mesh.X[n] - t0) * (mesh.X[n] - t0).transpose();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> ts(tcov);
  if (tip.size() < 3 || !(ts.eigenvalues()[1] > 1e-12 * ts.eigenvalues()[2]))
    return give_up("the boundary nodes farthest from the clamp do not span a face");
  char buf[160];
  std::snprintf(buf, sizeof buf, "%zu boundary nodes at %.4g mm from the clamped face", tip.size(), hi * 1e3);
  warnings.push_back("mesh.tip_set: the deck has no node set '" + name + "'; the free end face was taken from the mesh (" +
                     buf + "); name a node set in mesh.tip_set to choose another");
  return tip;
}

void resolve_angle_frame(const Scene& s, Model& model, bool from_mesh, std::vector<std::string>& warnings) {
  const Mesh& mesh = model.mesh;
  const bool normal_free = from_mesh && s.origin("angle.fixed_normal") == "default scene";
  const bool bend_free = from_mesh && s.origin("angle.bend_direction") == "default scene";
  Eigen::Vector3d body = Eigen::Vector3d::Zero();
  for (const auto& x : mesh.X) body += x;
  body /= static_cast<double>(mesh.num_nodes());
  std::vector<Eigen::Vector3d> clamped;
  for (int n = 0; n < mesh.num_nodes(); ++n)
    if (model.fixed[3 * n] && model.fixed[3 * n + 1] && model.fixed[3 * n + 2]) clamped.push_back(mesh.X[n]);
  // n_face: outward normal of the clamped plane face (or 0); n_axis: the body's axis at the clamp,
  // pointing out of it, from the tip face (or 0).
  Eigen::Vector3d n_face = Eigen::Vector3d::Zero(), n_axis = Eigen::Vector3d::Zero();
  if (clamped.size() >= 3) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero();
    for (const auto& x : clamped) c += x;
    c /= static_cast<double>(clamped.size());
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (const auto& x : clamped) cov += (x - c) * (x - c).transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);  // ascending eigenvalues
    const bool planar = es.eigenvalues()[0] <= 1e-4 * es.eigenvalues()[2] && es.eigenvalues()[1] > 0.0;
    Eigen::Vector3d n_fit = es.eigenvectors().col(0);
    if (n_fit.dot(c - body) < 0.0) n_fit = -n_fit;  // outward: away from the body
    if (planar && (c - body).norm() > 0.0) n_face = n_fit;
    if (!model.angle.tip_nodes.empty()) {
      Eigen::Vector3d t = Eigen::Vector3d::Zero();
      for (int n : model.angle.tip_nodes) t += mesh.X[n];
      t /= static_cast<double>(model.angle.tip_nodes.size());
      if ((c - t).norm() > 0.0) n_axis = (c - t).normalized();
    }
  }
  const Eigen::Vector3d n_mesh = n_face.norm() > 0.0 ? n_face : n_axis;
  if (normal_free && n_mesh.norm() > 0.0 && n_mesh.dot(model.angle.fixed_normal_out.normalized()) < 1.0 - 1e-9) {
    model.angle.fixed_normal_out = n_mesh;
    warnings.push_back("angle.fixed_normal taken from the mesh: " + vec_text(n_mesh) + " (the outward normal of " +
                       (n_face.norm() > 0.0 ? std::string("the clamped end face")
                                            : std::string("the clamped end, from the tip face's centroid to the clamped nodes'")) +
                       "); set angle.fixed_normal to choose another");
  }
  const Eigen::Vector3d n_given = model.angle.fixed_normal_out.normalized();
  if (!normal_free && n_face.norm() > 0.0 && n_face.dot(n_given) < 0.9)
    s.fail("angle.fixed_normal", "is " + vec_text(n_given) + " but the clamped nodes lie on a plane face whose outward "
                                 "normal is " + vec_text(n_face) + ": set angle.fixed_normal = " + vec_text(n_face) +
                                 " and angle.bend_direction perpendicular to it, towards the inextensible layer");
  // The side of the stiff layer, across the actuator (0 when no part is 100x stiffer than another).
  Eigen::Vector3d side = Eigen::Vector3d::Zero();
  double mu_min = INFINITY, mu_max = 0.0;
  for (const Part& p : model.parts) {
    mu_min = std::min(mu_min, p.material->initial_shear_modulus());
    mu_max = std::max(mu_max, p.material->initial_shear_modulus());
  }
  Eigen::Vector3d layer = Eigen::Vector3d::Zero();
  double count = 0.0;
  if (mu_max > 100.0 * mu_min) {
    for (int e = 0; e < mesh.num_elements(); ++e)
      if (model.material_of(e).initial_shear_modulus() == mu_max)
        for (int a = 0; a < mesh.npe(); ++a) layer += mesh.X[mesh.element(e)[a]], count += 1.0;
  } else {  // a membrane fabric (mesh.fabric_model = "membrane") is the layer
    for (const MembraneSet& m : model.membranes)
      for (int n : m.nodes) layer += mesh.X[n], count += 1.0;
  }
  if (count > 0.0) {
    side = layer / count - body;
    side -= side.dot(n_given) * n_given;  // across the actuator, not along it
  }
  if (model.angle.mirror_axis >= 0) side[model.angle.mirror_axis] = 0.0;  // a half model bends in its symmetry plane
  if (bend_free) {
    // The default direction made perpendicular to the normal is kept when it points within 10 deg of
    // the layer's side (a translated deck keeps the built-in's exact axes: the centroid of an
    // asymmetric section is a little off its bending plane); otherwise the side of the layer; without
    // a stiff layer the default, else the coordinate axis most perpendicular to the normal.
    Eigen::Vector3d d0 = model.angle.bend_direction - model.angle.bend_direction.dot(n_given) * n_given;
    const bool d0_ok = d0.norm() >= 1e-3 * model.angle.bend_direction.norm();
    Eigen::Vector3d d = side;
    if (d0_ok && (side.norm() == 0.0 || d0.normalized().dot(side.normalized()) > std::cos(10.0 * std::numbers::pi / 180.0))) {
      d = d0;
    } else if (side.norm() == 0.0) {
      Eigen::Index k = 0;
      n_given.cwiseAbs().minCoeff(&k);
      d = Eigen::Vector3d::Unit(k) - n_given[k] * n_given;
    }
    d.normalize();
    if (d.dot(model.angle.bend_direction.normalized()) < 1.0 - 1e-9) {
      model.angle.bend_direction = d;
      warnings.push_back("angle.bend_direction taken from the mesh: " + vec_text(d) +
                         (side.norm() > 0.0 ? std::string(" (towards the inextensible layer, so angles are positive)")
                                            : std::string(" (no part is 100x stiffer than another, so the side the actuator "
                                                          "bends to is not known from the mesh: check the sign of the angles)")) +
                         "; set angle.bend_direction to choose another");
    }
    return;
  }
  const Eigen::Vector3d d = model.angle.bend_direction.normalized();
  if (side.norm() > 0.0 && d.dot(side.normalized()) < -0.5)
    warnings.push_back("angle.bend_direction " + vec_text(d) + " points away from the inextensible layer (towards " +
                       vec_text(-side.normalized()) + "), to which the actuator curls: its angles will come out "
                       "negative; set angle.bend_direction = " + vec_text(side.normalized()) +
                       " for the usual positive convention");
}

void set_rig_gravity(const Scene& s, Model& model) {
  const double phi_deg = s.number("gravity.rig_angle_deg");
  if (!std::isfinite(phi_deg)) s.fail("gravity.rig_angle_deg", "must be a number (< 0: off)");
  if (phi_deg < 0.0) return;
  if (phi_deg > 180.0) s.fail("gravity.rig_angle_deg", "must lie in [0, 180] deg (or < 0: off)");
  if (model.gravity_m_s2.norm() > 0.0)
    s.fail("gravity.rig_angle_deg", "and gravity.g_m_s2 both give gravity: set g_m_s2 = [0.0, 0.0, 0.0] or "
                                    "rig_angle_deg = -1.0");
  constexpr double g = 9.81;
  const double phi = phi_deg * std::numbers::pi / 180.0;
  const Eigen::Vector3d a = -model.angle.fixed_normal_out.normalized();
  const Eigen::Vector3d d = (model.angle.bend_direction - model.angle.bend_direction.dot(a) * a).normalized();
  const double ga = g * std::cos(phi), gd = g * std::sin(phi);
  for (int k = 0; k < 3; ++k) {
    const double v = ga * a[k] + gd * d[k];
    model.gravity_m_s2[k] = std::abs(v) < 1e-12 * g ? 0.0 : v;
  }
}

}  // namespace pneufem::detail
