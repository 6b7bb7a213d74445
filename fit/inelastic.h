#pragma once
// Constants of the inelastic effects of damage/ from test data, with the same laws the simulation
// runs (damage/mullins.h, damage/viscoelastic.h):
//
// Mullins (Ogden & Roxburgh 1999, with Abaqus's beta) from loading-unloading curves of one homogeneous
// test mode, in time order. Along the curve the isochoric energy W = W(l) of the base law
// (incompressible.h: strain_energy) has the running maximum W_max, and
//   P = eta P0(l),   eta = 1 - (1/r) erf((W_max - W) / (m + beta W_max))    (damage/mullins.h),
// where P0 is the base law's nominal stress. The base is fitted first to the primary (virgin) loading
// points - those at or beyond every earlier stretch, where eta = 1 - and r, m, beta then to all points
// (the primary ones do not depend on them) by weighted least squares (fit.h's weights), with NLopt's
// BOBYQA over x = (ln(r - 1), m / W_ref, beta), W_ref the largest W of the data, within
// r - 1 in [1e-3, 100], m / W_ref in [1e-6, 10], beta in [0, 10], from 8 starts. Since eta multiplies
// the stress of every mode alike, the 1-D model is the 3D decorator at the homogeneous state exactly
// (tests/fit/test_inelastic.cpp).
//
// Prony terms from a relaxation test: a step strain held, the stress normalised by its value at
// t = 0+ (Abaqus's *VISCOELASTIC, TIME = RELAXATION TEST DATA, g_R(t)):
//   g_R(t) = 1 - sum_i g_i (1 - exp(-t / tau_i)),   g_i >= 0, sum g_i < 1,
// which is what damage/viscoelastic.h gives for a held step in either moduli convention (its header).
// For fixed tau the g_i are a non-negative least-squares problem (solved exactly, fit.cpp's method);
// ln tau_i are searched by BOBYQA within [ln(t_min / 10), ln(10 t_max)] from starts spread over the
// data's decades. The residuals are absolute (g_R is already normalised).
#include <string>
#include <vector>

#include "damage/mullins.h"
#include "fit/fit.h"

namespace pneufem::fit {

/// The points of a cyclic curve at or beyond every earlier stretch (the virgin loading envelope).
TestCurve primary_loading(const TestCurve& t);

/// P (Pa) of base + Mullins along the curve, in its order (W_max is the running maximum of W).
std::vector<double> mullins_stress(const TestCurve& t, const Constants& base, const MullinsParams& p);

struct MullinsFit {
  MullinsParams params;
  double objective = 0.0;              ///< E over all points (fit.h's weights)
  std::vector<std::vector<double>> model_P_Pa;  ///< per test, per point
  std::vector<double> r2;              ///< per test: 1 - SS_res/SS_tot of the stresses
  int evaluations = 0;
  int unloading_points = 0;            ///< points off the primary curve (the ones that fix r, m, beta)
};

/// r, m, beta for the given base (fitted to primary_loading of the same curves). Throws InputError
/// naming the files: no unloading points (a monotonic test holds no Mullins information), too few
/// (fewer than 3), no convergence within max_evaluations per start.
MullinsFit fit_mullins(const std::vector<TestCurve>& tests, const Constants& base, Weighting w,
                       int max_evaluations = 5000);

struct RelaxationPoint {
  double t_s;  ///< time since the step
  double g;    ///< stress over the stress at t = 0+
  int line;
};

struct RelaxationCurve {
  std::string source;
  std::vector<RelaxationPoint> points;
};

/// g_R(t) of Prony terms in Abaqus's form (g_i fractions of the instantaneous modulus).
double prony_relaxation(const std::vector<double>& g, const std::vector<double>& tau_s, double t_s);

struct PronyFit {
  std::vector<double> g, tau_s;  ///< ascending tau; terms with g = 0 dropped
  double objective = 0.0;        ///< sum of squared residuals of g_R
  std::vector<double> model;     ///< g_R at each point
  double r2 = 0.0;
  int evaluations = 0;
  std::vector<std::string> notes;
};

/// `terms` (1..3) Prony terms. Throws InputError naming the file: too few points (2 per term), no
/// relaxation (g_R does not fall), sum g >= 1 (relaxes to nothing: no long-term modulus), no
/// convergence.
PronyFit fit_prony(const RelaxationCurve& c, int terms, int max_evaluations = 5000);

}  // namespace pneufem::fit
