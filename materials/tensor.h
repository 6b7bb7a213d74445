#pragma once
// Fixed-size tensor types shared by the constitutive kernels.
//
// Fourth-order tangents A = dP/dF are stored as 9x9 matrices acting on F flattened
// column-major (Eigen's default): index(i,J) = i + 3*J, so A(i+3J, k+3L) = dP_iJ / dF_kL.
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <Eigen/LU>

namespace pneufem {

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Mat9 = Eigen::Matrix<double, 9, 9>;
using Vec9 = Eigen::Matrix<double, 9, 1>;

/// Flattened index of tensor component (i, J) in a 9-vector (column-major).
constexpr int flat(int i, int J) { return i + 3 * J; }

inline Vec9 flatten(const Mat3& A) { return Eigen::Map<const Vec9>(A.data()); }
inline Mat3 unflatten(const Vec9& a) { return Eigen::Map<const Mat3>(a.data()); }

}  // namespace pneufem
