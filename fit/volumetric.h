#pragma once
// The bulk modulus from volumetric test data (Abaqus's *VOLUMETRIC TEST DATA: pressure p against the
// volume ratio J = V/V0, p > 0 in compression). pneufem's decoupled laws share the volumetric energy
// U = K/2 (J - 1)^2 (materials/invariant_kernel.h: volumetric_abaqus; Abaqus D1 = 2/K), so
//   p = -dU/dJ = K (1 - J),
// linear in K: weighted least squares with fit.h's weights (relative: 1/max(|p|, 0.01 max|p|)), solved
// in closed form, K = sum w^2 x p / sum w^2 x^2 with x = 1 - J, and the standard error of a one-
// parameter regression. The scene stores K as K_over_mu = K / mu0 of the law.
#include <string>
#include <vector>

#include "fit/fit.h"

namespace pneufem::fit {

struct VolumetricPoint {
  double J;     ///< volume ratio V / V0
  double p_Pa;  ///< pressure, > 0 in compression
  int line;
};

struct VolumetricCurve {
  std::string source;
  std::vector<VolumetricPoint> points;
};

struct BulkFit {
  double K_Pa = 0.0;
  double std_error_Pa = 0.0;  ///< 0 with a single point
  double r2 = 0.0;            ///< of the pressures
  std::vector<double> model_p_Pa;
};

/// Throws InputError naming the file: no point away from J = 1, or K <= 0 (the pressure falls as the
/// volume shrinks: check the sign convention, p > 0 in compression).
BulkFit fit_bulk_modulus(const VolumetricCurve& c, Weighting w);

}  // namespace pneufem::fit
