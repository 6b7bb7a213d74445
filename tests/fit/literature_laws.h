#pragma once
// Laws the fit tests share (test_incompressible.cpp, test_stability.cpp).
#include <vector>

#include "fit/incompressible.h"

namespace pneufem::fit::testing {

/// Laws with constants from the literature: Kulkarni's Ecoflex 00-50 Yeoh (the default scene), a
/// Mooney-Rivlin, a neo-Hookean and Ogden's 1972 Treloar fit (Abaqus convention, README of
/// tests/data/treloar1944).
inline std::vector<Constants> literature_laws() {
  constexpr double kMPa = 1e6;
  return {
      {Law::yeoh, {0.019 * kMPa, 9.0e-4 * kMPa, -4.75e-6 * kMPa}, {}},
      {Law::mooney_rivlin, {0.15 * kMPa, 0.03 * kMPa}, {}},
      {Law::neo_hookean, {0.2 * kMPa}, {}},
      {Law::ogden, {0.4095 * kMPa, 0.003 * kMPa, 0.01 * kMPa}, {1.3, 5.0, -2.0}},
  };
}

}  // namespace pneufem::fit::testing
