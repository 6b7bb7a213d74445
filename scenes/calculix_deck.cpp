#include "scenes/calculix_deck.h"

#include <cmath>
#include <cstdio>
#include <sstream>

#include "core/errors.h"
#include "scenes/inp/deck.h"

namespace pneufem {

namespace {

std::string g(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.10g", v);
  return buf;
}

void write_nset(std::ostringstream& os, const std::string& name, const std::vector<long>& ids) {
  os << "*NSET, NSET=" << name << "\n";
  for (std::size_t i = 0; i < ids.size(); ++i) os << ids[i] << ((i + 1) % 16 == 0 || i + 1 == ids.size() ? "\n" : ", ");
}

// Material block in CalculiX syntax (stresses in MPa, D1 = 2/K in 1/MPa).
void write_material(std::ostringstream& os, const Scene& s, const std::string& name, const std::string& ccx_name) {
  const std::string T = "materials." + name;
  const std::string model = s.string(T + ".model");
  // The model first: an unknown one is named as such, not as a constant it lacks.
  if (model != "linear_elastic" && model != "yeoh" && model != "neo_hookean" && model != "mooney_rivlin" && model != "ogden")
    s.fail(T + ".model", "\"" + model + "\" cannot be exported to CalculiX (linear_elastic, yeoh, neo_hookean, "
                         "mooney_rivlin or ogden can)");
  os << "*MATERIAL, NAME=" << ccx_name << "\n";
  if (model == "linear_elastic") {
    os << "*ELASTIC\n" << g(s.number(T + ".E_MPa")) << ", " << g(s.number(T + ".nu")) << "\n";
  } else {
    const double Kr = s.number(T + ".K_over_mu");
    if (model == "yeoh") {
      const double C10 = s.number(T + ".C10_MPa");
      const double C20 = s.has(T + ".C20_MPa") ? s.number(T + ".C20_MPa") : 0.0;
      const double C30 = s.has(T + ".C30_MPa") ? s.number(T + ".C30_MPa") : 0.0;
      os << "*HYPERELASTIC, YEOH\n" << g(C10) << ", " << g(C20) << ", " << g(C30) << ", " << g(2.0 / (Kr * 2 * C10))
         << ", 0., 0.\n";
    } else if (model == "neo_hookean") {
      const double C10 = s.number(T + ".C10_MPa");
      os << "*HYPERELASTIC, NEO HOOKE\n" << g(C10) << ", " << g(2.0 / (Kr * 2 * C10)) << "\n";
    } else if (model == "mooney_rivlin") {
      const double C10 = s.number(T + ".C10_MPa"), C01 = s.number(T + ".C01_MPa");
      os << "*HYPERELASTIC, MOONEY-RIVLIN\n" << g(C10) << ", " << g(C01) << ", " << g(2.0 / (Kr * 2 * (C10 + C01))) << "\n";
    } else if (model == "ogden") {
      const std::vector<double> mu = s.numbers(T + ".mu_MPa"), alpha = s.numbers(T + ".alpha");
      double mu0 = 0;
      for (double m : mu) mu0 += m;
      os << "*HYPERELASTIC, OGDEN, N=" << mu.size() << "\n";
      std::vector<std::string> v;
      for (std::size_t i = 0; i < mu.size(); ++i) {
        v.push_back(g(mu[i]));
        v.push_back(g(alpha[i]));
      }
      v.push_back(g(2.0 / (Kr * mu0)));
      for (std::size_t i = 1; i < mu.size(); ++i) v.push_back("0.");
      for (std::size_t i = 0; i < v.size(); ++i) os << v[i] << ((i + 1) % 8 == 0 || i + 1 == v.size() ? "\n" : ", ");
    } else {
      s.fail(T + ".model", "cannot be exported to CalculiX");
    }
  }
  os << "*DENSITY\n" << g(s.number(T + ".density_kg_m3") * 1e-12) << "\n";
}

}  // namespace

std::string calculix_deck(const Scene& s, const BuiltModel& bm) {
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
  std::vector<long> tip;
  for (int n : m.angle.tip_nodes) tip.push_back(mesh.node_ids[n]);
  write_nset(os, "PNEUFEM_TIP", tip);
  for (int i = 0; i < s.array_size("parts"); ++i) {
    const std::string key = "parts[" + std::to_string(i) + "]";
    const std::string mat = s.string(key + ".material");
    std::string upper = mat;
    for (char& c : upper) c = static_cast<char>(::toupper(c));
    write_material(os, s, mat, "M_" + upper);
    os << "*SOLID SECTION, ELSET=" << s.string(key + ".elset") << ", MATERIAL=M_" << upper << "\n";
  }
  os << "*BOUNDARY\n";
  for (int d = 0; d < 3; ++d) {
    bool any = false;
    for (int n = 0; n < mesh.num_nodes() && !any; ++n) any = m.fixed[3 * n + d];
    if (any) os << "PNEUFEM_FIX" << d + 1 << ", " << d + 1 << ", " << d + 1 << ", 0.\n";
  }
  const double pmax = s.number("load.max_kPa"), dp = s.number("load.step_kPa");
  os << "*AMPLITUDE, NAME=PRAMP\n0., 0., " << g(pmax) << ", " << g(pmax) << "\n";
  os << "*TIME POINTS, NAME=TP\n";
  std::vector<std::string> points;
  for (int k = 1; k * dp <= pmax + 1e-9; ++k) points.push_back(g(k * dp));
  for (std::size_t i = 0; i < points.size(); ++i) os << points[i] << ((i + 1) % 8 == 0 || i + 1 == points.size() ? "\n" : ", ");
  os << "*STEP, NLGEOM, INC=2000\n*STATIC\n0.5, " << g(pmax) << ", 0.002, 2.5\n";
  os << "*DLOAD, AMPLITUDE=PRAMP\n";  // amplitude(t) * 0.001 MPa = t kPa
  for (const FaceRef& f : m.pressure_faces) os << mesh.element_ids[f.element] << ", P" << f.local_face + 1 << ", 0.001\n";
  os << "*NODE FILE, TIME POINTS=TP\nU\n*END STEP\n";
  std::string text = os.str();
  return text;
}

}  // namespace pneufem
