#include "app/fit_material/cli.h"

#include <cmath>
#include <cstdio>

#include "core/errors.h"
#include "core/number_text.h"

namespace pneufem {

namespace {

/// "LO:HI" of --stability-range.
void parse_range(const std::string& text, double& lo, double& hi) {
  const std::size_t c = text.find(':');
  try {
    if (c == std::string::npos) throw std::invalid_argument("no colon");
    std::size_t used = 0;
    lo = std::stod(text.substr(0, c), &used);
    if (used != c) throw std::invalid_argument("low");
    hi = std::stod(text.substr(c + 1), &used);
    if (used != text.size() - c - 1) throw std::invalid_argument("high");
  } catch (const std::exception&) {
    throw InputError("--stability-range " + text + ": write LO:HI in nominal strain, e.g. -0.9:9 (Abaqus's range)");
  }
}

}  // namespace

std::unique_ptr<FitMaterialCommand> add_fit_material_command(CLI::App& app) {
  auto c = std::make_unique<FitMaterialCommand>();
  FitMaterialOptions& o = c->options;
  CLI::App* f = c->cmd = app.add_subcommand(
      "fit-material",
      "Material constants from lab tests: a hyperelastic law from uniaxial, equibiaxial, planar (nominal stress vs "
      "nominal strain, as Abaqus's test data) and volumetric tests, Mullins from loading-unloading cycles, Prony terms "
      "from relaxation, by weighted least squares: DIR/material.toml (the scene's [materials.NAME] block), "
      "residuals.csv, fit.svg (+ fit.csv), fit.json, R^2 per test and the Drucker stability check");
  f->add_option("data", o.data,
                "Test files: uniaxial:FILE, biaxial:FILE, planar:FILE, volumetric:FILE, relaxation:FILE (or a FILE whose name says which), or deck:FILE.inp (its *HYPERELASTIC, TEST DATA INPUT); CSV whose header "
                "names the strain (strain, strain_percent or stretch) and the stress with its unit (stress_kPa, "
                "stress_MPa, stress_Pa, stress_psi)")
      ->required();
  f->add_option("--model", o.model, "Law: yeoh, neo_hookean, mooney_rivlin, ogden (1 term), ogden2 or ogden3")
      ->capture_default_str();
  f->add_option("--out", o.out_dir, "Output directory")->required();
  f->add_option("--name", o.name, "NAME of the [materials.NAME] block")->capture_default_str();
  f->add_option("--weights", o.weights,
                "relative: each residual over its measured stress (as Abaqus; floor 1 % of the test's largest "
                "stress); absolute: stress residuals")
      ->check(CLI::IsMember({"relative", "absolute"}))
      ->capture_default_str();
  f->add_option("--max-strain", o.max_strain, "Fit only points up to this nominal strain (e.g. the actuator's range)")
      ->check(CLI::PositiveNumber);
  f->add_option("--K-over-mu", o.K_over_mu, "Written as K_over_mu unless a volumetric:FILE fits it (tension tests are incompressible)")
      ->check(CLI::Range(1.0, 1e5))
      ->capture_default_str();
  f->add_option("--density", o.density_kg_m3, "Written as density_kg_m3 (kg/m^3, not fitted)")
      ->check(CLI::PositiveNumber)
      ->capture_default_str();
  f->add_option("--max-evaluations", o.max_evaluations, "Ogden, Mullins and Prony fits: objective evaluations per optimiser start")
      ->check(CLI::Range(1, 10000000))
      ->capture_default_str();
  f->add_option("--stability-range", c->stability_range,
                "Nominal strain range LO:HI of the Drucker stability check (Abaqus: -0.9:9)")
      ->capture_default_str();
  f->add_option("--deck-material", o.deck_material,
                "The *MATERIAL of a deck:FILE.inp to fit (needed when several have *HYPERELASTIC, TEST DATA INPUT)");
  f->add_option("--deck-length-unit", o.deck_length_unit,
                "A deck's consistent units: mm (stresses in MPa, as pneufem's decks) or m (Pa)")
      ->check(CLI::IsMember({"mm", "m"}))
      ->capture_default_str();
  f->add_flag("--mullins", o.mullins,
              "The tension tests are loading-unloading cycles in time order: fit the law to the primary loading and "
              "Ogden-Roxburgh r, m, beta to the rest ([materials.NAME.mullins])");
  f->add_option("--prony", o.prony_terms, "Prony terms (1-3) fitted to a relaxation:FILE ([materials.NAME.viscoelastic])")
      ->check(CLI::Range(1, 3))
      ->capture_default_str();
  f->add_option("--moduli", o.moduli,
                "The viscoelastic block's convention: instantaneous (the law is the response right after a step, as "
                "Abaqus) or long_term")
      ->check(CLI::IsMember({"instantaneous", "long_term"}))
      ->capture_default_str();
  f->add_flag("--allow-unstable", o.allow_unstable,
              "Write a fit that is unstable within its own data's strain range (a warning instead of an error)");
  return c;
}

int run_fit_material_command(FitMaterialCommand& c) {
  c.options.model_given = c.cmd->count("--model") > 0;
  parse_range(c.stability_range, c.options.stability_lo, c.options.stability_hi);
  const FitMaterialResult r = run_fit_material(c.options);
  for (const std::string& n : r.notes) std::printf("note: %s\n", n.c_str());
  const fit::FitOptions& fo = r.fit_options;
  std::printf("fit-material: %s, %s weights, %zu test(s)\n", fit::law_name(fo.law),
              fo.weighting == fit::Weighting::relative ? "relative" : "absolute", r.tests.size());
  for (std::size_t t = 0; t < r.tests.size(); ++t)
    std::printf("  %-9s %s: %zu points, R^2 %.4f, rms relative error %.2f %%\n", fit::mode_name(r.tests[t].mode),
                r.tests[t].source.c_str(), r.tests[t].points.size(), r.fit.tests[t].r2,
                100.0 * r.fit.tests[t].rms_relative);
  std::printf("constants (MPa):");
  const fit::Constants& k = r.fit.constants;
  static const char* kNames[3][3] = {{"C10", "", ""}, {"C10", "C01", ""}, {"C10", "C20", "C30"}};
  for (std::size_t i = 0; i < k.c.size(); ++i) {
    const std::string name = k.law == fit::Law::ogden ? "mu" + std::to_string(i + 1)
                                                      : kNames[static_cast<int>(k.law)][i];
    std::printf("%s %s %s", i ? "," : "", name.c_str(), short_num(k.c[i] * 1e-6).c_str());
    if (i < r.fit.std_error.size()) std::printf(" +- %s", short_num(r.fit.std_error[i] * 1e-6).c_str());
    if (k.law == fit::Law::ogden) std::printf(" (alpha %s)", short_num(k.alpha[i]).c_str());
  }
  std::printf("; mu0 %s MPa\n", short_num(k.mu0() * 1e-6).c_str());
  if (r.mullins)
    std::printf("Mullins (Ogden-Roxburgh, %d unloading/reloading points): r %s, m %s MPa, beta %s; R^2 with it %s\n",
                r.mullins->unloading_points, short_num(r.mullins->params.r).c_str(),
                short_num(r.mullins->params.m_Pa * 1e-6).c_str(), short_num(r.mullins->params.beta).c_str(),
                short_num(r.mullins->r2.front()).c_str());
  if (r.bulk)
    std::printf("bulk modulus (%s): K %s +- %s MPa, K/mu0 %s, R^2 %.4f\n", r.volumetric.front().source.c_str(),
                short_num(r.bulk->K_Pa * 1e-6).c_str(), short_num(r.bulk->std_error_Pa * 1e-6).c_str(),
                short_num(r.bulk->K_Pa / k.mu0()).c_str(), r.bulk->r2);
  if (r.prony) {
    std::printf("Prony (%s, %zu points): ", r.relaxation.front().source.c_str(), r.relaxation.front().points.size());
    for (std::size_t i = 0; i < r.prony->g.size(); ++i)
      std::printf("%sg %s tau %s s", i ? ", " : "", short_num(r.prony->g[i]).c_str(), short_num(r.prony->tau_s[i]).c_str());
    std::printf("; R^2 %.4f\n", r.prony->r2);
  }
  for (const std::string& w : r.warnings) std::printf("warning: %s\n", w.c_str());
  if (r.stability.stable())
    std::printf("Drucker stability: stable for nominal strains %s to %s in all six paths\n",
                short_num(r.stability.strain_lo).c_str(), short_num(r.stability.strain_hi).c_str());
  std::printf("wrote %s/material.toml ([materials.%s]), residuals.csv, fit.svg (+ fit.csv)%s, fit.json\n",
              c.options.out_dir.c_str(), c.options.name.c_str(), r.prony ? ", relaxation.svg (+ .csv)" : "");
  return 0;
}

}  // namespace pneufem
