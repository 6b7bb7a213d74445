#include "engine/history_step.h"

#include <cmath>

namespace pneufem {

HistoryStep history_step(const std::vector<double>& prev, const std::vector<double>& cur, const std::vector<double>& next,
                         double r) {
  HistoryStep out;
  for (std::size_t i = 0; i < next.size(); i += 2) {
    const int point = static_cast<int>(i / 2);
    const double c = std::abs(next[i] - cur[i]) + std::abs(next[i + 1] - cur[i + 1]);
    if (c > out.change) out.change = c, out.change_point = point;
    if (prev.empty()) continue;
    double e = 0.0;
    for (std::size_t k = i; k < i + 2; ++k) e += std::abs((next[k] - cur[k]) - r * (cur[k] - prev[k]));
    e *= r / (1.0 + r);
    if (e > out.error) out.error = e, out.error_point = point;
  }
  return out;
}

double prony_interpolation_G(double x) {
  if (!(x > 0.0)) return 0.0;
  // The closed form cancels to x^3/12 from terms of size x: the series below x = 0.1 (its next
  // term, x^9 / 103680, is ~1e-10 of the sum there).
  if (x < 0.1) return x * x * x * (1.0 / 12 + x * (-1.0 / 24 + x * (1.0 / 80 + x * (-1.0 / 360 + x * (1.0 / 2016 - x / 13440)))));
  const double em = std::exp(-x);
  return (0.5 * x - 1.0) * -std::expm1(-x) + x * em;
}

double linear_drive_error(const Material::LinearDrive& d, double c, double h) {
  double sum = 0.0;
  for (int i = 0; i < d.terms; ++i) sum += d.a[i] * d.tau_s[i] * d.tau_s[i] * prony_interpolation_G(h / d.tau_s[i]);
  return c * sum;
}

}  // namespace pneufem
