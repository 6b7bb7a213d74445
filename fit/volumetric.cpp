#include "fit/volumetric.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/errors.h"
#include "core/number_text.h"

namespace pneufem::fit {

BulkFit fit_bulk_modulus(const VolumetricCurve& c, Weighting w) {
  double largest = 0.0;
  for (const VolumetricPoint& q : c.points) largest = std::max(largest, std::abs(q.p_Pa));
  const auto weight = [&](const VolumetricPoint& q) {
    return w == Weighting::absolute ? 1e-6 : 1.0 / std::max({std::abs(q.p_Pa), 0.01 * largest, 1e-300});
  };
  double sxx = 0.0, sxp = 0.0;
  int n = 0;
  for (const VolumetricPoint& q : c.points) {
    const double ww = weight(q) * weight(q), x = 1.0 - q.J;
    sxx += ww * x * x;
    sxp += ww * x * q.p_Pa;
    n += x != 0.0;
  }
  if (n == 0)
    throw InputError(c.source + ": no volumetric point away from J = 1; the bulk modulus needs compressed volumes "
                     "(J < 1) with their pressures");
  BulkFit f;
  f.K_Pa = sxp / sxx;
  if (!(f.K_Pa > 0.0))
    throw InputError(c.source + ": the fitted bulk modulus is " + short_num(f.K_Pa) +
                     " Pa <= 0: the pressure does not rise as the volume shrinks; the convention is p > 0 in "
                     "compression (J < 1), as Abaqus's *VOLUMETRIC TEST DATA");
  double rss = 0.0, mean = 0.0, tot = 0.0, res = 0.0;
  for (const VolumetricPoint& q : c.points) mean += q.p_Pa / static_cast<double>(c.points.size());
  for (const VolumetricPoint& q : c.points) {
    const double p = f.K_Pa * (1.0 - q.J);
    f.model_p_Pa.push_back(p);
    rss += std::pow(weight(q) * (p - q.p_Pa), 2);
    res += (p - q.p_Pa) * (p - q.p_Pa);
    tot += (q.p_Pa - mean) * (q.p_Pa - mean);
  }
  if (c.points.size() > 1) f.std_error_Pa = std::sqrt(rss / static_cast<double>(c.points.size() - 1) / sxx);
  f.r2 = tot > 0.0 ? 1.0 - res / tot : std::numeric_limits<double>::quiet_NaN();
  return f;
}

}  // namespace pneufem::fit
