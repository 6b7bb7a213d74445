#pragma once
// Hyperelastic constants from homogeneous test data (uniaxial, equibiaxial, planar tension, alone
// or together) by weighted least squares, as Abaqus's *HYPERELASTIC, TEST DATA INPUT fits them:
//   minimise  E(c, alpha) = sum over tests t, points i of  w_ti^2 (P(c, alpha; mode_t, l_ti) - P_ti)^2,
// P from incompressible.h. Weights:
//   relative (default, as Abaqus): w = 1 / max(|P_ti|, 0.01 max_i |P_ti|) - the relative error, with a
//            floor at 1 % of the test's largest stress so that a point near zero stress (the origin, a
//            load-cell offset) does not dominate;
//   absolute: w = 1 / (1 MPa) - the stress error itself, so the stiffest test and the largest strains
//            weigh most.
//
// Method. Every law is linear in its moduli c at fixed exponents (incompressible.h), so
//  * neo-Hookean, Mooney-Rivlin and Yeoh are a linear least-squares problem, solved exactly by a
//    column-pivoting QR (no iterations, no start values, a unique answer when the points determine
//    the constants); the standard errors are those of linear regression, s sqrt(diag((A^T A)^-1)),
//    s^2 = E / (n - p);
//  * Ogden-N is separable (Golub & Pereyra 1973, "variable projection"): for given alpha the best
//    mu >= 0 (Ogden's stability condition mu_i alpha_i > 0 of the 1972 paper, mu_i > 0 in the Abaqus
//    convention, which materials/ogden.h enforces) is a non-negative least-squares problem in N <= 3
//    unknowns, solved exactly by trying every active set; the N exponents are then found by NLopt's
//    BOBYQA (bounded, derivative-free: the projected objective has kinks where the active set
//    changes, which a gradient method or Levenberg-Marquardt would mistake), started from every
//    combination of N distinct values of {-4, -2, -1, 0.5, 1, 2, 3, 5, 8} (Ogden fits have several
//    minima), alpha bounded by |alpha| <= alpha_bound. A term whose mu comes out 0 is dropped.
// R^2 per test is 1 - SS_res / SS_tot of the stresses themselves (unweighted), as Abaqus and
// spreadsheets print it, so it does not depend on the weighting.
#include <string>
#include <vector>

#include "fit/incompressible.h"

namespace pneufem::fit {

enum class Weighting { relative, absolute };

struct TestPoint {
  double stretch;  ///< l = 1 + nominal strain
  double P_Pa;     ///< nominal stress
  int line;        ///< line in its file (for messages), 0 if none
};

struct TestCurve {
  TestMode mode;
  std::string source;  ///< the file (for messages and outputs)
  std::vector<TestPoint> points;
};

struct FitOptions {
  Law law = Law::yeoh;
  int ogden_terms = 1;  ///< 1..3
  Weighting weighting = Weighting::relative;
  int max_evaluations = 5000;  ///< ogden: objective evaluations per BOBYQA start
  double alpha_bound = 20.0;   ///< ogden: |alpha_i| <= this
};

/// One test's share of a fit.
struct TestFit {
  std::vector<double> model_P_Pa;  ///< the fitted law at each point
  std::vector<double> weight;      ///< w_ti (1/Pa)
  double r2 = 0.0;                 ///< 1 - SS_res/SS_tot of the stresses
  double rms_relative = 0.0;       ///< rms of (P_model - P)/max(|P|, 1 % of the test's largest)
  double objective = 0.0;          ///< this test's part of E
};

struct FitResult {
  Constants constants;
  std::vector<double> std_error;  ///< of each modulus (Pa); linear laws only (empty for ogden)
  double objective = 0.0;         ///< E at the fit
  std::vector<TestFit> tests;     ///< one per TestCurve, in order
  int evaluations = 0;            ///< objective evaluations (ogden; 1 for the linear laws)
  std::vector<std::string> notes; ///< dropped terms, exponents at their bound
};

/// Points (away from the origin l = 1) the fit needs: the number of its constants.
int constant_count(const FitOptions& o);

/// The weights of one test (see the top of this file).
std::vector<double> point_weights(const TestCurve& t, Weighting w);
/// E of `k` on `tests` and each test's share (the same E the fit minimises).
std::vector<TestFit> evaluate_fit(const std::vector<TestCurve>& tests, const Constants& k, Weighting w);
double objective(const std::vector<TestCurve>& tests, const Constants& k, Weighting w);

/// The fit. Throws InputError naming the files: too few points for the law's constants, points that
/// do not determine them, a fit that does not converge within max_evaluations, constants the law
/// rejects (e.g. yeoh C10 <= 0: the data are not rubber-like at small strain).
FitResult fit_hyperelastic(const std::vector<TestCurve>& tests, const FitOptions& o);

}  // namespace pneufem::fit
