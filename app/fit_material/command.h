#pragma once
// `pneufem fit-material`: hyperelastic constants from lab tests (fit/fit.h does the math),
// written as the scene's [materials.NAME] block with the evidence beside it.
//
// Steps, each a function below: read the test files (test_data.h) -> fit the law (to the primary
// loading of cycles with --mullins, then r, m, beta; fit/inelastic.h) and Prony terms to a relaxation
// test -> check Drucker stability
// over a strain range (fit/stability.h; unstable within a test's own data is an error,
// elsewhere a warning, as Abaqus warns) -> write DIR/material.toml, residuals.csv, fit.svg (+ fit.csv,
// the plotted series) and fit.json.
#include <limits>
#include <string>
#include <vector>

#include <optional>

#include "fit/fit.h"
#include "fit/inelastic.h"
#include "fit/volumetric.h"
#include "fit/stability.h"

namespace pneufem {

struct FitMaterialOptions {
  std::vector<std::string> data;  ///< "uniaxial:FILE", ... (test_data.h: parse_test_spec), "deck:FILE.inp"
  std::string model = "yeoh";     ///< neo_hookean | mooney_rivlin | yeoh | ogden | ogden1..3
  std::string out_dir;
  std::string name = "silicone";  ///< the NAME of [materials.NAME]
  std::string weights = "relative";
  double max_strain = std::numeric_limits<double>::infinity();
  double K_over_mu = 100.0;       ///< not fitted (incompressible tests): written as given
  double density_kg_m3 = 1070.0;  ///< not fitted: written as given
  int max_evaluations = 5000;
  double stability_lo = -0.9, stability_hi = 9.0;  ///< nominal strain range of the Drucker check
  bool allow_unstable = false;    ///< write a fit that is unstable within its own data (warning instead of error)
  bool mullins = false;           ///< the tension tests are loading-unloading cycles: fit Ogden-Roxburgh too
  int prony_terms = 1;            ///< Prony terms fitted to a relaxation:FILE
  std::string moduli = "instantaneous";  ///< the viscoelastic block's convention (damage/viscoelastic.h)
  bool model_given = false;       ///< --model was given: it overrides the law of a deck's *HYPERELASTIC line
  std::string deck_material;      ///< which *MATERIAL of a deck:FILE (needed when it has several)
  std::string deck_length_unit = "mm";  ///< mm: the deck's stresses in MPa; m: in Pa
};

struct FitMaterialResult {
  std::vector<fit::TestCurve> tests;
  fit::FitOptions fit_options;
  fit::FitResult fit;
  fit::StabilityReport stability;
  std::optional<fit::MullinsFit> mullins;      ///< with --mullins: r, m, beta on the base `fit`
  std::vector<fit::RelaxationCurve> relaxation;
  std::optional<fit::PronyFit> prony;          ///< with a relaxation:FILE
  std::vector<fit::VolumetricCurve> volumetric;
  std::optional<fit::BulkFit> bulk;            ///< with a volumetric:FILE: K, written as K_over_mu
  std::vector<std::string> notes;     ///< from reading and fitting
  std::vector<std::string> warnings;  ///< stability
  std::string toml;                   ///< the material block as written
  std::string model;                  ///< the law fitted (options.model, or a deck's)
};

/// "yeoh", "neo_hookean", "mooney_rivlin", "ogden" (1 term, Abaqus's default), "ogden1".."ogden3" (also
/// "ogden[2]", "ogden_2"). Throws InputError listing them.
fit::FitOptions parse_model(const std::string& model, const std::string& weights);

/// The [materials.NAME] block of a fit, with comments that say what it came from.
std::string material_block(const FitMaterialOptions& o, const FitMaterialResult& r);

/// Unstable (Drucker) points inside a test's own data: an InputError naming the file and line of the
/// first, unless allow_unstable (then a warning). Limits elsewhere in the range become warnings.
void check_stability(const FitMaterialOptions& o, FitMaterialResult& r);

/// The whole command; writes the outputs and returns what it found (the CLI prints it).
FitMaterialResult run_fit_material(const FitMaterialOptions& o);

}  // namespace pneufem
