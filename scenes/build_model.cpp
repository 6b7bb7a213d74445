#include "scenes/build_model.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <optional>
#include <map>
#include <numbers>
#include <set>
#include <sstream>

#include <Eigen/Eigenvalues>

#include "damage/effects.h"
#include "damage/registry.h"
#include "materials/errors.h"
#include "materials/hyperelastic.h"
#include "materials/ogden.h"
#include "materials/scaled.h"
#include "scenes/inp.h"
#include "scenes/inp_assembly.h"
#include "scenes/pneunet.h"
#include "scenes/pressure_lag.h"
#include "scenes/solid_split.h"

namespace pneufem {

namespace {

constexpr double kMPa = 1e6, kkPa = 1e3, kmm = 1e-3;

void require_keys(const Scene& scene, const std::string& table, const std::set<std::string>& allowed,
                  const std::string& what) {
  for (const std::string& k : scene.table_keys(table))
    if (!allowed.count(k)) {
      std::string list;
      for (const auto& a : allowed) list += (list.empty() ? "" : ", ") + a;
      scene.fail(table + "." + k, "unknown key for " + what + "; allowed: " + list);
    }
}

/// The value of a string key that must be one of `options` (its name -> value), or a failure
/// naming the key and every allowed name.
template <class T>
T choice(const Scene& scene, const std::string& key, std::initializer_list<std::pair<const char*, T>> options) {
  const std::string v = scene.string(key);
  std::string allowed;
  std::size_t i = 0;
  for (const auto& [name, value] : options) {
    if (v == name) return value;
    allowed += std::string(i == 0 ? "" : i + 1 == options.size() ? " or " : ", ") + "\"" + name + "\"";
    ++i;
  }
  scene.fail(key, "must be " + allowed + ", got \"" + v + "\"");
}

double positive(const Scene& scene, const std::string& key) {
  const double v = scene.number(key);
  if (!(v > 0.0)) scene.fail(key, "must be > 0");
  return v;
}

/// A name `key` gives that the mesh lacks but that several instances of a deck define (stored as
/// "INSTANCE.NAME" each, inp_assembly.h): a failure listing the qualified names to choose from.
template <class V>
void reject_ambiguous(const Scene& s, const std::string& key, const std::map<std::string, V>& names,
                      const std::string& name, const std::string& what) {
  std::string upper = name;
  std::transform(upper.begin(), upper.end(), upper.begin(), ::toupper);
  const std::vector<std::string> choices = inp::qualified_choices(names, upper);
  if (choices.size() > 1)
    s.fail(key, what + " '" + name + "' is defined by " + std::to_string(choices.size()) +
                    " instances of the deck; name one with its instance: " + inp::join_names(choices, " or "));
}

// ---- Fabric as a membrane (mesh.fabric_model, engine/membrane.h) --------------------------------

/// A surface of the mesh by its name as the scene writes it, or upper-cased (decks' names are);
/// nullptr if it has neither.
const std::pair<const std::string, std::vector<FaceRef>>* find_surface(const Mesh& mesh, const std::string& name) {
  std::string upper = name;
  std::transform(upper.begin(), upper.end(), upper.begin(), ::toupper);
  auto it = mesh.surfaces.find(name);
  if (it == mesh.surfaces.end()) it = mesh.surfaces.find(upper);
  return it == mesh.surfaces.end() ? nullptr : &*it;
}

/// mesh.fabric_model: "solid" (elements of set FABRIC) or "membrane".
bool fabric_is_membrane(const Scene& s) {
  const std::string v = s.string("mesh.fabric_model");
  if (v != "solid" && v != "membrane") s.fail("mesh.fabric_model", "must be \"solid\" or \"membrane\", got \"" + v + "\"");
  return v == "membrane";
}

/// The membrane fabric: the faces of surface mesh.fabric_surface (the mesher's FABRIC_MEMBRANE on
/// the layer's mid-plane, or a deck's surface: an embedded sheet of M3D3/M3D6/M3D4/M3D8 elements, a
/// *SURFACE), thickness geometry.fabric_thickness_mm, plane-stress St Venant-Kirchhoff with E and
/// nu of materials.fabric (which must be linear_elastic).
MembraneSet fabric_membrane(const Scene& s, const Mesh& mesh) {
  const std::string T = "materials.fabric";
  if (!s.has(T))
    s.fail(T, "mesh.fabric_model = \"membrane\" takes the fabric's E_MPa, nu and density_kg_m3 from [" + T +
                  "]; define it with model = \"linear_elastic\"");
  const std::string law = s.string(T + ".model");
  if (law != "linear_elastic")
    s.fail(T + ".model", "must be \"linear_elastic\" when mesh.fabric_model = \"membrane\" (the membrane is "
                         "plane-stress St Venant-Kirchhoff), got \"" + law + "\"; or use mesh.fabric_model = \"solid\"");
  const MaterialPtr mat = make_material(s, "fabric");  // validates the table like any material
  const auto* scaled = dynamic_cast<const ScaledMaterial*>(mat.get());
  const auto* svk = dynamic_cast<const SaintVenantKirchhoff*>(scaled ? scaled->base().get() : mat.get());
  if (!svk) s.fail(T + ".model", "internal: linear_elastic did not build a St Venant-Kirchhoff law");
  const std::string name = s.string("mesh.fabric_surface");
  const auto* surface = find_surface(mesh, name);
  if (!surface) reject_ambiguous(s, "mesh.fabric_surface", mesh.surfaces, name, "surface");
  if (!surface || surface->second.empty()) {
    std::string have;
    for (const auto& [k, v] : mesh.surfaces) have += (have.empty() ? "" : ", ") + k;
    s.fail("mesh.fabric_surface", "surface '" + name + "' " + (!surface ? "not found" : "has no faces") +
                                      " (the mesh has: " + (have.empty() ? "none" : have) +
                                      "); name the surface that carries the fabric membrane, or use "
                                      "mesh.fabric_model = \"solid\"");
  }
  MembraneSet m;
  m.name = surface->first;
  m.nodes = membrane_nodes_of_faces(mesh, surface->second);
  m.thickness_m = positive(s, "geometry.fabric_thickness_mm") * kmm;
  // Plane-stress SVK is linear in E: materials.fabric.stiffness_scale scales E exactly (the region
  // scales of [regions] apply to solid elements only).
  m.law = PlaneStressSVK((scaled ? scaled->scale() : 1.0) * svk->youngs_modulus(), svk->poisson_ratio());
  m.density_kg_m3 = positive(s, T + ".density_kg_m3");
  return m;
}

// ---- end fabric membrane -------------------------------------------------------------------------

PneuNetParams pneunet_params(const Scene& s) {
  PneuNetParams p;
  p.width = s.number("geometry.width_mm") * kmm;
  p.base_thickness = s.number("geometry.base_thickness_mm") * kmm;
  p.body_height = s.number("geometry.body_height_mm") * kmm;
  p.chambers = s.integer("geometry.chambers");
  p.chamber_length = s.number("geometry.chamber_length_mm") * kmm;
  p.interior_wall = s.number("geometry.interior_wall_mm") * kmm;
  p.side_wall = s.number("geometry.side_wall_mm") * kmm;
  p.roof = s.number("geometry.roof_mm") * kmm;
  p.end_cap = s.number("geometry.end_cap_mm") * kmm;
  p.channel_width = s.number("geometry.channel_width_mm") * kmm;
  p.channel_height = s.number("geometry.channel_height_mm") * kmm;
  p.fabric_z0 = s.number("geometry.fabric_z0_mm") * kmm;
  p.fabric_thickness = s.number("geometry.fabric_thickness_mm") * kmm;
  p.h = s.number("mesh.h_mm") * kmm;
  p.h_z = s.number("mesh.h_z_mm") * kmm;
  if (p.h_z < 0) s.fail("mesh.h_z_mm", "must be >= 0 (0 = same as mesh.h_mm)");
  p.fabric_layers = s.integer("mesh.fabric_layers");
  p.wall_layers = s.integer("mesh.wall_layers");
  if (p.wall_layers < 0) s.fail("mesh.wall_layers", "must be >= 0 (0 = from mesh.h_mm)");
  p.half = s.boolean("mesh.half");
  const std::string el = s.string("mesh.element");
  if (el == "tet10")
    p.element = ElementType::Tet10;
  else if (el == "tet4")
    p.element = ElementType::Tet4;
  else
    s.fail("mesh.element", "must be \"tet10\" or \"tet4\", got \"" + el + "\"");
  p.fabric_model = fabric_is_membrane(s) ? FabricModel::Membrane : FabricModel::Solid;
  return p;
}

double length_unit(const Scene& s) {
  const std::string u = s.string("mesh.length_unit");
  if (u == "mm") return 1e-3;
  if (u == "m") return 1.0;
  s.fail("mesh.length_unit", "must be \"mm\" or \"m\", got \"" + u + "\"");
}

const std::vector<int>& node_set(const Scene& s, const Mesh& m, const std::string& key) {
  std::string name = s.string(key);
  std::string upper = name;
  std::transform(upper.begin(), upper.end(), upper.begin(), ::toupper);
  for (const std::string& n : {name, upper}) {
    auto it = m.node_sets.find(n);
    if (it != m.node_sets.end()) {
      if (it->second.empty()) s.fail(key, "node set '" + name + "' is empty");
      return it->second;
    }
  }
  reject_ambiguous(s, key, m.node_sets, name, "node set");
  std::string avail;
  for (const auto& [k, v] : m.node_sets) avail += (avail.empty() ? "" : ", ") + k;
  s.fail(key, "node set '" + name + "' not found in the mesh; available: " + (avail.empty() ? "(none)" : avail));
}

const std::vector<int>* find_elset(const Mesh& m, const std::string& name) {
  std::string upper = name;
  std::transform(upper.begin(), upper.end(), upper.begin(), ::toupper);
  for (const std::string& n : {name, upper}) {
    auto it = m.element_sets.find(n);
    if (it != m.element_sets.end()) return &it->second;
  }
  return nullptr;
}

/// regions.TAG.stiffness_scale of every [regions.TAG] table (tags absent = 1). The tags are the
/// mesh's region names (engine/mesh.h: interior_wall, roof, side_wall, end_cap, base, fabric for the
/// built-in pneu-net; a deck's come from mesh.regions).
std::map<std::string, double> region_scales(const Scene& s, const Mesh& mesh) {
  std::map<std::string, double> out;
  for (const std::string& tag : s.table_keys("regions")) {
    const std::string T = "regions." + tag;
    if (std::find(mesh.region_names.begin(), mesh.region_names.end(), tag) == mesh.region_names.end()) {
      std::string valid;
      for (const std::string& r : mesh.region_names) valid += (valid.empty() ? "" : ", ") + r;
      s.fail(T, "no region '" + tag + "' in this mesh; valid region tags: " + (valid.empty() ? "(none)" : valid));
    }
    require_keys(s, T, {"stiffness_scale"}, "a region");
    if (!s.has(T + ".stiffness_scale")) continue;
    const double v = s.number(T + ".stiffness_scale");
    if (!(std::isfinite(v) && v > 0.0)) s.fail(T + ".stiffness_scale", "must be > 0 (1 = unchanged; 0.8 = 20 % softer)");
    out[tag] = v;
  }
  return out;
}


}  // namespace

namespace {

const std::set<std::string> kEffects = {"mullins", "fatigue", "viscoelastic"};

// Inelastic effects of a material table: [materials.NAME.mullins], .fatigue, .viscoelastic, each
// with `enabled` and its constants. Applied in the canonical order viscoelastic(fatigue(mullins)).
EffectParams effect_params(const Scene& s, const std::string& T) {
  EffectParams e;
  auto on = [&](const std::string& k) { return s.has(T + "." + k) && s.boolean(T + "." + k + ".enabled"); };
  if (on("mullins")) {
    const std::string K = T + ".mullins";
    require_keys(s, K, {"enabled", "r", "m_MPa", "beta"}, "mullins");
    e.mullins = MullinsParams{s.number(K + ".r"), s.number(K + ".m_MPa") * kMPa, s.number(K + ".beta")};
  }
  if (on("fatigue")) {
    const std::string K = T + ".fatigue";
    require_keys(s, K, {"enabled", "driver", "W_th_MPa", "lambda_th", "tau_s", "q", "n", "d_fail", "nonlocal_radius_mm"},
                 "fatigue");
    FatigueParams f;
    const std::string driver = s.string(K + ".driver");
    if (driver == "energy")
      f.driver = FatigueDriver::energy;
    else if (driver == "max_principal_stretch")
      f.driver = FatigueDriver::max_principal_stretch;
    else
      s.fail(K + ".driver", "must be \"energy\" or \"max_principal_stretch\"");
    f.W_th_Pa = s.number(K + ".W_th_MPa") * kMPa;
    f.lambda_th = s.number(K + ".lambda_th");
    f.tau_s = s.number(K + ".tau_s");
    f.q = s.number(K + ".q");
    f.n = s.number(K + ".n");
    f.d_fail = s.number(K + ".d_fail");
    const double R_mm = s.number(K + ".nonlocal_radius_mm");
    if (!(std::isfinite(R_mm) && R_mm >= 0.0))
      s.fail(K + ".nonlocal_radius_mm", "must be >= 0 mm (0 = local driver; > 0: averaged over this radius)");
    f.nonlocal_radius_m = R_mm * 1e-3;
    e.fatigue = f;
  }
  if (on("viscoelastic")) {
    const std::string K = T + ".viscoelastic";
    require_keys(s, K, {"enabled", "gamma", "tau_s"}, "viscoelastic");
    e.viscoelastic = ViscoParams{s.numbers(K + ".gamma"), s.numbers(K + ".tau_s")};
  }
  return e;
}

}  // namespace

namespace {
MaterialPtr make_base_material(const Scene& s, const std::string& name);

/// materials.NAME.stiffness_scale (absent in a user-defined table = 1).
double material_scale(const Scene& s, const std::string& name) {
  const std::string key = "materials." + name + ".stiffness_scale";
  if (!s.has(key)) return 1.0;
  const double v = s.number(key);
  if (!(std::isfinite(v) && v > 0.0)) s.fail(key, "must be > 0 (1 = the material as given; 0.8 = 20 % softer)");
  return v;
}

/// Keys every material table may have besides its law's constants: the scale and the effects.
std::set<std::string> with_common_keys(std::set<std::string> keys) {
  keys.insert("stiffness_scale");
  for (const MaterialEffect* fx : material_effects()) keys.insert(fx->name);
  return keys;
}

/// One inelastic layer to apply: ascending `order`, ties in registry order (damage/registry.h).
struct Layer {
  int order;
  std::size_t rank;
  std::string key;  ///< scene table, for error messages
  std::function<MaterialPtr(MaterialPtr)> apply;
};

/// The enabled registered (non-built-in) effect `fx` of table T, or nothing. Parameters left out
/// take the registry defaults; unknown keys are rejected naming the valid ones.
std::optional<Layer> registered_layer(const Scene& s, const std::string& T, const MaterialEffect& fx, std::size_t rank) {
  const std::string K = T + "." + fx.name;
  if (!s.has(K) || !s.boolean(K + ".enabled")) return std::nullopt;
  std::set<std::string> allowed{"enabled"};
  std::map<std::string, double> values;
  for (const EffectParameter& p : fx.params) {
    allowed.insert(p.name);
    values[p.name] = s.has(K + "." + p.name) ? s.number(K + "." + p.name) : p.default_value;
  }
  require_keys(s, K, allowed, "effect " + fx.name);
  const MaterialEffect* f = &fx;  // registry entries are never moved
  return Layer{fx.order, rank, K, [f, values](MaterialPtr b) { return f->decorate(std::move(b), values); }};
}
}  // namespace

/// The material of table materials.NAME with its stiffness scale times `region_scale`, wrapped by its
/// enabled effects: effect(...(scaled(base))). The scale sits inside the effects, so energy thresholds
/// (Mullins m, fatigue W_th) are in the scaled energy (materials/scaled.h explains why).
MaterialPtr make_material(const Scene& s, const std::string& name, double region_scale) {
  const std::string T = "materials." + name;
  MaterialPtr m = make_base_material(s, name);
  try {
    m = scale_material(std::move(m), material_scale(s, name) * region_scale);
  } catch (const InputError& err) {
    s.fail(T + ".stiffness_scale", err.what());
  }
  const EffectParams e = effect_params(s, T);
  std::vector<Layer> layers;
  std::size_t rank = 0;
  for (const MaterialEffect* fx : material_effects()) {
    ++rank;
    if (fx->name == "mullins" && e.mullins)
      layers.push_back({fx->order, rank, T, [p = *e.mullins](MaterialPtr b) { return make_mullins(std::move(b), p); }});
    else if (fx->name == "fatigue" && e.fatigue)
      layers.push_back({fx->order, rank, T, [p = *e.fatigue](MaterialPtr b) { return make_fatigue(std::move(b), p); }});
    else if (fx->name == "viscoelastic" && e.viscoelastic)
      layers.push_back({fx->order, rank, T, [p = *e.viscoelastic](MaterialPtr b) { return make_viscoelastic(std::move(b), p); }});
    else if (!is_builtin_effect(fx->name))
      if (auto l = registered_layer(s, T, *fx, rank)) layers.push_back(std::move(*l));
  }
  std::stable_sort(layers.begin(), layers.end(),
                   [](const Layer& a, const Layer& b) { return a.order != b.order ? a.order < b.order : a.rank < b.rank; });
  for (const Layer& l : layers) {
    try {
      m = l.apply(std::move(m));
    } catch (const InputError& err) {
      s.fail(l.key, err.what());
    }
  }
  // A non-local fatigue driver reaches the engine through every layer around it (each forwards
  // Material::nonlocal); an effect registered in C++ that does not would silently make it local.
  if (e.fatigue && e.fatigue->nonlocal_radius_m > 0.0 && !(m->nonlocal().radius_m > 0.0))
    s.fail(T + ".fatigue.nonlocal_radius_mm",
           "an effect wrapped around fatigue ('" + m->name() + "') does not forward the non-local driver "
           "(Material::nonlocal, nonlocal_driver, set_nonlocal_driver to its base; docs/adding_an_effect.md); "
           "set nonlocal_radius_mm = 0.0 or forward them");
  return m;
}

MaterialPtr make_material(const Scene& s, const std::string& name) { return make_material(s, name, 1.0); }

namespace {
MaterialPtr make_base_material(const Scene& s, const std::string& name) {
  const std::string T = "materials." + name;
  if (!s.has(T)) s.fail(T, "no such material; define a [" + T + "] table");
  const std::string model = s.string(T + ".model");
  static const std::set<std::string> kModels = {"linear_elastic", "yeoh", "neo_hookean", "mooney_rivlin", "ogden"};
  if (!kModels.count(model))
    s.fail(T + ".model", "unknown material model \"" + model +
                             "\"; use yeoh, neo_hookean, mooney_rivlin, ogden or linear_elastic");
  positive(s, T + ".density_kg_m3");
  try {
    if (model == "linear_elastic") {
      require_keys(s, T, with_common_keys({"model", "E_MPa", "nu", "density_kg_m3"}), "model linear_elastic");
      return std::make_shared<SaintVenantKirchhoff>(s.number(T + ".E_MPa") * kMPa, s.number(T + ".nu"));
    }
    const double Kr = s.number(T + ".K_over_mu");
    if (model == "yeoh") {
      require_keys(s, T, with_common_keys({"model", "C10_MPa", "C20_MPa", "C30_MPa", "K_over_mu", "density_kg_m3"}), "model yeoh");
      const double C10 = s.number(T + ".C10_MPa") * kMPa;
      const double C20 = s.has(T + ".C20_MPa") ? s.number(T + ".C20_MPa") * kMPa : 0.0;
      const double C30 = s.has(T + ".C30_MPa") ? s.number(T + ".C30_MPa") * kMPa : 0.0;
      return std::make_shared<InvariantMaterial<Yeoh>>(Yeoh(C10, C20, C30, bulk_from_ratio(2 * C10, Kr)));
    }
    if (model == "neo_hookean") {
      require_keys(s, T, with_common_keys({"model", "C10_MPa", "K_over_mu", "density_kg_m3"}), "model neo_hookean");
      const double C10 = s.number(T + ".C10_MPa") * kMPa;
      return std::make_shared<InvariantMaterial<NeoHookean>>(NeoHookean(C10, bulk_from_ratio(2 * C10, Kr)));
    }
    if (model == "mooney_rivlin") {
      require_keys(s, T, with_common_keys({"model", "C10_MPa", "C01_MPa", "K_over_mu", "density_kg_m3"}), "model mooney_rivlin");
      const double C10 = s.number(T + ".C10_MPa") * kMPa, C01 = s.number(T + ".C01_MPa") * kMPa;
      return std::make_shared<InvariantMaterial<MooneyRivlin>>(
          MooneyRivlin(C10, C01, bulk_from_ratio(2 * (C10 + C01), Kr)));
    }
    if (model == "ogden") {
      require_keys(s, T, with_common_keys({"model", "mu_MPa", "alpha", "K_over_mu", "density_kg_m3"}), "model ogden");
      std::vector<double> mu = s.numbers(T + ".mu_MPa");
      const std::vector<double> alpha = s.numbers(T + ".alpha");
      double mu0 = 0.0;
      for (double& m : mu) {
        m *= kMPa;
        mu0 += m;
      }
      return std::make_shared<Ogden>(mu, alpha, bulk_from_ratio(mu0, Kr));
    }
  } catch (const InputError& e) {
    s.fail(T, e.what());
  }
  s.fail(T + ".model", "unknown material model \"" + model +
                           "\"; use yeoh, neo_hookean, mooney_rivlin, ogden or linear_elastic");
}

/// Vector text for messages, e.g. "[0.0, -1.0, 0.0]" (rounded to 3 decimals: a hint, not data).
std::string vec_text(const Eigen::Vector3d& v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "[%.3f, %.3f, %.3f]", v.x() + 0.0, v.y() + 0.0, v.z() + 0.0);
  return buf;
}

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

/// The free end face of a deck: the node set mesh.tip_set; when the scene leaves that key at its
/// default and the deck has no such set, the boundary nodes farthest from the clamp, with a note. The
/// clamp's side is the outward normal of the clamped nodes' plane face (all three dofs fixed); the tip
/// face is then the set of boundary nodes within 0.1 % of the body's length of the farthest one along
/// the opposite direction, which must hold at least three nodes that are not on one line (a flat end
/// face; a rounded end gives its cap, whose fitted plane still turns with the tip).
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

/// gravity.rig_angle_deg >= 0: the rig's orientation relative to the actuator, in its angle frame
/// (so a deck in any orientation, whose frame may come from the mesh, hangs the same way):
/// g = 9.81 (cos(phi) a + sin(phi) d), a = -angle.fixed_normal (along the actuator, away from the
/// clamp), d = the bend direction made perpendicular to a. For the built-in frame a = +y, d = -z, so
/// g = [0, 9.81 cos(phi), -9.81 sin(phi)] to the bit (components below 1e-12 g are exactly 0).
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

}  // namespace

Mesh build_mesh(const Scene& s, std::vector<std::string>* warnings) {
  const std::string source = s.string("mesh.source");
  if (source == "pneunet") {
    PneuNetParams p = pneunet_params(s);
    p.validate();
    return build_pneunet(p);
  }
  if (source != "inp") s.fail("mesh.source", "must be \"pneunet\" or \"inp\", got \"" + source + "\"");
  const std::string file = s.string("mesh.file");
  if (file.empty()) s.fail("mesh.file", "mesh.source = \"inp\" needs the deck's path in mesh.file");
  InpDeck deck = read_inp(s.resolve_path(file), length_unit(s));
  if (warnings) warnings->insert(warnings->end(), deck.warnings.begin(), deck.warnings.end());
  Mesh mesh = std::move(deck.mesh);
  if (s.boolean("mesh.promote_to_tet10")) mesh = promote_to_tet10(mesh);
  return mesh;
}

LoadHistory inlet_load(const Scene& s) {
  LoadHistory load;
  const std::string protocol = s.string("load.protocol");
  if (protocol == "staircase") {
    load = staircase(s.number("load.max_kPa") * kkPa, s.number("load.step_kPa") * kkPa, s.number("load.hold_s"),
                     s.number("load.ramp_s"), s.integer("load.trials"), s.number("load.mark_s"), s.number("load.rest_s"),
                     s.number("load.output_every_s"));
  } else if (protocol == "csv") {
    const std::string csv = s.string("load.csv");
    if (csv.empty()) s.fail("load.csv", "protocol = \"csv\" needs the pressure file in load.csv");
    load = pressure_history_from_csv(s.resolve_path(csv), 0.25, s.number("load.output_every_s"));
    if (s.number("load.rest_s") > 0) load.rest_between_trials_s = s.number("load.rest_s");
  } else {
    s.fail("load.protocol", "must be \"staircase\" or \"csv\", got \"" + protocol + "\"");
  }
  return load;
}

std::unique_ptr<BuiltModel> build_model(const Scene& s) {
  auto out = std::make_unique<BuiltModel>();
  Model& model = out->model;
  const std::string source = s.string("mesh.source");
  InpDeck deck;
  if (source == "pneunet") {
    PneuNetParams p = pneunet_params(s);
    p.validate();
    model.mesh = build_pneunet(p);
  } else if (source == "inp") {
    const std::string file = s.string("mesh.file");
    if (file.empty()) s.fail("mesh.file", "mesh.source = \"inp\" needs the deck's path in mesh.file");
    deck = read_inp(s.resolve_path(file), length_unit(s));
    out->warnings = deck.warnings;
    if (deck.solid_instances.size() > 1)
      s.fail("mesh.file", "the deck's solid elements are in " + std::to_string(deck.solid_instances.size()) +
                              " instances (" + inp::join_names(deck.solid_instances) +
                              ") that share no node, so the model is not connected (ties are not applied); "
                              "pneufem needs one conforming mesh: merge the instances in Abaqus (Merge/Cut "
                              "Instances) so the mesh is conforming");
    if (s.boolean("mesh.promote_to_tet10")) {
      if (deck.mesh.type == ElementType::Tet4 && !deck.pressure_faces.empty())
        out->warnings.push_back("mesh.promote_to_tet10: *DLOAD faces are kept (faces map one to one)");
      promote_deck_to_tet10(deck);  // also the *BOUNDARY dofs of the new mid-edge nodes
    }
    model.mesh = std::move(deck.mesh);
  } else {
    s.fail("mesh.source", "must be \"pneunet\" or \"inp\", got \"" + source + "\"");
  }
  Mesh& mesh = model.mesh;
  mesh.ensure_ids();
  const bool membrane_fabric = fabric_is_membrane(s);

  // Regions from element sets (decks): mesh.regions = { ELSET = "region" }.
  for (const std::string& elset : s.table_keys("mesh.regions")) {
    const std::vector<int>* els = find_elset(mesh, elset);
    if (!els) {
      reject_ambiguous(s, "mesh.regions." + elset, mesh.element_sets, elset, "element set");
      s.fail("mesh.regions." + elset, "element set '" + elset + "' not found in the mesh");
    }
    const std::uint16_t r = mesh.region_id(s.string_entry("mesh.regions", elset));
    for (int e : *els) mesh.region[e] = r;
  }

  // Parts: element set -> material.
  const int nparts = s.array_size("parts");
  if (nparts == 0) s.fail("parts", "define at least one [[parts]] with elset and material");
  model.element_part.assign(mesh.num_elements(), -1);
  const std::map<std::string, double> region_scale = region_scales(s, mesh);
  for (int i = 0; i < nparts; ++i) {
    const std::string key = "parts[" + std::to_string(i) + "]";
    const std::string elset = s.string(key + ".elset"), mat = s.string(key + ".material");
    const std::vector<int>* els = find_elset(mesh, elset);
    if (!els) {
      reject_ambiguous(s, key + ".elset", mesh.element_sets, elset, "element set");
      std::string avail;
      for (const auto& [k, v] : mesh.element_sets) avail += (avail.empty() ? "" : ", ") + k;
      s.fail(key + ".elset", "element set '" + elset + "' not found in the mesh; available: " + avail);
    }
    if (membrane_fabric && els->empty()) continue;  // FABRIC is empty: the fabric is the membrane
    const double density = s.number("materials." + mat + ".density_kg_m3");
    model.parts.push_back(Part{elset, make_material(s, mat), density});
    const int part = static_cast<int>(model.parts.size()) - 1;
    // Elements of a region with a stiffness scale != 1 get their own part "ELSET@region" (same
    // material, scaled); each part's material sets its own state layout, so assembly is unchanged.
    std::map<std::uint16_t, int> region_part;
    for (int e : *els) {
      if (model.element_part[e] >= 0)
        s.fail(key + ".elset", mesh.element_label(e) + " is in two parts ('" +
                                   model.parts[model.element_part[e]].name + "' and '" + elset + "')");
      int p = part;
      if (static_cast<std::size_t>(e) < mesh.region.size()) {
        const std::string& tag = mesh.region_names[mesh.region[e]];
        const auto sc = region_scale.find(tag);
        if (sc != region_scale.end() && sc->second != 1.0) {
          auto [it, fresh] = region_part.try_emplace(mesh.region[e], -1);
          if (fresh) {
            model.parts.push_back(Part{elset + "@" + tag, make_material(s, mat, sc->second), density});
            it->second = static_cast<int>(model.parts.size()) - 1;
          }
          p = it->second;
        }
      }
      model.element_part[e] = p;
    }
  }
  for (int e = 0; e < mesh.num_elements(); ++e)
    if (model.element_part[e] < 0)
      s.fail("parts", mesh.element_label(e) + " belongs to no part; add its element set to a [[parts]] entry");

  // Boundary conditions.
  model.fixed.assign(3 * mesh.num_nodes(), 0);
  const bool is_inp = source == "inp";
  const std::string fixed_key = "mesh.fixed_set";
  if (!is_inp || !s.string(fixed_key).empty() || deck.fixed_dofs.empty())
    for (int n : node_set(s, mesh, fixed_key))
      for (int d = 0; d < 3; ++d) model.fixed[3 * n + d] = 1;
  if (is_inp && s.boolean("mesh.use_deck_boundary"))
    for (const auto& [n, d] : deck.fixed_dofs) model.fixed[3 * n + d] = 1;
  const bool half = is_inp ? !s.string("mesh.symmetry_set").empty() : s.boolean("mesh.half");
  if (half) {
    const std::vector<int>& sym = is_inp ? node_set(s, mesh, "mesh.symmetry_set") : mesh.node_sets.at("SYMMETRY");
    const double L = (compute_stats(mesh).bbox_max - compute_stats(mesh).bbox_min).norm();
    for (int n : sym) {
      if (std::abs(mesh.X[n].x()) > 1e-6 * L)
        s.fail("mesh.symmetry_set", "node " + mesh.node_name(n) +
                                        " is not on the plane x = 0; the symmetry plane must be x = 0");
      model.fixed[3 * n] = 1;
    }
    model.angle.mirror_axis = 0;
  }

  // Cavity faces.
  const std::string cav = is_inp ? s.string("mesh.cavity_surface") : "CAVITY";
  if (is_inp && (cav == "DLOAD" || cav == "dload")) {
    if (deck.pressure_faces.empty())
      s.fail("mesh.cavity_surface", "\"DLOAD\" was given but the deck has no *DLOAD ... Pn or *DSLOAD ..., P lines");
    for (const auto& pf : deck.pressure_faces) model.pressure_faces.push_back(pf.face);
  } else {
    const auto* surface = find_surface(mesh, cav);
    if (!surface) reject_ambiguous(s, "mesh.cavity_surface", mesh.surfaces, cav, "surface");
    if (surface) {
      model.pressure_faces = surface->second;
    } else if (is_inp && s.origin("mesh.cavity_surface") == "default scene" && !deck.pressure_faces.empty()) {
      // No surface of the default name: the deck's own pressure load marks the chambers.
      for (const auto& pf : deck.pressure_faces) model.pressure_faces.push_back(pf.face);
      out->warnings.push_back("mesh.cavity_surface: the deck has no surface '" + cav + "'; the faces of its pressure load (" +
                              std::to_string(deck.pressure_faces.size()) + " *DLOAD/*DSLOAD P faces) are the cavity; name a " +
                              "surface in mesh.cavity_surface to choose another");
    } else {
      s.fail("mesh.cavity_surface", "surface '" + cav + "' not found; name a *SURFACE of the deck or use \"DLOAD\"");
    }
  }
  if (model.pressure_faces.empty()) s.fail("mesh.cavity_surface", "the cavity surface has no faces");
  {
    // A deck's surface may be an embedded sheet (a fabric membrane's faces, shared by two
    // tetrahedra): pressure there would push on the solid from inside, so a cavity must not.
    std::set<std::pair<int, int>> outside;
    for (const FaceRef& f : boundary_faces(mesh)) outside.emplace(f.element, f.local_face);
    for (const FaceRef& f : model.pressure_faces)
      if (!outside.count({f.element, f.local_face}))
        s.fail("mesh.cavity_surface", "'" + cav + "' has a face inside the solid (face " + std::to_string(f.local_face + 1) +
                                          " of " + mesh.element_label(f.element) +
                                          ", shared by two tetrahedra): the cavity must be the chambers' boundary; "
                                          "name the surface of the chamber walls");
  }

  // Bending angle.
  model.angle.tip_nodes = is_inp ? deck_tip_nodes(s, model, out->warnings) : node_set(s, mesh, "mesh.tip_set");
  model.angle.fixed_normal_out = s.vec3("angle.fixed_normal");
  model.angle.bend_direction = s.vec3("angle.bend_direction");
  if (model.angle.fixed_normal_out.norm() < 1e-12) s.fail("angle.fixed_normal", "must be a nonzero vector");
  model.gravity_m_s2 = s.vec3("gravity.g_m_s2");
  if (membrane_fabric) model.membranes.push_back(fabric_membrane(s, mesh));
  validate(model);
  resolve_angle_frame(s, model, is_inp, out->warnings);
  if (model.angle.bend_direction.cross(model.angle.fixed_normal_out).norm() < 1e-9 * model.angle.bend_direction.norm())
    s.fail("angle.bend_direction", "must not be parallel to angle.fixed_normal");
  set_rig_gravity(s, model);
  out->stats = compute_stats(mesh);

  // Load.
  out->load = inlet_load(s);
  // Chamber pressure lagging the inlet (scenes/pressure_lag.h). Breakpoint tolerance: 0.5 % of a
  // staircase step (far below the 5 kPa steps' effect on the angle, ~0.1 deg); for a CSV inlet
  // 0.05 kPa, a fifth of the simplification tolerance the CSV itself is read with.
  const double lag_s = s.number("load.pressure_lag_s");
  if (!(std::isfinite(lag_s) && lag_s >= 0.0))
    s.fail("load.pressure_lag_s", "must be >= 0 s (0 = the chamber follows the inlet instantly)");
  if (lag_s > 0.0)
    out->load = apply_pressure_lag(out->load, lag_s,
                                   s.string("load.protocol") == "staircase" ? 0.005 * s.number("load.step_kPa") * kkPa : 0.05 * kkPa);

  // Solver.
  SolverSettings& sv = out->solver;
  sv.mode = choice<SolverSettings::Mode>(s, "solver.mode", {{"quasi_static", SolverSettings::Mode::QuasiStatic},
                                                           {"explicit", SolverSettings::Mode::Explicit}});
  sv.quasi_static.method = choice<EquilibriumMethod>(s, "solver.method", {{"newton", EquilibriumMethod::Newton},
                                                                          {"relaxation", EquilibriumMethod::Relaxation}});
  sv.quasi_static.newton.rel_tol = positive(s, "solver.rel_tol");
  sv.quasi_static.relaxation.rel_tol = sv.quasi_static.newton.rel_tol;
  sv.quasi_static.newton.max_iterations = s.integer("solver.max_iterations");
  if (sv.quasi_static.newton.max_iterations < 1) s.fail("solver.max_iterations", "must be >= 1");
  sv.quasi_static.newton.stiff_relaxation_steps = s.integer("solver.stiff_relaxation_steps");
  if (sv.quasi_static.newton.stiff_relaxation_steps < 0) s.fail("solver.stiff_relaxation_steps", "must be >= 0 (0 = off)");
  sv.quasi_static.newton.indefinite = choice<StaticOptions::Indefinite>(
      s, "solver.indefinite_tangent",
      {{"last_factor", StaticOptions::Indefinite::LastFactor}, {"shift", StaticOptions::Indefinite::Shift}});
  sv.quasi_static.newton.energy_line_search = choice<bool>(s, "solver.line_search", {{"energy", true}, {"slope", false}});
  sv.quasi_static.newton.max_increment_Pa = positive(s, "solver.max_increment_kPa") * kkPa;
  sv.quasi_static.newton.min_increment_Pa = positive(s, "solver.min_increment_kPa") * kkPa;
  sv.quasi_static.relaxation.max_iterations = s.integer("solver.relaxation_max_iterations");
  sv.quasi_static.newton.verbose = s.boolean("solver.verbose");
  sv.quasi_static.time_tol = positive(s, "solver.time_tol");
  sv.quasi_static.time_control =
      choice<TimeControl>(s, "solver.time_control", {{"change", TimeControl::Change}, {"error", TimeControl::Error}});
  sv.quasi_static.min_dt_s = positive(s, "solver.min_dt_s");
  sv.quasi_static.max_dt_s = positive(s, "solver.max_dt_s");
  if (sv.quasi_static.max_dt_s < sv.quasi_static.min_dt_s) s.fail("solver.max_dt_s", "must be >= solver.min_dt_s");
  sv.quasi_static.max_segment_steps = s.integer("solver.max_segment_steps");
  if (sv.quasi_static.max_segment_steps < 1) s.fail("solver.max_segment_steps", "must be >= 1");
  sv.quasi_static.newton.krylov_max_iterations = s.integer("solver.krylov_max_iterations");
  if (sv.quasi_static.newton.krylov_max_iterations < 0) s.fail("solver.krylov_max_iterations", "must be >= 0");
  sv.explicit_dynamics.dt_safety = positive(s, "solver.dt_safety");
  if (sv.explicit_dynamics.dt_safety > 1.0) s.fail("solver.dt_safety", "must be <= 1 (fraction of the stable step)");
  sv.explicit_dynamics.target_dt_s = s.number("solver.target_dt_s");
  sv.explicit_dynamics.damping_alpha_1_s = s.number("solver.damping_1_s");
  if (sv.explicit_dynamics.damping_alpha_1_s < 0) s.fail("solver.damping_1_s", "must be >= 0");
  sv.explicit_dynamics.adaptive_damping = s.boolean("solver.adaptive_damping");
  sv.time_scale = positive(s, "solver.time_scale");

  out->output.vtu = s.string("output.vtu");
  if (out->output.vtu != "steps" && out->output.vtu != "all" && out->output.vtu != "none")
    s.fail("output.vtu", "must be \"steps\", \"all\" or \"none\"");
  return out;
}

LoadHistory pressure_history_from_csv(const std::string& path, double tol_kPa, double output_every_s) {
  std::ifstream in(path);
  if (!in) throw InputError("cannot open pressure file '" + path + "'");
  std::string line;
  if (!std::getline(in, line)) throw InputError(path + ":1: empty file; expected a header trial,time_s,pressure_kPa");
  std::vector<std::string> cols;
  {
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) {
      c.erase(std::remove_if(c.begin(), c.end(), ::isspace), c.end());
      cols.push_back(c);
    }
  }
  auto col = [&](const std::string& n) {
    auto it = std::find(cols.begin(), cols.end(), n);
    if (it == cols.end()) throw InputError(path + ":1: missing column '" + n + "'; header must contain trial,time_s,pressure_kPa");
    return static_cast<std::size_t>(it - cols.begin());
  };
  const std::size_t ct = col("trial"), cs = col("time_s"), cp = col("pressure_kPa");
  std::map<int, std::pair<std::vector<double>, std::vector<double>>> data;
  long lineno = 1;
  while (std::getline(in, line)) {
    ++lineno;
    if (line.empty()) continue;
    std::vector<std::string> f;
    std::stringstream ss(line);
    for (std::string c; std::getline(ss, c, ',');) f.push_back(c);
    while (f.size() < cols.size()) f.emplace_back();
    if (f[cp].find_first_not_of(" \t\r") == std::string::npos) continue;  // angle-only row
    try {
      std::size_t used = 0;
      const int trial = std::stoi(f[ct]);
      const double t = std::stod(f[cs], &used);
      const double p = std::stod(f[cp]);
      auto& [ts, ps] = data[trial];
      if (!ts.empty() && t <= ts.back())
        throw InputError(path + ":" + std::to_string(lineno) + ": time_s must increase within a trial");
      ts.push_back(t);
      ps.push_back(p);
    } catch (const InputError&) {
      throw;
    } catch (const std::exception&) {
      throw InputError(path + ":" + std::to_string(lineno) + ": could not read numbers in '" + line + "'");
    }
  }
  if (data.empty()) throw InputError(path + ": no pressure samples found");
  LoadHistory h;
  for (auto& [trial, tp] : data) {
    auto& [ts, ps] = tp;
    const std::vector<char> keep = rdp_keep(ts, ps, tol_kPa);
    TrialLoad tl;
    const double t0 = ts.front();
    for (std::size_t i = 0; i < ts.size(); ++i)
      if (keep[i]) {
        tl.time_s.push_back(ts[i] - t0);
        tl.pressure_Pa.push_back(ps[i] * kkPa);
      }
    tl.output_s = tl.time_s;
    if (output_every_s > 0)
      for (double t = output_every_s; t < tl.duration(); t += output_every_s) tl.output_s.push_back(t);
    std::sort(tl.output_s.begin(), tl.output_s.end());
    h.trials.push_back(std::move(tl));
  }
  h.description = "pressure from " + path;
  return h;
}

}  // namespace pneufem
