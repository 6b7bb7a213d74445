#include "scenes/inp/assembly.h"

#include <cmath>
#include <numbers>

namespace pneufem::inp {

Eigen::Matrix3d rotation_deg(const Eigen::Vector3d& k, double angle_deg) {
  double c = 0.0, s = 0.0;
  const double turns = angle_deg / 90.0;
  if (turns == std::round(turns) && std::abs(turns) < 1e15) {
    // Quarter turns: cos(pi/2) evaluates to 6e-17, not 0; the exact values keep a part turned
    // by 90 or 180 degrees on the grid it was meshed on.
    const long q = ((static_cast<long>(std::round(turns)) % 4) + 4) % 4;
    c = q == 0 ? 1.0 : q == 2 ? -1.0 : 0.0;
    s = q == 1 ? 1.0 : q == 3 ? -1.0 : 0.0;
  } else {
    const double theta = angle_deg * std::numbers::pi / 180.0;
    c = std::cos(theta);
    s = std::sin(theta);
  }
  Eigen::Matrix3d K;  // cross-product matrix: K v = k x v
  K << 0.0, -k.z(), k.y(), k.z(), 0.0, -k.x(), -k.y(), k.x(), 0.0;
  // Rodrigues: R = cos I + sin K + (1 - cos) k k^T.
  return c * Eigen::Matrix3d::Identity() + s * K + (1.0 - c) * (k * k.transpose());
}

std::pair<std::string_view, std::string_view> split_qualified(std::string_view token) {
  const std::size_t dot = token.find('.');
  if (dot == std::string_view::npos) return {std::string_view(), token};
  return {token.substr(0, dot), token.substr(dot + 1)};
}

std::string join_names(const std::vector<std::string>& names, const char* last) {
  std::string out;
  for (std::size_t i = 0; i < names.size(); ++i)
    out += (i == 0 ? "" : i + 1 == names.size() ? last : ", ") + names[i];
  return out;
}

}  // namespace pneufem::inp
