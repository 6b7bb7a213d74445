// Scene -> model (scenes/build_model.h): the mesh (built-in pneu-net or a deck), its regions and
// parts, boundary conditions, cavity faces, fabric membrane and bending-angle keys, the load
// history and the solver settings. Materials are built in scene_materials.cpp, a deck's angle frame
// and the rig's gravity in angle_frame.cpp.
#include "scenes/build_model.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <initializer_list>
#include <limits>
#include <map>
#include <set>
#include <sstream>

#include "core/errors.h"
#include "core/number_text.h"
#include "materials/hyperelastic.h"
#include "materials/scaled.h"
#include "scenes/angle_frame.h"
#include "scenes/inp/assembly.h"
#include "scenes/inp/deck.h"
#include "scenes/inp/solid_split.h"
#include "scenes/pneunet.h"
#include "scenes/pressure_lag.h"
#include "scenes/scene_keys.h"
#include "scenes/stl_scene.h"

namespace pneufem {

namespace {

using detail::choice;
using detail::deck_tip_nodes;
using detail::kkPa;
using detail::kmm;
using detail::node_set;
using detail::positive;
using detail::reject_ambiguous;
using detail::require_keys;
using detail::resolve_angle_frame;
using detail::set_rig_gravity;

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

/// The membrane fabric: the faces of surface mesh.fabric_surface (the mesher's FABRIC_MEMBRANE on
/// the layer's mid-plane, or a deck's surface: an embedded sheet of M3D3/M3D6/M3D4/M3D8 elements, a
/// *SURFACE), thickness geometry.fabric_thickness_mm (for mesh.source = "stl" that of
/// mesh.fabric_slab_mm), plane-stress St Venant-Kirchhoff with E and
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
  if (s.string("mesh.source") == "stl") {  // the layer is the slab of the surface's mesh
    const std::vector<double> slab = s.numbers("mesh.fabric_slab_mm");
    if (slab.size() == 2) m.thickness_m = (slab[1] - slab[0]) * kmm;
  }
  // Plane-stress SVK is linear in E: materials.fabric.stiffness_scale scales E exactly (the region
  // scales of [regions] apply to solid elements only).
  m.law = PlaneStressSVK((scaled ? scaled->scale() : 1.0) * svk->youngs_modulus(), svk->poisson_ratio());
  m.density_kg_m3 = positive(s, T + ".density_kg_m3");
  return m;
}

// ---- end fabric membrane -------------------------------------------------------------------------

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

/// The built-in pneu-net of the scene's [geometry] and [mesh] keys.
Mesh built_in_mesh(const Scene& s) {
  PneuNetParams p = pneunet_settings(s);
  p.validate();
  return build_pneunet(p);
}

/// The deck of mesh.file (mesh.source = "inp"), as read.
InpDeck scene_deck(const Scene& s) {
  const std::string file = s.string("mesh.file");
  if (file.empty()) s.fail("mesh.file", "mesh.source = \"inp\" needs the deck's path in mesh.file");
  return read_inp(s.resolve_path(file), mesh_settings(s).length_unit_m);
}

/// The mesh of mesh.source (`source`): the built-in pneu-net, or a deck, which is kept in `deck`
/// (its *BOUNDARY dofs and pressure faces are read later) with its notes in `warnings`. Unlike
/// build_mesh, a deck of several unconnected instances is refused, and a promotion to Tet10 carries
/// the deck's *BOUNDARY dofs to the new mid-edge nodes.
Mesh read_model_mesh(const Scene& s, MeshSettings::Source source, InpDeck& deck, std::vector<std::string>& warnings) {
  if (source == MeshSettings::Source::PneuNet) return built_in_mesh(s);
  if (source == MeshSettings::Source::Stl) return stl_scene_mesh(s, &warnings);
  deck = scene_deck(s);
  warnings = deck.warnings;
  if (deck.solid_instances.size() > 1)
    s.fail("mesh.file", "the deck's solid elements are in " + std::to_string(deck.solid_instances.size()) +
                            " instances (" + inp::join_names(deck.solid_instances) +
                            ") that share no node, so the model is not connected (ties are not applied); "
                            "pneufem needs one conforming mesh: merge the instances in Abaqus (Merge/Cut "
                            "Instances) so the mesh is conforming");
  if (s.boolean("mesh.promote_to_tet10")) {
    if (deck.mesh.type == ElementType::Tet4 && !deck.pressure_faces.empty())
      warnings.push_back("mesh.promote_to_tet10: *DLOAD faces are kept (faces map one to one)");
    promote_deck_to_tet10(deck);  // also the *BOUNDARY dofs of the new mid-edge nodes
  }
  return std::move(deck.mesh);
}

/// "MODULI=LONG TERM" / "MODULI=INSTANTANEOUS" of a deck's *MATERIAL (for messages).
std::string to_words(const InpModuli& d) {
  return std::string("MODULI=") + (d.value == "long_term" ? "LONG TERM" : "INSTANTANEOUS") +
         (d.material.empty() ? std::string() : " of *MATERIAL " + d.material);
}

/// The deck's MODULI= (Abaqus: whether the hyperelastic constants are the instantaneous or the
/// long-term response of a viscoelastic material; InpDeck::moduli) as materials.M.viscoelastic.moduli
/// of every material M whose viscoelastic table is enabled and leaves `moduli` to the default scene:
/// the value of the deck's *MATERIAL of the same name (case-insensitive), else the one value all
/// the deck's MODULI= agree on. A scene that sets the key itself keeps it, with a note when the deck
/// says otherwise; MODULI= values that differ, none for a material of this name: an error naming the
/// lines. Each value taken is noted in `warnings`.
Scene with_deck_moduli(const Scene& s, const InpDeck& deck, std::vector<std::string>& warnings) {
  if (deck.moduli.empty()) return s;
  std::vector<std::string> sets;
  for (const std::string& m : s.table_keys("materials")) {
    const std::string K = "materials." + m + ".viscoelastic";
    std::string m_upper = m;  // deck names are stored upper-cased
    std::transform(m_upper.begin(), m_upper.end(), m_upper.begin(), [](unsigned char c) { return std::toupper(c); });
    if (!s.has(K + ".enabled") || !s.boolean(K + ".enabled")) continue;
    const InpModuli* from = nullptr;
    for (const InpModuli& d : deck.moduli)
      if (d.material == m_upper) from = &d;  // the last one, as a repeated keyword overrides
    if (!from) {
      from = &deck.moduli.front();
      for (const InpModuli& d : deck.moduli)
        if (d.value != from->value)
          s.fail(K + ".moduli", "the deck's MODULI= differ (" + to_words(*from) + " at " + from->where + ", " +
                                    to_words(d) + " at " + d.where + ") and none belongs to a *MATERIAL named '" + m +
                                    "'; set moduli = \"instantaneous\" or \"long_term\" here");
    }
    const std::string key = K + ".moduli";
    const bool set_by_scene = s.has(key) && s.origin(key) != "default scene";
    if (set_by_scene) {
      if (s.string(key) != from->value)
        warnings.push_back(key + " = \"" + s.string(key) + "\" (" + s.origin(key) + ") is kept over the deck's " +
                           to_words(*from) + " (" + from->where + ")");
      continue;
    }
    sets.push_back(key + "=" + from->value);
    warnings.push_back(key + " = \"" + from->value + "\" from the deck's " + to_words(*from) + " (" + from->where + ")");
  }
  return s.with(sets);
}

/// [[mesh.region_boxes]]: the elements whose centroid (the mean of their corner nodes, reference
/// configuration) lies in a box take its region tag, box after box. A box must hold at least one
/// centroid: an empty one is a typo in its coordinates or units, and is named with the mesh's extent.
void apply_region_boxes(const Scene& s, Mesh& mesh) {
  const int nboxes = s.array_size("mesh.region_boxes");
  if (nboxes == 0) return;
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (const Eigen::Vector3d& x : mesh.X) lo = lo.cwiseMin(x), hi = hi.cwiseMax(x);
  constexpr int corners = 4;  // Tet4 and Tet10 list their corner nodes first
  std::vector<Eigen::Vector3d> centroid(static_cast<std::size_t>(mesh.num_elements()), Eigen::Vector3d::Zero());
  for (int e = 0; e < mesh.num_elements(); ++e) {
    for (int a = 0; a < corners; ++a) centroid[static_cast<std::size_t>(e)] += mesh.X[static_cast<std::size_t>(mesh.element(e)[a])];
    centroid[static_cast<std::size_t>(e)] /= corners;
  }
  auto mm = [](const Eigen::Vector3d& x) {
    std::ostringstream os;
    os << '[' << short_num(1e3 * x.x()) << ", " << short_num(1e3 * x.y()) << ", " << short_num(1e3 * x.z()) << ']';
    return os.str();
  };
  for (int i = 0; i < nboxes; ++i) {
    const std::string key = "mesh.region_boxes[" + std::to_string(i) + "]";
    const std::string tag = s.string(key + ".region");
    if (tag.empty()) s.fail(key + ".region", "must name a region tag, e.g. \"interior_wall\"");
    const Eigen::Vector3d bmin = 1e-3 * s.vec3(key + ".min_mm"), bmax = 1e-3 * s.vec3(key + ".max_mm");
    if (!(bmin.array() < bmax.array()).all())
      s.fail(key + ".max_mm", "must be above min_mm along x, y and z (min " + mm(bmin) + ", max " + mm(bmax) + " mm)");
    std::vector<int> inside;
    for (int e = 0; e < mesh.num_elements(); ++e) {
      const Eigen::Vector3d& c = centroid[static_cast<std::size_t>(e)];
      if ((c.array() >= bmin.array()).all() && (c.array() <= bmax.array()).all()) inside.push_back(e);
    }
    if (inside.empty())
      s.fail(key, "the box " + mm(bmin) + " to " + mm(bmax) + " mm holds no element's centroid; the mesh spans " + mm(lo) +
                      " to " + mm(hi) + " mm");
    const std::uint16_t r = mesh.region_id(tag);
    for (int e : inside) mesh.region[static_cast<std::size_t>(e)] = r;
  }
}

/// mesh.regions (element sets of a deck as regions), then mesh.region_boxes, then the [[parts]]: every element gets one part,
/// the elements of a region with a stiffness scale a part of their own. With a membrane fabric an
/// empty element set (FABRIC) makes no part.
void assign_parts(const Scene& s, Model& model, bool membrane_fabric) {
  Mesh& mesh = model.mesh;
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

  apply_region_boxes(s, mesh);

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
    // The material first: it names what is wrong with its table (an unknown model, a missing
    // constant) before the density is read from it.
    MaterialPtr material = make_material(s, mat);
    const double density = positive(s, "materials." + mat + ".density_kg_m3");
    model.parts.push_back(Part{elset, std::move(material), density});
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
}

/// The pressure faces: surface mesh.cavity_surface (for a deck also "DLOAD", its own pressure load,
/// which a deck without the default surface takes with a note), all on the boundary of the solid.
void set_cavity_faces(const Scene& s, Model& model, const InpDeck& deck, bool is_inp, std::vector<std::string>& warnings) {
  const Mesh& mesh = model.mesh;
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
      warnings.push_back("mesh.cavity_surface: the deck has no surface '" + cav + "'; the faces of its pressure load (" +
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
}

}  // namespace

Scene elastic_reference_scene(const Scene& scene) {
  std::vector<std::string> sets;
  for (const std::string& m : scene.table_keys("materials"))
    for (const std::string& sub : scene.table_keys("materials." + m))
      if (scene.has("materials." + m + "." + sub + ".enabled")) sets.push_back("materials." + m + "." + sub + ".enabled=false");
  sets.push_back("gravity.g_m_s2=[0.0, 0.0, 0.0]");
  sets.push_back("gravity.rig_angle_deg=-1.0");
  if (scene.has("load.pressure_lag_s")) sets.push_back("load.pressure_lag_s=0.0");
  if (scene.has("load.pressure_lag2_s")) sets.push_back("load.pressure_lag2_s=0.0");
  return scene.with(sets);
}

LoadHistory chamber_load(const Scene& s) {
  LoadHistory load = inlet_load(s);
  // Chamber pressure lagging the inlet (scenes/pressure_lag.h). Breakpoint tolerance: 0.5 % of a
  // staircase step (far below the 5 kPa steps' effect on the angle, ~0.1 deg); for a CSV inlet
  // 0.05 kPa, a fifth of the simplification tolerance the CSV itself is read with.
  // First order, or second (load.pressure_lag2_s > 0) with the same tolerance.
  const PressureLag lag = scene_pressure_lag(s);
  if (lag.on()) {
    const LoadSettings settings = load_settings(s);
    const bool staircase = settings.protocol == LoadSettings::Protocol::Staircase;
    load = apply_pressure_lag(load, lag, staircase ? 0.005 * settings.step_Pa : 0.05 * kkPa);
  }
  return load;
}

Mesh build_mesh(const Scene& s, std::vector<std::string>* warnings) {
  const MeshSettings::Source source = mesh_settings(s).source;
  if (source == MeshSettings::Source::PneuNet) return built_in_mesh(s);
  if (source == MeshSettings::Source::Stl) return stl_scene_mesh(s, warnings);
  InpDeck deck = scene_deck(s);
  if (warnings) warnings->insert(warnings->end(), deck.warnings.begin(), deck.warnings.end());
  Mesh mesh = std::move(deck.mesh);
  if (s.boolean("mesh.promote_to_tet10")) mesh = promote_to_tet10(mesh);
  return mesh;
}

LoadHistory inlet_load(const Scene& s) {
  LoadHistory load;
  const LoadSettings settings = load_settings(s);
  if (settings.protocol == LoadSettings::Protocol::Staircase) {
    const double p_max = settings.max_Pa, dp = settings.step_Pa;
    const double hold_s = settings.hold_s, every_s = settings.output_every_s;
    const int trials = settings.trials;
    // The size first, so that the key and where it was set are named (staircase() checks it too).
    const StaircaseSize size = staircase_size(p_max, dp, hold_s, trials, every_s);
    if (size.levels > kMaxStaircaseLevels)
      s.fail("load.step_kPa", "gives " + short_num(size.levels) + " pressure levels up to load.max_kPa = " +
                                  short_num(p_max / kkPa) + " kPa; the limit is " + short_num(kMaxStaircaseLevels) +
                                  " (each level is a solve); use a larger step");
    if (size.reports > kMaxReports)
      s.fail(every_s > 0.0 ? "load.output_every_s" : "load.trials",
             "the protocol would make " + short_num(size.reports) + " reports (" + std::to_string(trials) + " trial(s) x " +
                 short_num(size.levels) + " levels x " + short_num(size.reports / (trials * size.levels)) +
                 " per level); the limit is " + short_num(kMaxReports) +
                 "; report less often (load.output_every_s) or run fewer trials");
    // The keys that must agree with each other, with where they were set (staircase() checks them
    // too, but knows no scene).
    const double ramp_s = settings.ramp_s, mark_s = settings.mark_s;
    if (!(ramp_s < hold_s))
      s.fail("load.ramp_s", "got " + short_num(ramp_s) + "; it must be shorter than load.hold_s = " + short_num(hold_s));
    if (!(mark_s >= ramp_s && mark_s <= hold_s))
      s.fail("load.mark_s", "got " + short_num(mark_s) + "; the mark must lie within the hold, after the ramp: from " +
                                "load.ramp_s = " + short_num(ramp_s) + " to load.hold_s = " + short_num(hold_s) + " s");
    load = staircase(p_max, dp, hold_s, ramp_s, trials, mark_s, settings.rest_s, every_s);
  } else {  // LoadSettings::Protocol::Csv
    const std::string& csv = settings.csv;
    if (csv.empty()) s.fail("load.csv", "protocol = \"csv\" needs the pressure file in load.csv");
    try {
      load = pressure_history_from_csv(s.resolve_path(csv), 0.25, settings.output_every_s);
    } catch (const InputError& e) {
      if (std::string(e.what()).find("load.output_every_s") == std::string::npos) throw;
      s.fail("load.output_every_s", e.what());
    }
    load.rest_between_trials_s = settings.rest_s;
  }
  return load;
}

std::unique_ptr<BuiltModel> build_model(const Scene& s) {
  auto out = std::make_unique<BuiltModel>();
  Model& model = out->model;
  const MeshSettings::Source source = mesh_settings(s).source;
  InpDeck deck;
  model.mesh = read_model_mesh(s, source, deck, out->warnings);
  out->warnings.insert(out->warnings.end(), s.notes().begin(), s.notes().end());  // a deck's materials
  Mesh& mesh = model.mesh;
  mesh.ensure_ids();
  const bool membrane_fabric = mesh_settings(s).membrane_fabric;
  assign_parts(with_deck_moduli(s, deck, out->warnings), model, membrane_fabric);  // s itself without MODULI=

  // Boundary conditions.
  model.fixed.assign(3 * mesh.num_nodes(), 0);
  const bool is_inp = source == MeshSettings::Source::Inp;
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

  set_cavity_faces(s, model, deck, is_inp, out->warnings);

  // Bending angle.
  model.angle.tip_nodes = is_inp ? deck_tip_nodes(s, model, out->warnings) : node_set(s, mesh, "mesh.tip_set");
  model.angle.fixed_normal_out = s.vec3("angle.fixed_normal");
  model.angle.bend_direction = s.vec3("angle.bend_direction");
  if (model.angle.fixed_normal_out.norm() < 1e-12) s.fail("angle.fixed_normal", "must be a nonzero vector");
  model.gravity_m_s2 = s.vec3("gravity.g_m_s2");
  if (membrane_fabric) model.membranes.push_back(fabric_membrane(s, mesh));
  validate(model);
  resolve_angle_frame(s, model, is_inp || source == MeshSettings::Source::Stl, out->warnings);
  if (model.angle.bend_direction.cross(model.angle.fixed_normal_out).norm() < 1e-9 * model.angle.bend_direction.norm())
    s.fail("angle.bend_direction", "must not be parallel to angle.fixed_normal");
  set_rig_gravity(s, model);
  out->stats = compute_stats(mesh);

  out->load = chamber_load(s);

  out->solver = solver_settings(s);

  out->output = output_settings(s);
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
      if (!std::isfinite(t) || !std::isfinite(p))  // stod reads "inf" and "nan"
        throw InputError(path + ":" + std::to_string(lineno) + ": time_s and pressure_kPa must be finite numbers, got '" +
                         line + "'");
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
  double reports = 0.0;  // the extra reports of output_every_s so far, against kMaxReports
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
    if (output_every_s > 0) {
      reports += std::ceil(tl.duration() / output_every_s);
      if (!(reports <= kMaxReports))
        throw InputError("load.output_every_s = " + short_num(output_every_s) + " s would make more than " +
                         short_num(kMaxReports) + " reports over the trials of " + path + " (the limit); report less often");
      for (double t = output_every_s; t < tl.duration(); t += output_every_s) tl.output_s.push_back(t);
    }
    std::sort(tl.output_s.begin(), tl.output_s.end());
    h.trials.push_back(std::move(tl));
  }
  h.description = "pressure from " + path;
  return h;
}

}  // namespace pneufem
