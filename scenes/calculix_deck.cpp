#include "scenes/calculix_deck.h"

#include <cmath>
#include <cstdio>
#include <set>
#include <sstream>

#include "core/errors.h"
#include "damage/registry.h"
#include "scenes/inp/deck.h"
#include "scenes/inp/materials.h"
#include "scenes/scene_keys.h"
#include "scenes/scene_settings.h"

namespace pneufem {

namespace {

/// A number of the deck: the shortest text that reads back exactly (when it fits CalculiX's fields).
std::string g(double v) { return inp_real_text(v); }

/// Step times and pressures, as they have always been written (10 significant digits).
std::string g10(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

void write_nset(std::ostringstream& os, const std::string& name, const std::vector<long>& ids) {
  os << "*NSET, NSET=" << name << "\n";
  for (std::size_t i = 0; i < ids.size(); ++i) os << ids[i] << ((i + 1) % 16 == 0 || i + 1 == ids.size() ? "\n" : ", ");
}

/// Values as data lines of at most 8 (Abaqus's limit for material data).
void write_values(std::ostringstream& os, const std::vector<double>& v) {
  for (std::size_t i = 0; i < v.size(); ++i) os << g(v[i]) << ((i + 1) % 8 == 0 || i + 1 == v.size() ? "\n" : ", ");
}

/// Parameter `p` of the enabled effect table K: the scene's value, else the registry's default (as the
/// scene reader takes it, scenes/scene_materials.cpp).
std::vector<double> effect_values(const Scene& s, const std::string& K, const std::string& effect, const std::string& p) {
  if (!s.has(K + "." + p)) return {builtin_effect(effect).param(p).default_value};
  const MaterialEffect& fx = builtin_effect(effect);
  return fx.param(p).per_term ? s.numbers(K + "." + p) : std::vector<double>{s.number(K + "." + p)};
}

bool effect_on(const Scene& s, const std::string& K) { return s.has(K) && s.boolean(K + ".enabled"); }

/// The hyperelastic law of table T as *HYPERELASTIC with its constants times `scale` (the material's
/// stiffness_scale: energy, stresses and moduli scale alike, so K/mu and D1 = 2/(K/mu mu0) follow).
void write_hyperelastic(std::ostringstream& os, const Scene& s, const std::string& T, const std::string& model,
                        double scale, const std::string& moduli) {
  const double Kr = s.number(T + ".K_over_mu");
  auto c = [&](const char* k) { return s.has(T + "." + k) ? scale * s.number(T + "." + k) : 0.0; };
  const std::string tail = moduli.empty() ? "" : ", MODULI=" + moduli;
  if (model == "yeoh") {
    const double C10 = scale * s.number(T + ".C10_MPa");
    os << "*HYPERELASTIC, YEOH" << tail << "\n";
    write_values(os, {C10, c("C20_MPa"), c("C30_MPa"), abaqus_d1(Kr, 2 * C10), 0.0, 0.0});
  } else if (model == "neo_hookean") {
    const double C10 = scale * s.number(T + ".C10_MPa");
    os << "*HYPERELASTIC, NEO HOOKE" << tail << "\n";
    write_values(os, {C10, abaqus_d1(Kr, 2 * C10)});
  } else if (model == "mooney_rivlin") {
    const double C10 = scale * s.number(T + ".C10_MPa"), C01 = scale * s.number(T + ".C01_MPa");
    os << "*HYPERELASTIC, MOONEY-RIVLIN" << tail << "\n";
    write_values(os, {C10, C01, abaqus_d1(Kr, 2 * (C10 + C01))});
  } else {  // ogden, in Abaqus's convention as the law (materials/ogden.h)
    const std::vector<double> mu = s.numbers(T + ".mu_MPa"), alpha = s.numbers(T + ".alpha");
    if (mu.size() != alpha.size()) s.fail(T + ".alpha", "needs one alpha per mu_MPa");
    double mu0 = 0;
    std::vector<double> v;
    for (std::size_t i = 0; i < mu.size(); ++i) {
      v.push_back(scale * mu[i]);
      v.push_back(alpha[i]);
      mu0 += scale * mu[i];
    }
    v.push_back(abaqus_d1(Kr, mu0));
    for (std::size_t i = 1; i < mu.size(); ++i) v.push_back(0.0);  // D2..DN
    os << "*HYPERELASTIC, OGDEN, N=" << mu.size() << tail << "\n";
    write_values(os, v);
  }
}

// Material block in Abaqus syntax (mm, N, MPa, tonne; D1 = 2/K in 1/MPa) through the conversions the
// deck reader inverts (scenes/inp/materials.h), so that the deck re-imports to the same scene: the
// law (scaled by stiffness_scale), *DENSITY, *MULLINS EFFECT and *VISCOELASTIC, TIME=PRONY of the
// enabled effects. Effects Abaqus has no keyword for (fatigue, registered ones) are named in `notes`
// and in a comment line of the deck.
void write_material(std::ostringstream& os, const Scene& s, const std::string& name, const std::string& deck_name,
                    std::vector<std::string>& notes) {
  const std::string T = "materials." + name;
  if (!s.has(T)) s.fail(T, "no such material; define a [" + T + "] table");
  const std::string model = s.string(T + ".model");
  // The model first: an unknown one is named as such, not as a constant it lacks.
  if (model != "linear_elastic" && model != "yeoh" && model != "neo_hookean" && model != "mooney_rivlin" && model != "ogden")
    s.fail(T + ".model", "\"" + model + "\" cannot be exported to CalculiX (linear_elastic, yeoh, neo_hookean, "
                         "mooney_rivlin or ogden can)");
  const double scale = s.has(T + ".stiffness_scale") ? s.number(T + ".stiffness_scale") : 1.0;
  const bool visco = effect_on(s, T + ".viscoelastic");
  std::string moduli;
  if (visco) {
    const std::string m = s.has(T + ".viscoelastic.moduli") ? s.string(T + ".viscoelastic.moduli")
                                                            : builtin_effect("viscoelastic").choices.at(0).values.front();
    moduli = m == "long_term" ? "LONG TERM" : "INSTANTANEOUS";
  }
  os << "*MATERIAL, NAME=" << deck_name << "\n";
  if (model == "linear_elastic") {
    os << "*ELASTIC" << (moduli.empty() ? "" : ", MODULI=" + moduli) << "\n";
    write_values(os, {scale * s.number(T + ".E_MPa"), s.number(T + ".nu")});
  } else {
    write_hyperelastic(os, s, T, model, scale, moduli);
  }
  os << "*DENSITY\n" << g(deck_density(s.number(T + ".density_kg_m3"), "mm")) << "\n";
  if (effect_on(s, T + ".mullins")) {
    const std::string K = T + ".mullins";
    os << "*MULLINS EFFECT\n";
    write_values(os, {effect_values(s, K, "mullins", "r")[0], effect_values(s, K, "mullins", "m_MPa")[0],
                      effect_values(s, K, "mullins", "beta")[0]});
  }
  if (visco) {
    const std::string K = T + ".viscoelastic";
    const std::vector<double> gamma = effect_values(s, K, "viscoelastic", "gamma");
    const std::vector<double> tau = effect_values(s, K, "viscoelastic", "tau_s");
    if (gamma.size() != tau.size()) s.fail(K + ".tau_s", "needs one relaxation time per gamma");
    const std::vector<double> g_abaqus = abaqus_g(gamma);
    os << "*VISCOELASTIC, TIME=PRONY\n";
    for (std::size_t i = 0; i < gamma.size(); ++i) write_values(os, {g_abaqus[i], 0.0, tau[i]});
  }
  for (const MaterialEffect* fx : material_effects())
    if (fx->name != "mullins" && fx->name != "viscoelastic" && effect_on(s, T + "." + fx->name)) {
      const std::string note = T + "." + fx->name + " is not written to the deck: Abaqus has no keyword for it (a " +
                               "scene reading the deck switches it on in its own [" + T + "." + fx->name + "] table)";
      os << "** pneufem: " << note << "\n";
      notes.push_back(note);
    }
}

/// Region stiffness scales make parts of their own (scenes/build_model.cpp); the deck has one section
/// per [[parts]] entry, so a scale other than 1 cannot be written.
void refuse_region_scales(const Scene& s) {
  for (const std::string& tag : s.table_keys("regions")) {
    const std::string key = "regions." + tag + ".stiffness_scale";
    if (s.has(key) && s.number(key) != 1.0)
      s.fail(key, "the CalculiX export writes one material per [[parts]] entry and cannot scale a region; set it to 1 "
                  "(or give the region's elements a part and material of their own)");
  }
}

}  // namespace

std::string calculix_deck(const Scene& s, const BuiltModel& bm, std::vector<std::string>* notes) {
  const Model& m = bm.model;
  const Mesh& mesh = m.mesh;
  if (!m.membranes.empty())
    s.fail("mesh.fabric_model", "the CalculiX export does not write membranes yet; export with mesh.fabric_model = \"solid\"");
  std::ostringstream os;
  os << "*HEADING\npneufem export: units mm, N, MPa, tonne. Step time == cavity pressure in kPa.\n";
  write_inp_mesh(os, mesh, 1e-3);
  // Fixed dofs, grouped per direction.
  for (int d = 0; d < 3; ++d) {
    std::vector<long> ids;
    for (int n = 0; n < mesh.num_nodes(); ++n)
      if (m.fixed[3 * n + d]) ids.push_back(mesh.node_ids[n]);
    if (!ids.empty()) write_nset(os, "PNEUFEM_FIX" + std::to_string(d + 1), ids);
  }
  refuse_region_scales(s);
  std::vector<long> tip;
  for (int n : m.angle.tip_nodes) tip.push_back(mesh.node_ids[n]);
  write_nset(os, "PNEUFEM_TIP", tip);
  std::set<std::string> written;  // materials (upper case) already written: one block each
  std::vector<std::string> unwritten;
  for (int i = 0; i < s.array_size("parts"); ++i) {
    const std::string key = "parts[" + std::to_string(i) + "]";
    const std::string mat = s.string(key + ".material");
    std::string upper = mat;  // the reader names the scene table in lower case again
    for (char& c : upper) c = static_cast<char>(::toupper(static_cast<unsigned char>(c)));
    if (written.insert(upper).second) write_material(os, s, mat, upper, unwritten);
    os << "*SOLID SECTION, ELSET=" << s.string(key + ".elset") << ", MATERIAL=" << upper << "\n";
  }
  if (notes) notes->insert(notes->end(), unwritten.begin(), unwritten.end());
  os << "*BOUNDARY\n";
  for (int d = 0; d < 3; ++d) {
    bool any = false;
    for (int n = 0; n < mesh.num_nodes() && !any; ++n) any = m.fixed[3 * n + d];
    if (any) os << "PNEUFEM_FIX" << d + 1 << ", " << d + 1 << ", " << d + 1 << ", 0.\n";
  }
  const LoadSettings load = load_settings(s);
  const double pmax = load.max_Pa / detail::kkPa, dp = load.step_Pa / detail::kkPa;  // in kPa, as the amplitude
  os << "*AMPLITUDE, NAME=PRAMP\n0., 0., " << g10(pmax) << ", " << g10(pmax) << "\n";
  os << "*TIME POINTS, NAME=TP\n";
  std::vector<std::string> points;
  for (int k = 1; k * dp <= pmax + 1e-9; ++k) points.push_back(g10(k * dp));
  for (std::size_t i = 0; i < points.size(); ++i) os << points[i] << ((i + 1) % 8 == 0 || i + 1 == points.size() ? "\n" : ", ");
  os << "*STEP, NLGEOM, INC=2000\n*STATIC\n0.5, " << g10(pmax) << ", 0.002, 2.5\n";
  os << "*DLOAD, AMPLITUDE=PRAMP\n";  // amplitude(t) * 0.001 MPa = t kPa
  for (const FaceRef& f : m.pressure_faces) os << mesh.element_ids[f.element] << ", P" << f.local_face + 1 << ", 0.001\n";
  os << "*NODE FILE, TIME POINTS=TP\nU\n*END STEP\n";
  std::string text = os.str();
  return text;
}

}  // namespace pneufem
