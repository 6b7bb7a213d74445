#include "materials/material.h"

#include <array>

namespace pneufem {

void Material::stress(StressBatch& b, const TimeStep& step, std::span<const double> state_old,
                      std::span<double> state_new) const {
  std::array<Mat3, StressBatch::kLanes> F;
  std::array<PointResponse, StressBatch::kLanes> r;
  for (int l = 0; l < b.n; ++l) F[l] = b.F_of(l);
  evaluate(std::span<const Mat3>(F.data(), b.n), step, state_old, state_new, std::span<PointResponse>(r.data(), b.n),
           false);
  for (int l = 0; l < b.n; ++l) b.set_response(l, r[l]);
}

}  // namespace pneufem
