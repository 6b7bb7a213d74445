#pragma once
// Test helper shared by the test programs: the scene settings of a tiny actuator.
#include <string>
#include <vector>

namespace pneufem::test {

/// 3 chambers at h = 6 mm, no VTU (a few hundred Tet10: each equilibrium takes milliseconds), then
/// `more` (later settings win).
inline std::vector<std::string> tiny(const std::vector<std::string>& more) {
  std::vector<std::string> s = {"geometry.chambers=3", "mesh.h_mm=6.0", "output.vtu=none"};
  s.insert(s.end(), more.begin(), more.end());
  return s;
}

}  // namespace pneufem::test
