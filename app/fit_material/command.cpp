#include "app/fit_material/command.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "app/fit_material/deck_test_data.h"
#include "app/fit_material/test_data.h"
#include "core/atomic_file.h"
#include "core/errors.h"
#include "core/json_writer.h"
#include "core/number_text.h"
#include "core/output_dir.h"
#include "core/version.h"
#include "damage/viscoelastic.h"
#include "viz/svg_plot.h"

namespace pneufem {

namespace {

using fit::Law;
using fit::TestMode;

std::string pct(double v) {
  char b[32];
  std::snprintf(b, sizeof b, "%.2f %%", 100.0 * v);
  return b;
}

std::string fixed(double v, int digits) {
  char b[32];
  std::snprintf(b, sizeof b, "%.*f", digits, v);
  return b;
}

std::string weighting_text(fit::Weighting w) {
  return w == fit::Weighting::relative
             ? "relative weights (each residual over its measured stress, floored at 1 % of the test's largest)"
             : "absolute weights (stress residuals in MPa)";
}

std::string model_label(const fit::FitOptions& o) {
  return std::string(law_name(o.law)) + (o.law == Law::ogden ? std::to_string(o.ogden_terms) : "");
}

/// The names of the moduli in the scene's keys (ogden: one list).
std::vector<std::string> modulus_keys(Law law) {
  switch (law) {
    case Law::neo_hookean: return {"C10_MPa"};
    case Law::mooney_rivlin: return {"C10_MPa", "C01_MPa"};
    case Law::yeoh: return {"C10_MPa", "C20_MPa", "C30_MPa"};
    case Law::ogden: return {"mu_MPa"};
  }
  return {};
}

std::string toml_list(const std::vector<double>& v, double scale) {
  std::string s = "[";
  for (std::size_t i = 0; i < v.size(); ++i) s += (i ? ", " : "") + json::num(v[i] * scale);
  return s + "]";
}

std::string stability_text(const fit::StabilityLimit& s) {
  return std::string(fit::mode_name(s.mode)) + (s.tension ? " tension" : " compression") + " at nominal strain " +
         short_num(s.strain);
}

// --- the steps ----------------------------------------------------------------------------------

/// The test data of one *MATERIAL of a deck (deck_test_data.h); its law unless --model was given.
void read_deck(const FitMaterialOptions& o, const std::string& path, FitMaterialResult& r) {
  const std::vector<DeckTestData> all = read_deck_test_data(path, o.deck_length_unit);
  std::string names;
  for (const DeckTestData& d : all) names += (names.empty() ? "" : ", ") + d.material;
  if (all.empty())
    throw InputError(path + ": no *HYPERELASTIC, TEST DATA INPUT with test data in this deck");
  const DeckTestData* pick = nullptr;
  for (const DeckTestData& d : all)
    if (o.deck_material.empty() ? all.size() == 1 : d.material == o.deck_material) pick = &d;
  if (!pick)
    throw InputError(path + ": " + (o.deck_material.empty() ? "several materials have test data (" + names +
                                                                  "); choose one with --deck-material NAME"
                                                            : "no material '" + o.deck_material + "' with test data; it has " + names));
  if (pick->tests.empty()) throw InputError(pick->where + ": *MATERIAL " + pick->material + " has no tension test data");
  for (fit::TestCurve t : pick->tests) {  // --max-strain as for CSV files
    const std::size_t n = t.points.size();
    std::erase_if(t.points, [&](const fit::TestPoint& p) { return p.stretch - 1.0 > o.max_strain; });
    if (t.points.size() < n)
      r.notes.push_back(t.source + ": " + std::to_string(n - t.points.size()) + " point(s) above --max-strain " +
                        short_num(o.max_strain) + " left out");
    r.tests.push_back(std::move(t));
  }
  for (const fit::VolumetricCurve& v : pick->volumetric) r.volumetric.push_back(v);
  if (!o.model_given) r.model = pick->law;
  r.notes.push_back(path + ": test data of *MATERIAL " + pick->material + " (" + std::to_string(pick->tests.size()) +
                    " tension, " + std::to_string(pick->volumetric.size()) + " volumetric block(s); stresses in " +
                    (o.deck_length_unit == "mm" ? "MPa" : "Pa") + ", --deck-length-unit " + o.deck_length_unit +
                    "), law " + r.model + (o.model_given ? " (--model)" : " (its *HYPERELASTIC line, " + pick->where + ")"));
}

void read_tests(const FitMaterialOptions& o, FitMaterialResult& r) {
  if (o.data.empty()) throw InputError("fit-material: give at least one DATA file (uniaxial:FILE, biaxial:FILE, planar:FILE)");
  if (o.mullins && std::isfinite(o.max_strain))
    throw InputError("--max-strain cannot cut loading-unloading cycles (the Mullins law needs each cycle's peak); "
                     "leave it out with --mullins");
  for (const std::string& arg : o.data) {
    if (arg.rfind("deck:", 0) == 0 || (arg.size() > 4 && arg.substr(arg.size() - 4) == ".inp")) {
      read_deck(o, arg.rfind("deck:", 0) == 0 ? arg.substr(5) : arg, r);
      continue;
    }
    const TestFileSpec spec = parse_test_spec(arg);
    if (spec.kind == TestFileSpec::Kind::relaxation) r.relaxation.push_back(read_relaxation_csv(spec.path, r.notes));
    else if (spec.kind == TestFileSpec::Kind::volumetric) r.volumetric.push_back(read_volumetric_csv(spec.path, r.notes));
    else r.tests.push_back(read_test_csv(spec.path, spec.mode, r.notes, o.max_strain, o.mullins));
  }
  if (r.tests.empty())
    throw InputError("fit-material: no tension test among the DATA files; give the law's uniaxial:, biaxial: or "
                     "planar: test (a relaxation test only adds Prony terms to it)");
  if (r.relaxation.size() > 1)
    throw InputError("fit-material: " + std::to_string(r.relaxation.size()) + " relaxation files; give one");
  if (r.volumetric.size() > 1)
    throw InputError("fit-material: " + std::to_string(r.volumetric.size()) + " volumetric files; give one");
}

/// The model's stresses replace the base law's in each test's share of the fit (with --mullins).
void use_mullins_model(FitMaterialResult& r) {
  r.mullins = fit::fit_mullins(r.tests, r.fit.constants, r.fit_options.weighting, r.fit_options.max_evaluations);
  for (std::size_t t = 0; t < r.tests.size(); ++t) {
    fit::TestFit& f = r.fit.tests[t];
    f.model_P_Pa = r.mullins->model_P_Pa[t];
    f.r2 = r.mullins->r2[t];
    const std::vector<double> rel = fit::point_weights(r.tests[t], fit::Weighting::relative);
    double s = 0.0;
    for (std::size_t j = 0; j < rel.size(); ++j) s += std::pow((f.model_P_Pa[j] - r.tests[t].points[j].P_Pa) * rel[j], 2);
    f.rms_relative = std::sqrt(s / static_cast<double>(rel.size()));
  }
}

void write_residuals(const std::string& dir, const FitMaterialResult& r) {
  std::string s = "test,mode,file,line,stretch,nominal_strain,stress_MPa,fitted_MPa,residual_MPa,relative_residual,weight_per_MPa\n";
  for (std::size_t t = 0; t < r.tests.size(); ++t) {
    const fit::TestCurve& c = r.tests[t];
    const std::vector<double> rel = fit::point_weights(c, fit::Weighting::relative);
    for (std::size_t j = 0; j < c.points.size(); ++j) {
      const fit::TestPoint& p = c.points[j];
      const double Pm = r.fit.tests[t].model_P_Pa[j];
      s += std::to_string(t + 1) + "," + fit::mode_name(c.mode) + "," + svg::csv_field(c.source) + "," +
           std::to_string(p.line) + "," + json::num(p.stretch) + "," + json::num(p.stretch - 1.0) + "," +
           json::num(p.P_Pa * 1e-6) + "," + json::num(Pm * 1e-6) + "," + json::num((Pm - p.P_Pa) * 1e-6) + "," +
           json::num((Pm - p.P_Pa) * rel[j]) + "," + json::num(r.fit.tests[t].weight[j] * 1e6) + "\n";
    }
  }
  if (r.bulk) {  // volumetric rows: stretch = J, stress = pressure
    const fit::VolumetricCurve& v = r.volumetric.front();
    for (std::size_t j = 0; j < v.points.size(); ++j) {
      const double p = v.points[j].p_Pa, pm = r.bulk->model_p_Pa[j];
      s += std::to_string(r.tests.size() + 1) + ",volumetric," + svg::csv_field(v.source) + "," +
           std::to_string(v.points[j].line) + "," + json::num(v.points[j].J) + ",," + json::num(p * 1e-6) + "," +
           json::num(pm * 1e-6) + "," + json::num((pm - p) * 1e-6) + ",,\n";
    }
  }
  write_file_atomic(dir + "/residuals.csv", s);
}

/// Top: nominal stress against nominal strain, data (markers) and the fit (line, over each test's
/// strain range) per test. Bottom: relative residuals.
void write_figure(const std::string& dir, const FitMaterialResult& r) {
  svg::Figure fig(svg::kColumnWidthPx, 560, 2, 1);
  fig.title(model_label(r.fit_options) + " fit");
  svg::Axes& top = fig.axes(0, 0);
  svg::Axes& bottom = fig.axes(1, 0);
  top.title("nominal stress").xlabel("nominal strain").ylabel("nominal stress (MPa)");
  bottom.title("relative residual").xlabel("nominal strain").ylabel("(fit - data) / data");
  for (std::size_t t = 0; t < r.tests.size(); ++t) {
    const fit::TestCurve& c = r.tests[t];
    const std::string label = std::string(fit::mode_name(c.mode)) + " (test " + std::to_string(t + 1) + ")";
    std::vector<double> x, y, res;
    const std::vector<double> rel = fit::point_weights(c, fit::Weighting::relative);
    double hi = 0.0;
    for (std::size_t j = 0; j < c.points.size(); ++j) {
      x.push_back(c.points[j].stretch - 1.0);
      y.push_back(c.points[j].P_Pa * 1e-6);
      res.push_back((r.fit.tests[t].model_P_Pa[j] - c.points[j].P_Pa) * rel[j]);
      hi = std::max(hi, x.back());
    }
    svg::Style dots;
    dots.color = svg::palette_color(t);
    dots.marker = svg::Marker::Circle;
    dots.marker_size = 2.0;
    dots.line_width = 0.0;
    top.scatter(x, y, label + " data", dots);
    std::vector<double> xf, yf;
    if (r.mullins) {  // path-dependent: the model along the test's own path
      xf = x;
      for (double P : r.fit.tests[t].model_P_Pa) yf.push_back(P * 1e-6);
    } else {
      for (int k = 0; k <= 200; ++k) {
        const double e = hi * k / 200.0;
        xf.push_back(e);
        yf.push_back(fit::nominal_stress(r.fit.constants, c.mode, 1.0 + e) * 1e-6);
      }
    }
    svg::Style line;
    line.color = svg::palette_color(t);
    top.line(xf, yf, label + " fit", line);
    bottom.scatter(x, res, label, dots);
  }
  fig.save(dir + "/fit.svg");
  if (!r.prony) return;
  svg::Figure rel(svg::kColumnWidthPx, 320);
  const fit::RelaxationCurve& c = r.relaxation.front();
  svg::Axes& ax = rel.axes();
  ax.title("relaxation").xlabel("time since the step (s)").ylabel("g_R = stress / stress at 0+").xlog();
  std::vector<double> t, g, tf, gf;
  for (const fit::RelaxationPoint& p : c.points)
    if (p.t_s > 0.0) t.push_back(p.t_s), g.push_back(p.g);
  svg::Style dots;
  dots.marker = svg::Marker::Circle;
  dots.marker_size = 2.0;
  dots.line_width = 0.0;
  ax.scatter(t, g, "data", dots);
  for (int k = 0; k <= 200 && !t.empty(); ++k) {
    tf.push_back(t.front() * std::pow(t.back() / t.front(), k / 200.0));
    gf.push_back(fit::prony_relaxation(r.prony->g, r.prony->tau_s, tf.back()));
  }
  ax.line(tf, gf, std::to_string(r.prony->g.size()) + "-term Prony fit");
  rel.save(dir + "/relaxation.svg");
}

void write_json(const std::string& dir, const FitMaterialOptions& o, const FitMaterialResult& r) {
  const fit::Constants& k = r.fit.constants;
  json::Object constants;
  constants.add_str("model", fit::law_name(k.law));
  const std::vector<std::string> keys = modulus_keys(k.law);
  if (k.law == Law::ogden) {
    constants.add("mu_MPa", toml_list(k.c, 1e-6));
    constants.add("alpha", json::array(k.alpha));
  } else {
    for (std::size_t i = 0; i < keys.size(); ++i) constants.add(keys[i], k.c[i] * 1e-6);
    std::vector<double> se;
    for (double v : r.fit.std_error) se.push_back(v * 1e-6);
    constants.add("std_error_MPa", json::array(se));
  }
  constants.add("mu0_MPa", k.mu0() * 1e-6);
  std::string tests = "[";
  for (std::size_t t = 0; t < r.tests.size(); ++t) {
    json::Object e;
    e.add_str("mode", fit::mode_name(r.tests[t].mode)).add_str("file", r.tests[t].source);
    e.add("points", json::num(static_cast<double>(r.tests[t].points.size())));
    e.add("r2", r.fit.tests[t].r2).add("rms_relative_error", r.fit.tests[t].rms_relative);
    e.add("objective", r.fit.tests[t].objective);
    tests += (t ? ", " : "") + e.str(4);
  }
  tests += "]";
  std::string limits = "[";
  for (std::size_t i = 0; i < r.stability.limits.size(); ++i) {
    const fit::StabilityLimit& s = r.stability.limits[i];
    json::Object e;
    e.add_str("mode", fit::mode_name(s.mode)).add_str("path", s.tension ? "tension" : "compression");
    e.add("unstable_from_strain", s.strain);
    limits += (i ? ", " : "") + e.str(6);
  }
  limits += "]";
  json::Object stab;
  stab.add("strain_range", json::array({r.stability.strain_lo, r.stability.strain_hi}));
  stab.add("stable", r.stability.stable() ? "true" : "false").add("limits", limits);
  std::string notes = "[";
  for (std::size_t i = 0; i < r.notes.size(); ++i) notes += (i ? ", " : "") + json::quote(r.notes[i]);
  notes += "]";
  json::Object root;
  root.add_str("version", version_string()).add_str("model", model_label(r.fit_options));
  root.add_str("weights", o.weights).add_str("weighting", weighting_text(r.fit_options.weighting));
  root.add("constants", constants.str(2)).add("objective", r.fit.objective);
  root.add("evaluations", json::num(r.fit.evaluations)).add("tests", tests);
  root.add("drucker_stability", stab.str(2)).add("notes", notes);
  if (r.mullins) {
    json::Object m;
    m.add("r", r.mullins->params.r).add("m_MPa", r.mullins->params.m_Pa * 1e-6).add("beta", r.mullins->params.beta);
    m.add("objective", r.mullins->objective).add("unloading_points", json::num(r.mullins->unloading_points));
    m.add("r2", json::array(r.mullins->r2));
    root.add("mullins", m.str(2));
  }
  if (r.bulk) {
    json::Object b;
    b.add("K_MPa", r.bulk->K_Pa * 1e-6).add("std_error_MPa", r.bulk->std_error_Pa * 1e-6);
    b.add("K_over_mu", r.bulk->K_Pa / r.fit.constants.mu0()).add("r2", r.bulk->r2);
    b.add_str("file", r.volumetric.front().source);
    root.add("volumetric", b.str(2));
  }
  if (r.prony) {
    json::Object p;
    p.add("g", json::array(r.prony->g)).add("tau_s", json::array(r.prony->tau_s));
    p.add("objective", r.prony->objective).add("r2", r.prony->r2).add_str("file", r.relaxation.front().source);
    root.add("prony", p.str(2));
  }
  write_file_atomic(dir + "/fit.json", root.str() + "\n");
}

}  // namespace

fit::FitOptions parse_model(const std::string& model, const std::string& weights) {
  fit::FitOptions o;
  if (weights == "relative") o.weighting = fit::Weighting::relative;
  else if (weights == "absolute") o.weighting = fit::Weighting::absolute;
  else throw InputError("--weights " + weights + ": use relative (the default, as Abaqus) or absolute");
  std::string m = model;
  m.erase(std::remove_if(m.begin(), m.end(), [](char c) { return c == '[' || c == ']' || c == '_' || c == ' '; }),
          m.end());
  if (model == "yeoh") o.law = Law::yeoh;
  else if (model == "neo_hookean") o.law = Law::neo_hookean;
  else if (model == "mooney_rivlin") o.law = Law::mooney_rivlin;
  else if (m == "ogden") o.law = Law::ogden, o.ogden_terms = 1;
  else if (m.size() == 6 && m.rfind("ogden", 0) == 0 && m[5] >= '1' && m[5] <= '3')
    o.law = Law::ogden, o.ogden_terms = m[5] - '0';
  else
    throw InputError("--model " + model + ": use yeoh, neo_hookean, mooney_rivlin, ogden (1 term), ogden2 or ogden3");
  return o;
}

std::string material_block(const FitMaterialOptions& o, const FitMaterialResult& r) {
  const fit::Constants& k = r.fit.constants;
  std::string s = "# " + model_label(r.fit_options) + " fitted by pneufem fit-material (" + version_string() + "), " +
                  weighting_text(r.fit_options.weighting) + ".\n";
  for (std::size_t t = 0; t < r.tests.size(); ++t)
    s += "#   " + std::string(fit::mode_name(r.tests[t].mode)) + " " + r.tests[t].source + ": " +
         std::to_string(r.tests[t].points.size()) + " points, R^2 " + fixed(r.fit.tests[t].r2, 4) +
         ", rms relative error " + pct(r.fit.tests[t].rms_relative) + "\n";
  s += "# Drucker stability, nominal strain " + short_num(r.stability.strain_lo) + " to " +
       short_num(r.stability.strain_hi) + ": ";
  if (r.stability.stable()) {
    s += "stable on all six paths\n";
  } else {
    std::string lim;
    for (const fit::StabilityLimit& l : r.stability.limits)
      if (!std::isnan(l.strain)) lim += (lim.empty() ? "" : "; ") + stability_text(l);
    s += "UNSTABLE from " + lim + "\n";
  }
  s += r.bulk ? "# density_kg_m3 is not fitted: set it for your material.\n"
              : "# K_over_mu and density_kg_m3 are not fitted (incompressible tests): set them for your material.\n";
  s += "[materials." + o.name + "]\n";
  s += "model = \"" + std::string(fit::law_name(k.law)) + "\"\n";
  if (k.law == Law::ogden) {
    s += "mu_MPa = " + toml_list(k.c, 1e-6) + "\n";
    s += "alpha = " + toml_list(k.alpha, 1.0) + "\n";
  } else {
    const std::vector<std::string> keys = modulus_keys(k.law);
    for (std::size_t i = 0; i < keys.size(); ++i) s += keys[i] + " = " + json::num(k.c[i] * 1e-6) + "\n";
  }
  if (r.bulk)
    s += "K_over_mu = " + json::num(r.bulk->K_Pa / k.mu0()) + "  # fitted: K = " + short_num(r.bulk->K_Pa * 1e-6) +
         " MPa (D1 = " + short_num(2.0 / (r.bulk->K_Pa * 1e-6)) + " /MPa) from " + r.volumetric.front().source + "\n";
  else
    s += "K_over_mu = " + json::num(o.K_over_mu) + "\n";
  s += "density_kg_m3 = " + json::num(o.density_kg_m3) + "\n";
  if (r.mullins) {
    const MullinsParams& p = r.mullins->params;
    s += "\n# Ogden-Roxburgh Mullins softening fitted to " + std::to_string(r.mullins->unloading_points) +
         " unloading/reloading points (the law above: the primary loading)\n";
    s += "[materials." + o.name + ".mullins]\nenabled = true\n";
    s += "r = " + json::num(p.r) + "\nm_MPa = " + json::num(p.m_Pa * 1e-6) + "\nbeta = " + json::num(p.beta) + "\n";
  }
  if (r.prony) {
    const ViscoParams v = prony_from_abaqus(r.prony->g, r.prony->tau_s,
                                                 o.moduli == "long_term" ? ViscoModuli::long_term : ViscoModuli::instantaneous);
    s += "\n# Prony terms fitted to " + r.relaxation.front().source + " (R^2 " + fixed(r.prony->r2, 4) +
         "); Abaqus g_i = " + toml_list(r.prony->g, 1.0) + ", gamma_i = g_i / (1 - sum g).\n";
    s += "# moduli = \"" + o.moduli + "\": the law above is the " +
         (o.moduli == "long_term" ? std::string("relaxed (long-term)") : std::string("instantaneous")) +
         " response (damage/viscoelastic.h)\n";
    s += "[materials." + o.name + ".viscoelastic]\nenabled = true\nmoduli = \"" + o.moduli + "\"\n";
    s += "gamma = " + toml_list(v.gamma, 1.0) + "\ntau_s = " + toml_list(v.tau_s, 1.0) + "\n";
  }
  return s;
}

void check_stability(const FitMaterialOptions& o, FitMaterialResult& r) {
  r.stability = fit::drucker_stability(r.fit.constants, o.stability_lo, o.stability_hi);
  for (const fit::StabilityLimit& l : r.stability.limits)
    if (!std::isnan(l.strain))
      r.warnings.push_back("the fit is unstable (Drucker) in " + stability_text(l) + " and beyond");
  for (const fit::TestCurve& c : r.tests)
    for (const fit::TestPoint& p : c.points) {
      if (fit::drucker_stable(r.fit.constants, fit::mode_stretches(c.mode, p.stretch))) continue;
      const std::string msg = c.source + ":" + std::to_string(p.line) + ": the fitted " +
                              model_label(r.fit_options) + " is unstable (Drucker) at this test's own nominal strain " +
                              short_num(p.stretch - 1.0) +
                              ": a simulation would soften without bound there. Fit a narrower range "
                              "(--max-strain), another law (ogden keeps mu_i > 0 and is stable), or more test "
                              "modes together; --allow-unstable writes it anyway";
      if (!o.allow_unstable) throw InputError(msg);
      r.warnings.push_back(msg);
      return;
    }
}

namespace {

/// Options that are wrong whatever the files hold, before any file is read.
void check_options(const FitMaterialOptions& o) {
  parse_model(o.model, o.weights);
  if (!(o.K_over_mu >= 1.0)) throw InputError("--K-over-mu must be >= 1 (silicone: 100-1000), got " + short_num(o.K_over_mu));
  if (!(o.stability_lo > -1.0 && o.stability_lo <= 0.0 && o.stability_hi >= 0.0))
    throw InputError("--stability-range: the low end must lie in (-1, 0] and the high end be >= 0");
  if (o.moduli != "instantaneous" && o.moduli != "long_term")
    throw InputError("--moduli " + o.moduli + ": use instantaneous (Abaqus's default) or long_term");
}

/// The law: on all tension points, or with --mullins on the primary loading and then r, m, beta.
void fit_law(const FitMaterialOptions& o, FitMaterialResult& r) {
  r.fit_options = parse_model(r.model, o.weights);
  r.fit_options.max_evaluations = o.max_evaluations;
  if (!o.mullins) {
    r.fit = fit::fit_hyperelastic(r.tests, r.fit_options);
    return;
  }
  std::vector<fit::TestCurve> primary;
  for (const fit::TestCurve& t : r.tests) primary.push_back(fit::primary_loading(t));
  r.fit = fit::fit_hyperelastic(primary, r.fit_options);
  r.fit.tests = fit::evaluate_fit(r.tests, r.fit.constants, r.fit_options.weighting);
  use_mullins_model(r);
}

/// K from a volumetric test, within the scenes' range of K_over_mu.
void fit_volumetric(FitMaterialResult& r) {
  if (r.volumetric.empty()) return;
  r.bulk = fit::fit_bulk_modulus(r.volumetric.front(), r.fit_options.weighting);
  const double ratio = r.bulk->K_Pa / r.fit.constants.mu0();
  if (!(ratio >= 1.0 && ratio <= 1e5))
    throw InputError(r.volumetric.front().source + ": the fitted bulk modulus K = " + short_num(r.bulk->K_Pa * 1e-6) +
                     " MPa is " + short_num(ratio) + " times the law's mu0; scenes take K_over_mu in [1, 1e5] "
                     "(silicone: 100-1000). Check the pressure and volume-ratio units");
}

void fit_relaxation(const FitMaterialOptions& o, FitMaterialResult& r) {
  if (r.relaxation.empty()) return;
  r.prony = fit::fit_prony(r.relaxation.front(), o.prony_terms, o.max_evaluations);
  for (const std::string& n : r.prony->notes) r.notes.push_back(n);
}

void write_outputs(const FitMaterialOptions& o, FitMaterialResult& r) {
  r.toml = material_block(o, r);
  prepare_output_dir(o.out_dir, "--out");
  write_file_atomic(o.out_dir + "/material.toml", r.toml);
  write_residuals(o.out_dir, r);
  write_figure(o.out_dir, r);
  write_json(o.out_dir, o, r);
}

}  // namespace

FitMaterialResult run_fit_material(const FitMaterialOptions& o) {
  check_output_dir(o.out_dir, "--out");
  check_options(o);
  FitMaterialResult r;
  r.model = o.model;
  read_tests(o, r);  // a deck's *HYPERELASTIC line may set r.model
  fit_law(o, r);
  fit_volumetric(r);
  fit_relaxation(o, r);
  for (const std::string& n : r.fit.notes) r.notes.push_back(n);
  check_stability(o, r);
  write_outputs(o, r);
  return r;
}

}  // namespace pneufem
