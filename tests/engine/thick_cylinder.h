#pragma once
// Analytic inflation of a thick-walled cylinder (plane strain, incompressible Yeoh with the
// constants of testing::ecoflex()): the truth of the cylinder system tests.
#include <cmath>

namespace pneufem::testing {

// Plane-strain thick cylinder A <= R <= B inflated by internal follower pressure p, incompressible
// Yeoh: r^2 = R^2 + a^2 - A^2, lambda = r/R, I1 = lambda^2 + lambda^-2 + 1 and (radial equilibrium)
//   p = int_a^b 2 W'(I1) (lambda^2 - lambda^-2) / r dr.
inline double yeoh_W1(double I1) {
  const double x = I1 - 3.0;
  return 0.019e6 + 2 * 9.0e2 * x + 3 * (-4.75) * x * x;
}
inline double cylinder_pressure(double a, double A, double B) {
  const double b = std::sqrt(B * B + a * a - A * A);
  const int n = 2000;  // Simpson on a smooth integrand: error << 1e-8
  double sum = 0.0;
  for (int i = 0; i <= n; ++i) {
    const double r = a + (b - a) * i / n;
    const double R = std::sqrt(r * r - a * a + A * A);
    const double l = r / R;
    const double f = 2 * yeoh_W1(l * l + 1 / (l * l) + 1) * (l * l - 1 / (l * l)) / r;
    sum += f * (i == 0 || i == n ? 1 : (i % 2 ? 4 : 2));
  }
  return sum * (b - a) / (3 * n);
}
inline double cylinder_inner_radius(double p, double A, double B) {
  double lo = A, hi = 3 * A;
  for (int it = 0; it < 200; ++it) {
    const double mid = 0.5 * (lo + hi);
    (cylinder_pressure(mid, A, B) < p ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace pneufem::testing
