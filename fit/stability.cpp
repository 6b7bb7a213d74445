#include "fit/stability.h"

#include <cmath>
#include <limits>

#include "materials/hyperelastic.h"
#include "materials/invariant_kernel.h"

namespace pneufem::fit {

namespace {

/// W1, W2, W11 of an invariant law at I1 (J = 1), from the law's own derivatives.
InvariantDerivatives invariant_derivatives(const Constants& k, double I1, double I2) {
  Invariants v{};
  v.J = 1.0;
  v.I1b = I1;
  v.I2b = I2;
  switch (k.law) {
    case Law::neo_hookean: return NeoHookean(k.c[0], 1.0).derivatives(v);
    case Law::mooney_rivlin: return MooneyRivlin(k.c[0], k.c[1], 1.0).derivatives(v);
    default: return Yeoh(k.c[0], k.c[1], k.c[2], 1.0).derivatives(v);
  }
}

}  // namespace

Eigen::Matrix2d drucker_tangent(const Constants& k, const Vec3& l) {
  Mat3 M = Mat3::Zero();  // d tau_a / d ln l_b
  if (k.law == Law::ogden) {
    for (int a = 0; a < 3; ++a)
      for (std::size_t i = 0; i < k.c.size(); ++i) M(a, a) += 2.0 * k.c[i] * std::pow(l[a], k.alpha[i]);
  } else {
    const Vec3 l2 = l.array().square();
    const InvariantDerivatives d = invariant_derivatives(k, l2.sum(), l2.cwiseInverse().sum());
    for (int a = 0; a < 3; ++a) {
      for (int b = 0; b < 3; ++b) M(a, b) = 4.0 * d.W11 * l2[a] * l2[b];
      M(a, a) += 4.0 * d.W1 * l2[a] + 4.0 * d.W2 / l2[a];
    }
  }
  Eigen::Matrix2d D;
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j) D(i, j) = M(i, j) - M(i, 2) - M(2, j) + M(2, 2);
  return D;
}

bool drucker_stable(const Constants& k, const Vec3& lambda) {
  const Eigen::Matrix2d D = drucker_tangent(k, lambda);
  return D.trace() > 0.0 && D.determinant() > 0.0;
}

bool StabilityReport::stable() const {
  for (const StabilityLimit& s : limits)
    if (!std::isnan(s.strain)) return false;
  return true;
}

StabilityReport drucker_stability(const Constants& k, double lo, double hi, double step) {
  StabilityReport r{lo, hi, step, {}};
  for (TestMode m : {TestMode::uniaxial, TestMode::biaxial, TestMode::planar})
    for (bool tension : {true, false}) {
      StabilityLimit s{m, tension, std::numeric_limits<double>::quiet_NaN()};
      const double end = tension ? hi : lo;
      const int n = static_cast<int>(std::floor(std::abs(end) / step + 1e-9));
      for (int i = 0; i <= n; ++i) {
        const double eps = (tension ? 1.0 : -1.0) * i * step;
        if (!drucker_stable(k, mode_stretches(m, 1.0 + eps))) {
          s.strain = eps;
          break;
        }
      }
      r.limits.push_back(s);
    }
  return r;
}

}  // namespace pneufem::fit
