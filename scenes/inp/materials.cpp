// The materials and sections of a deck (scenes/inp/materials.h).
#include "scenes/inp/materials.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <functional>
#include <map>
#include <set>

#include "core/errors.h"
#include "core/message_text.h"
#include "core/number_text.h"
#include "scenes/inp/text.h"

namespace pneufem {

namespace {

using inp::Keyword;
using inp::Loc;

/// The shortest decimal (1 to 17 significant digits) near `approx` for which forward(x) == target
/// exactly; `approx` itself when there is none.
double shortest_preimage(double approx, double target, const std::function<double(double)>& forward) {
  if (!std::isfinite(approx)) return approx;
  for (int digits = 1; digits <= 17; ++digits) {
    char buf[48];
    std::snprintf(buf, sizeof buf, "%.*e", digits - 1, approx);
    const double x = std::strtod(buf, nullptr);
    if (forward(x) == target) return x;
  }
  return approx;
}

// Material options pneufem passes over: no effect on its runs (isothermal, no heat; damping is the
// scene's solver.damping_1_s).
const std::set<std::string> kPassedOver = {"CONDUCTIVITY", "SPECIFIC HEAT", "EXPANSION", "LATENT HEAT", "DAMPING",
                                           "DIELECTRIC", "ELECTRICAL CONDUCTIVITY", "DEPVAR", "INELASTIC HEAT FRACTION"};
// Material options that change the mechanics in ways pneufem does not model.
const std::set<std::string> kRefused = {
    "PLASTIC", "HYPERFOAM", "CREEP", "VISCOUS", "DAMAGE INITIATION", "DAMAGE EVOLUTION", "USER MATERIAL",
    "ANISOTROPIC HYPERELASTIC", "HYSTERESIS", "PARALLEL RHEOLOGICAL FRAMEWORK", "VISCOELASTIC NETWORK", "SWELLING",
    "LOW DENSITY FOAM", "CRUSHABLE FOAM", "FABRIC", "CAST IRON PLASTICITY", "DRUCKER PRAGER", "MOHR COULOMB",
    "PLASTIC STRAIN RATE", "RATE DEPENDENT", "CYCLIC HARDENING", "TRS", "POROUS ELASTIC"};
// Test data lines (fitted by `pneufem fit-material`), passed over.
const std::set<std::string> kTestData = {"UNIAXIAL TEST DATA", "BIAXIAL TEST DATA", "PLANAR TEST DATA",
                                         "VOLUMETRIC TEST DATA", "SHEAR TEST DATA", "SIMPLE SHEAR TEST DATA"};

/// Parameter names with single blanks: "NEO  HOOKE" -> "NEO HOOKE".
std::string single_blanks(const std::string& s) {
  std::string out;
  bool blank = false;
  for (char c : s) {
    if (inp::is_blank(c)) {
      blank = !out.empty();
      continue;
    }
    if (blank) out.push_back(' ');
    blank = false;
    out.push_back(c);
  }
  return out;
}

/// The hyperelastic law of a *HYPERELASTIC line: its model word, how many constants (before the
/// D values) and their scene keys, and how many D values.
struct HyperLaw {
  std::string model;
  std::vector<std::string> keys;  // scene keys of the coefficients; Ogden: "mu"/"alpha" pairs
  int n_d = 1;
  int ogden_terms = 0;
};

class MaterialReader {
 public:
  MaterialReader(inp::LineSource& lines, std::string length_unit) : lines_(lines), unit_(std::move(length_unit)) {}

  InpMaterials read() {
    std::string_view text;
    Loc loc;
    while (lines_.next(text, loc)) {
      if (text.front() == '*')
        keyword(inp::parse_keyword(text), loc);
      else
        data_line(text, loc);
    }
    end_option();
    check_sections();
    return std::move(out_);
  }

 private:
  enum class Option { None, Hyper, Elastic, Density, Mullins, Visco, Section, Skip };

  std::string where(const Loc& loc) const { return lines_.where(loc); }

  [[noreturn]] void fail(const Loc& loc, const std::string& keyword, const std::string& what, const std::string& todo) const {
    throw InputError(printable(where(loc) + ": " + keyword + ": " + what + "; " + todo));
  }

  /// "*HYPERELASTIC, YEOH, N=3": the keyword line as the messages quote it.
  static std::string quoted(const Keyword& kw) {
    std::string s = "*" + kw.name;
    for (const auto& [k, v] : kw.params) s += ", " + single_blanks(k) + (v.empty() ? "" : "=" + v);
    return s;
  }

  /// The parameters of `kw` (blanks normalised), each of which must be in `allowed`.
  std::map<std::string, std::string> params(const Keyword& kw, const Loc& loc, const std::set<std::string>& allowed,
                                            const std::string& todo) const {
    std::map<std::string, std::string> p;
    for (const auto& [k, v] : kw.params) {
      const std::string key = single_blanks(k);
      if (!allowed.count(key)) fail(loc, quoted(kw), "the parameter " + key + " is not read by pneufem", todo);
      p[key] = v;
    }
    return p;
  }

  InpMaterial& material(const Keyword& kw, const Loc& loc) {
    if (material_ < 0)
      fail(loc, "*" + kw.name, "a material option outside a *MATERIAL", "put it after the *MATERIAL, NAME=... line it belongs to");
    return out_.materials[static_cast<std::size_t>(material_)];
  }

  void keyword(const Keyword& kw, const Loc& loc) {
    end_option();
    option_ = Option::None;
    const std::string& k = kw.name;
    if (k == "MATERIAL") return begin_material(kw, loc);
    if (k == "SOLID SECTION") return begin_section(kw, loc);
    if (k == "HYPERELASTIC") return begin_hyperelastic(kw, loc);
    if (k == "ELASTIC") return begin_elastic(kw, loc);
    if (k == "DENSITY") return begin_simple(kw, loc, Option::Density);
    if (k == "MULLINS EFFECT") return begin_simple(kw, loc, Option::Mullins);
    if (k == "VISCOELASTIC") return begin_viscoelastic(kw, loc);
    if (kTestData.count(k)) {
      (void)material(kw, loc);
      option_ = Option::Skip;
      return;
    }
    if (kPassedOver.count(k) && material_ >= 0) {
      out_.notes.push_back(where(loc) + ": *" + k + " of *MATERIAL " + out_.materials[static_cast<std::size_t>(material_)].name +
                           " passed over (no effect in pneufem's isothermal runs" +
                           (k == "DAMPING" ? "; explicit runs are damped by solver.damping_1_s" : "") + ")");
      option_ = Option::Skip;
      return;
    }
    if (kRefused.count(k) && material_ >= 0)
      fail(loc, "*" + k, "pneufem does not model this material behaviour (its laws: hyperelastic YEOH, NEO HOOKE, MOONEY-RIVLIN, "
                         "OGDEN; *ELASTIC; *MULLINS EFFECT; *VISCOELASTIC, TIME=PRONY)",
           "remove it from *MATERIAL " + out_.materials[static_cast<std::size_t>(material_)].name +
               ", or set the material in the scene ([materials.NAME])");
    material_ = -1;  // any other keyword ends the material
  }

  void begin_material(const Keyword& kw, const Loc& loc) {
    const auto p = params(kw, loc, {"NAME"}, "a *MATERIAL line is '*MATERIAL, NAME=<name>'");
    const std::string name = kw.get("NAME");
    if (name.empty()) fail(loc, quoted(kw), "no NAME=", "name the material: *MATERIAL, NAME=<name>");
    const std::string key = inp::upper(name);
    if (names_.count(key))
      fail(loc, quoted(kw), "a second material named " + name + " (the first at " + out_.materials[names_[key]].where + ")",
           "rename one (material names are case-insensitive)");
    names_[key] = out_.materials.size();
    InpMaterial m;
    m.name = name;
    m.where = where(loc);
    out_.materials.push_back(std::move(m));
    material_ = static_cast<int>(out_.materials.size()) - 1;
  }

  void begin_section(const Keyword& kw, const Loc& loc) {
    material_ = -1;
    (void)params(kw, loc, {"ELSET", "MATERIAL", "ORIENTATION", "CONTROLS"},
                 "a solid section is '*SOLID SECTION, ELSET=<element set>, MATERIAL=<material>'");
    const std::string elset = kw.get("ELSET"), mat = kw.get("MATERIAL");
    if (elset.empty() || mat.empty())
      fail(loc, quoted(kw), std::string("no ") + (elset.empty() ? "ELSET=" : "MATERIAL="),
           "give both: *SOLID SECTION, ELSET=<element set>, MATERIAL=<material>");
    out_.sections.push_back(InpSection{elset, mat, where(loc)});
    option_ = Option::Section;  // its data line (a thickness, for solids empty) is passed over
  }

  /// MODULI=INSTANTANEOUS | LONG TERM (an underscore for the space and any case): the scene's word.
  void moduli(const Keyword& kw, const Loc& loc, InpMaterial& m) {
    if (!kw.has("MODULI")) return;
    std::string v = inp::upper(kw.get("MODULI"));
    for (char& c : v)
      if (c == '_') c = ' ';
    v = single_blanks(v);
    if (v != "INSTANTANEOUS" && v != "LONG TERM")
      fail(loc, quoted(kw), "MODULI=" + kw.get("MODULI") + " is unknown",
           "use MODULI=INSTANTANEOUS (Abaqus's default) or MODULI=LONG TERM");
    m.moduli = v == "INSTANTANEOUS" ? "instantaneous" : "long_term";
    m.moduli_where = where(loc);
  }

  void set_law(InpMaterial& m, const Keyword& kw, const Loc& loc, const std::string& model) {
    if (!m.model.empty())
      fail(loc, quoted(kw), "*MATERIAL " + m.name + " has an elastic law already (" + m.law_keyword + " at " + m.law_where + ")",
           "give one *HYPERELASTIC or *ELASTIC per material");
    m.model = model;
    m.law_keyword = quoted(kw);
    m.law_where = where(loc);
  }

  HyperLaw hyper_law(const Keyword& kw, const Loc& loc, const std::map<std::string, std::string>& p) const {
    const std::string n = p.count("N") ? p.at("N") : "1";
    const auto n_is = [&](std::initializer_list<const char*> ok, const std::string& what) {
      for (const char* o : ok)
        if (n == o) return std::stoi(n);
      fail(loc, quoted(kw), "N=" + n + " is not one pneufem has", what);
    };
    if (p.count("YEOH")) return {"yeoh", {"C10_MPa", "C20_MPa", "C30_MPa"}, 3};
    if (p.count("NEO HOOKE")) return {"neo_hookean", {"C10_MPa"}, 1};
    if (p.count("MOONEY-RIVLIN")) return {"mooney_rivlin", {"C10_MPa", "C01_MPa"}, 1};
    if (p.count("OGDEN")) {
      const int t = n_is({"1", "2", "3"}, "pneufem's Ogden law has 1 to 3 terms: use N=1, 2 or 3");
      HyperLaw law{"ogden", {}, t, t};
      return law;
    }
    if (p.count("REDUCED POLYNOMIAL")) {
      const int t = n_is({"1", "2", "3"}, "pneufem has REDUCED POLYNOMIAL N=1 (neo-Hookean) to N=3 (Yeoh)");
      if (t == 1) return {"neo_hookean", {"C10_MPa"}, 1};
      std::vector<std::string> keys = {"C10_MPa", "C20_MPa", "C30_MPa"};
      keys.resize(static_cast<std::size_t>(t));
      return {"yeoh", keys, t};
    }
    // POLYNOMIAL, or no law named (Abaqus's default, POLYNOMIAL with N = 1): Mooney-Rivlin.
    if (p.count("POLYNOMIAL")) (void)n_is({"1"}, "pneufem has POLYNOMIAL N=1 (Mooney-Rivlin); use N=1 or YEOH");
    return {"mooney_rivlin", {"C10_MPa", "C01_MPa"}, 1};
  }

  void begin_hyperelastic(const Keyword& kw, const Loc& loc) {
    InpMaterial& m = material(kw, loc);
    const auto p = params(kw, loc,
                          {"YEOH", "NEO HOOKE", "MOONEY-RIVLIN", "OGDEN", "POLYNOMIAL", "REDUCED POLYNOMIAL", "N", "MODULI",
                           "TEST DATA INPUT", "POISSON"},
                          "pneufem reads YEOH, NEO HOOKE, MOONEY-RIVLIN, OGDEN (N=1..3), POLYNOMIAL (N=1), REDUCED "
                          "POLYNOMIAL (N=1..3), N=, MODULI= and TEST DATA INPUT; fit another law's test data with "
                          "`pneufem fit-material` or set the material in the scene");
    int laws = 0;
    for (const char* l : {"YEOH", "NEO HOOKE", "MOONEY-RIVLIN", "OGDEN", "POLYNOMIAL", "REDUCED POLYNOMIAL"}) laws += p.count(l) ? 1 : 0;
    if (laws > 1) fail(loc, quoted(kw), "names more than one law", "name one");
    moduli(kw, loc, m);
    if (p.count("TEST DATA INPUT")) {
      set_law(m, kw, loc, "test_data");
      option_ = Option::Skip;
      return;
    }
    if (p.count("POISSON")) fail(loc, quoted(kw), "POISSON= belongs to TEST DATA INPUT", "remove it");
    law_ = hyper_law(kw, loc, p);
    set_law(m, kw, loc, law_.model);
    begin_values(kw, loc, Option::Hyper,
                 law_.ogden_terms > 0 ? 3 * law_.ogden_terms : static_cast<int>(law_.keys.size()) + law_.n_d);
  }

  void begin_elastic(const Keyword& kw, const Loc& loc) {
    InpMaterial& m = material(kw, loc);
    const auto p = params(kw, loc, {"TYPE", "MODULI"}, "pneufem reads *ELASTIC, TYPE=ISOTROPIC (E, nu)");
    if (p.count("TYPE") && inp::upper(p.at("TYPE")) != "ISOTROPIC")
      fail(loc, quoted(kw), "TYPE=" + p.at("TYPE") + " is not isotropic", "pneufem's linear elastic law is isotropic: give TYPE=ISOTROPIC with E, nu");
    moduli(kw, loc, m);
    set_law(m, kw, loc, "linear_elastic");
    begin_values(kw, loc, Option::Elastic, 2);
  }

  void begin_simple(const Keyword& kw, const Loc& loc, Option o) {
    InpMaterial& m = material(kw, loc);
    const bool density = o == Option::Density;
    (void)params(kw, loc, {}, density ? "pneufem reads *DENSITY with one value, rho"
                                      : "pneufem reads the Ogden-Roxburgh constants r, m, beta of *MULLINS EFFECT; fit "
                                        "cyclic test data with `pneufem fit-material --mullins`");
    if (density ? m.density.has_value() : m.mullins.has_value())
      fail(loc, quoted(kw), "given twice for *MATERIAL " + m.name, "keep one");
    begin_values(kw, loc, o, density ? 1 : 3);
  }

  void begin_viscoelastic(const Keyword& kw, const Loc& loc) {
    InpMaterial& m = material(kw, loc);
    const auto p = params(kw, loc, {"TIME", "MODULI"},
                          "pneufem reads *VISCOELASTIC, TIME=PRONY (g_i, k_i, tau_i); fit relaxation data with "
                          "`pneufem fit-material relaxation:FILE`");
    if (inp::upper(kw.get("TIME")) != "PRONY")
      fail(loc, quoted(kw), p.count("TIME") ? "TIME=" + p.at("TIME") + " is not read" : "no TIME=PRONY",
           "give the Prony terms: *VISCOELASTIC, TIME=PRONY with lines g_i, k_i, tau_i (fit relaxation or creep data "
           "with `pneufem fit-material relaxation:FILE`)");
    if (m.prony) fail(loc, quoted(kw), "given twice for *MATERIAL " + m.name, "keep one");
    moduli(kw, loc, m);
    m.prony = InpMaterial::Prony{{}, {}, where(loc)};
    option_ = Option::Visco;
    keyword_ = quoted(kw);
    keyword_loc_ = loc;
    lines_in_option_ = 0;
  }

  void begin_values(const Keyword& kw, const Loc& loc, Option o, int count) {
    option_ = o;
    keyword_ = quoted(kw);
    keyword_loc_ = loc;
    expected_ = count;
    values_.clear();
    lines_in_option_ = 0;
  }

  void data_line(std::string_view text, const Loc& loc) {
    if (option_ == Option::None || option_ == Option::Skip || option_ == Option::Section) return;
    std::vector<std::string_view> fields;
    bool trailing = false;
    inp::split_fields(text, fields, trailing);
    ++lines_in_option_;
    if (option_ == Option::Visco) return prony_line(fields, loc);
    // Values run on over lines (Abaqus: 8 a line) until the law has them all; more is temperature data.
    if (static_cast<int>(values_.size()) >= expected_)
      fail(loc, keyword_, "more data lines than its " + std::to_string(expected_) + " value(s) (temperature-dependent data?)",
           "give the constants once, at the test temperature");
    for (std::size_t i = 0; i < fields.size(); ++i) {
      const std::string_view f = fields[i];
      if (static_cast<int>(values_.size()) >= expected_) {
        if (!f.empty())
          fail(loc, keyword_, "value " + std::to_string(values_.size() + 1) + " '" + std::string(f) + "' is more than its " +
                                  std::to_string(expected_) + " (a temperature? pneufem reads no temperature dependence)",
               "remove it");
        continue;
      }
      const std::optional<double> v = f.empty() ? std::optional<double>(0.0) : inp::parse_double(f);  // blank = 0
      if (!v) fail(loc, keyword_, "value " + std::to_string(values_.size() + 1) + " '" + std::string(f) + "' is not a number", "fix it");
      values_.push_back(*v);
    }
    // A line of 8 values continues on the next line; a shorter one ends the data (blank = 0).
    if (fields.size() < 8) values_.resize(static_cast<std::size_t>(std::max<int>(expected_, static_cast<int>(values_.size()))), 0.0);
  }

  void prony_line(const std::vector<std::string_view>& fields, const Loc& loc) {
    InpMaterial::Prony& p = *out_.materials[static_cast<std::size_t>(material_)].prony;
    double v[3] = {0, 0, 0};
    for (std::size_t i = 0; i < fields.size(); ++i) {
      const std::optional<double> x = fields[i].empty() ? std::optional<double>(0.0) : inp::parse_double(fields[i]);
      if (i >= 3) {
        if (x && *x == 0.0) continue;
        fail(loc, keyword_, "a Prony line has 3 values, g_i, k_i, tau_i", "remove the rest");
      }
      if (!x) fail(loc, keyword_, "value " + std::to_string(i + 1) + " '" + std::string(fields[i]) + "' is not a number", "fix it");
      v[i] = *x;
    }
    if (v[1] != 0.0)
      fail(loc, keyword_, "k_i = " + short_num(v[1]) + ": pneufem relaxes the isochoric response only (the volumetric "
                          "response of nearly incompressible silicone is elastic)",
           "set k_i = 0");
    if (!(v[0] >= 0.0 && v[0] < 1.0)) fail(loc, keyword_, "g_i = " + short_num(v[0]) + " is outside [0, 1)", "fix it");
    if (!(v[2] > 0.0)) fail(loc, keyword_, "tau_i = " + short_num(v[2]) + " is not > 0", "give the relaxation time in s");
    p.g.push_back(v[0]);
    p.tau_s.push_back(v[2]);
    if (p.g.size() > 3) fail(loc, keyword_, "more than 3 Prony terms", "pneufem's Prony series has 1 to 3 terms: merge the terms");
    double sum = 0.0;
    for (double g : p.g) sum += g;
    if (!(sum < 1.0))
      fail(loc, keyword_, "the g_i sum to " + short_num(sum) + " >= 1 (no long-term stiffness left)", "the g_i must sum to less than 1");
  }

  /// The deck's stress number in MPa: a mm deck's as written; an m deck's (Pa) the shortest decimal
  /// whose 1e6 multiple is the deck's number.
  double stress_MPa(double v) const {
    if (unit_ == "mm") return v;
    return shortest_preimage(v * 1e-6, v, [](double x) { return x * 1e6; });
  }

  /// The option's values are all read (at its end): checks and stores them.
  void end_option() {
    if (option_ == Option::None || option_ == Option::Skip || option_ == Option::Section) return;
    InpMaterial& m = out_.materials[static_cast<std::size_t>(material_)];
    if (lines_in_option_ == 0)
      fail(keyword_loc_, keyword_, "no data line", option_ == Option::Visco ? "give a line g_i, k_i, tau_i per Prony term"
                                                                            : "give its constants on the next line");
    if (option_ == Option::Visco) return;
    if (static_cast<int>(values_.size()) < expected_)
      fail(keyword_loc_, keyword_, std::to_string(values_.size()) + " of its " + std::to_string(expected_) + " values",
           "a line of 8 values continues on the next line; give the rest");
    const std::string at = where(keyword_loc_);
    switch (option_) {
      case Option::Hyper: return store_hyper(m);
      case Option::Elastic:
        m.constants = {{"E_MPa", stress_MPa(values_[0])}, {"nu", values_[1]}};
        return;
      case Option::Density:
        m.density = values_[0];
        m.density_where = at;
        return;
      case Option::Mullins:
        m.mullins = InpMaterial::Mullins{values_[0], stress_MPa(values_[1]), values_[2], at};
        return;
      default:
        return;
    }
  }

  void store_hyper(InpMaterial& m) {
    const std::size_t nc = law_.ogden_terms > 0 ? static_cast<std::size_t>(2 * law_.ogden_terms) : law_.keys.size();
    if (law_.ogden_terms > 0) {
      for (int i = 0; i < law_.ogden_terms; ++i) {
        m.mu_MPa.push_back(stress_MPa(values_[static_cast<std::size_t>(2 * i)]));
        m.alpha.push_back(values_[static_cast<std::size_t>(2 * i + 1)]);
        m.mu0_MPa += m.mu_MPa.back();
      }
    } else {
      for (std::size_t i = 0; i < nc; ++i) m.constants.emplace_back(law_.keys[i], stress_MPa(values_[i]));
      // REDUCED POLYNOMIAL, N=2 is a Yeoh law with C30 = 0.
      if (m.model == "yeoh" && m.constants.size() == 2) m.constants.emplace_back("C30_MPa", 0.0);
      double mu0 = 0.0;
      for (const auto& [k, v] : m.constants)
        if (k == "C10_MPa" || k == "C01_MPa") mu0 += v;
      m.mu0_MPa = 2.0 * mu0;
    }
    const double d1 = values_[nc];
    for (std::size_t i = nc + 1; i < values_.size(); ++i)
      if (values_[i] != 0.0)
        fail(keyword_loc_, keyword_, "D" + std::to_string(i - nc + 1) + " = " + short_num(values_[i]) +
                                         ": pneufem's volumetric energy is U = (J - 1)^2 / D1 alone",
             "set D2, D3, ... to 0");
    if (d1 < 0.0) fail(keyword_loc_, keyword_, "D1 = " + short_num(d1) + " < 0", "D1 = 2/K0 must be >= 0 (0: incompressible)");
    // D1 is 1/stress: a m deck's 1/Pa in 1/MPa is its 1e6 multiple.
    m.D1_per_MPa = unit_ == "mm" ? d1 : shortest_preimage(d1 * 1e6, d1, [](double x) { return x * 1e-6; });
  }

  void check_sections() const {
    for (const InpSection& s : out_.sections)
      if (!names_.count(inp::upper(s.material))) {
        std::string have;
        for (const InpMaterial& m : out_.materials) have += (have.empty() ? "" : ", ") + m.name;
        throw InputError(printable(s.where + ": *SOLID SECTION, ELSET=" + s.elset + ", MATERIAL=" + s.material +
                                   ": the deck defines no material " + s.material + " (it has: " +
                                   (have.empty() ? std::string("none") : have) +
                                   "); add its *MATERIAL, NAME=" + s.material + " block or fix the name"));
      }
    for (const InpMaterial& m : out_.materials)
      if (m.model.empty())
        throw InputError(printable(m.where + ": *MATERIAL, NAME=" + m.name +
                                   ": no elastic law; give it *HYPERELASTIC (YEOH, NEO HOOKE, MOONEY-RIVLIN, OGDEN) or *ELASTIC"));
  }

  inp::LineSource& lines_;
  std::string unit_;
  InpMaterials out_;
  std::map<std::string, std::size_t> names_;  // upper-case name -> index
  int material_ = -1;                         // the *MATERIAL whose options are being read
  Option option_ = Option::None;
  HyperLaw law_;
  std::string keyword_;
  Loc keyword_loc_;
  int expected_ = 0;
  int lines_in_option_ = 0;
  std::vector<double> values_;
};

}  // namespace

InpMaterials read_inp_materials(const std::string& path, const std::string& length_unit) {
  if (length_unit != "mm" && length_unit != "m")
    throw InputError(path + ": length unit '" + length_unit + "': use mm (N, MPa, tonne) or m (N, Pa, kg)");
  inp::LineSource lines(path);
  return MaterialReader(lines, length_unit).read();
}

double abaqus_d1(double K_over_mu, double mu0_MPa) { return 2.0 / (K_over_mu * mu0_MPa); }

double deck_density(double rho_kg_m3, const std::string& length_unit) {
  return length_unit == "mm" ? rho_kg_m3 * 1e-12 : rho_kg_m3;  // tonne/mm^3 = 1e12 kg/m^3
}

std::vector<double> abaqus_g(const std::vector<double>& gamma) {
  double sum = 0.0;
  for (double g : gamma) sum += g;
  std::vector<double> g;
  for (double x : gamma) g.push_back(x / (1.0 + sum));
  return g;
}

double k_over_mu_from_d1(double D1_per_MPa, double mu0_MPa) {
  return shortest_preimage(2.0 / (D1_per_MPa * mu0_MPa), D1_per_MPa, [&](double k) { return abaqus_d1(k, mu0_MPa); });
}

double density_from_deck(double rho_deck, const std::string& length_unit) {
  if (length_unit != "mm") return rho_deck;
  return shortest_preimage(rho_deck * 1e12, rho_deck, [&](double r) { return deck_density(r, length_unit); });
}

std::vector<double> gamma_from_abaqus_g(const std::vector<double>& g) {
  double sum = 0.0;
  for (double x : g) sum += x;
  std::vector<double> gamma;
  for (double x : g) gamma.push_back(x / (1.0 - sum));
  // Each term the shortest decimal that keeps its own g exact, the others as they stand; kept only if
  // the whole series then gives the deck's g exactly.
  std::vector<double> shortest = gamma;
  for (int pass = 0; pass < 2; ++pass)
    for (std::size_t i = 0; i < g.size(); ++i)
      shortest[i] = shortest_preimage(gamma[i], g[i], [&](double x) {
        std::vector<double> t = shortest;
        t[i] = x;
        return abaqus_g(t)[i];
      });
  return abaqus_g(shortest) == g ? shortest : gamma;
}

}  // namespace pneufem
