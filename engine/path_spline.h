#pragma once
// Interpolation along a traced elastic path (engine/path_model.h, engine/rom.h): quantities known
// at the path's samples theta_0 < theta_1 < ... (the bending angle, deg) are interpolated between
// them by cubic Hermite pieces whose end slopes make the whole curve a C2 cubic spline.
//
// Why C2 and not linear or C1: the reduced models solve for the point of the path in equilibrium,
// and their residual involves d/dtheta of the interpolated deformation. With a polyline the slope
// jumps at every sample, and the equilibrium angle of a model that is not the reference sticks to
// the samples as its constants change (a calibration objective piecewise constant at the 1 % level,
// 2026-11-26); with three-point (C1) slopes the second derivative still jumps and left kinks of ~6 %
// of the slope (PathModel.AngleIsSmoothInTheConstants).
#include <cstddef>
#include <functional>
#include <vector>

namespace pneufem {

/// Cubic Hermite interpolation on one path segment at a = (theta - theta_k) / dth: the weights of
/// the two end values and end slopes, for the value and for its theta-derivative (and the second
/// derivative), computed once per segment position and applied to every quantity there. Outside
/// [0, 1], linear with the end slope (extrapolation: callers clamp the segment index, so a < 0 only
/// on the first segment, a > 1 only on the last).
struct Hermite {
  double a, dth;
  double w00 = 0, w10 = 0, w01 = 0, w11 = 0;  ///< value weights of y0, m0, y1, m1
  double s0 = 0, sm0 = 0, sm1 = 0;            ///< slope = s0 (y0 - y1) + sm0 m0 + sm1 m1
  double c0 = 0, cm0 = 0, cm1 = 0;            ///< curvature = c0 (y0 - y1) + cm0 m0 + cm1 m1
  Hermite(double a_, double dth_) : a(a_), dth(dth_) {
    const double a2 = a * a, a3 = a2 * a;
    w00 = 2 * a3 - 3 * a2 + 1, w10 = (a3 - 2 * a2 + a) * dth, w01 = 3 * a2 - 2 * a3, w11 = (a3 - a2) * dth;
    s0 = (6 * a2 - 6 * a) / dth, sm0 = 3 * a2 - 4 * a + 1, sm1 = 3 * a2 - 2 * a;
    c0 = (12 * a - 6) / (dth * dth), cm0 = (6 * a - 4) / dth, cm1 = (6 * a - 2) / dth;
  }
  bool inside() const { return a >= 0.0 && a <= 1.0; }
  /// The interpolated value; `slope` gets its d/dtheta.
  template <class T>
  T operator()(const T& y0, const T& y1, const T& m0, const T& m1, T* slope) const {
    if (a < 0.0) {
      *slope = m0;
      return y0 + (a * dth) * m0;
    }
    if (a > 1.0) {
      *slope = m1;
      return y1 + ((a - 1.0) * dth) * m1;
    }
    *slope = s0 * (y0 - y1) + sm0 * m0 + sm1 * m1;
    return w00 * y0 + w10 * m0 + w01 * y1 + w11 * m1;
  }
  /// The value only.
  template <class T>
  T value(const T& y0, const T& y1, const T& m0, const T& m1) const {
    if (a < 0.0) return y0 + (a * dth) * m0;
    if (a > 1.0) return y1 + ((a - 1.0) * dth) * m1;
    return w00 * y0 + w10 * m0 + w01 * y1 + w11 * m1;
  }
  /// The theta-derivative only.
  template <class T>
  T slope(const T& y0, const T& y1, const T& m0, const T& m1) const {
    if (a < 0.0) return m0;
    if (a > 1.0) return m1;
    return s0 * (y0 - y1) + sm0 * m0 + sm1 * m1;
  }
  /// The second theta-derivative (zero outside the segment: linear extrapolation).
  template <class T>
  T curvature(const T& y0, const T& y1, const T& m0, const T& m1) const {
    if (!inside()) return 0.0 * m0;
    return c0 * (y0 - y1) + cm0 * m0 + cm1 * m1;
  }
};

/// Slopes of samples y[k] at theta[k] such that the piecewise cubic Hermite through them is the
/// cubic spline (C2: continuous second derivative) with not-a-knot ends, which reproduces any
/// cubic exactly. Not natural ends (zero second derivative): the path's top ends at or near a
/// limit point, where it curves most. The tridiagonal system (non-uniform knots)
///   h_k m_{k-1} + 2 (h_{k-1} + h_k) m_k + h_{k-1} m_{k+1} = 3 (h_k d_{k-1} + h_{k-1} d_k)
/// with h_k = theta_{k+1} - theta_k and chords d_k (and the two end rows), is solved by the Thomas
/// algorithm without pivoting: the interior rows are diagonally dominant, and the pivots stay
/// above 0.12 h for any spacing whose neighbours differ by less than 3x (checked on 20 000 random
/// spacings; a path's samples, equal steps of pressure apart, differ by far less).
/// T: any type with +, -, and scalar * and / (double, Eigen vectors and matrices).
template <class T>
std::vector<T> spline_slopes(const std::vector<double>& theta, const std::function<T(std::size_t)>& y) {
  const std::size_t n = theta.size();
  std::vector<T> m(n);
  if (n == 2) {
    m[0] = m[1] = (y(1) - y(0)) / (theta[1] - theta[0]);
    return m;
  }
  std::vector<double> h(n - 1), lower(n, 0.0), diag(n), upper(n, 0.0);
  std::vector<T> d(n - 1), rhs(n);
  for (std::size_t k = 0; k + 1 < n; ++k) {
    h[k] = theta[k + 1] - theta[k];
    d[k] = (y(k + 1) - y(k)) / h[k];
  }
  if (n >= 4) {  // not-a-knot ends: the third derivative continuous at the second and last-but-one sample
    const double h0 = h[0], h1 = h[1], ha = h[n - 3], hb = h[n - 2];
    diag[0] = h1, upper[0] = h0 + h1, rhs[0] = ((h0 + 2.0 * (h0 + h1)) * h1 * d[0] + h0 * h0 * d[1]) / (h0 + h1);
    lower[n - 1] = ha + hb, diag[n - 1] = ha;
    rhs[n - 1] = (hb * hb * d[n - 3] + (2.0 * (ha + hb) + hb) * ha * d[n - 2]) / (ha + hb);
  } else {  // three samples: natural ends (zero second derivative)
    diag[0] = 2.0, upper[0] = 1.0, rhs[0] = 3.0 * d[0];
    lower[n - 1] = 1.0, diag[n - 1] = 2.0, rhs[n - 1] = 3.0 * d[n - 2];
  }
  for (std::size_t k = 1; k + 1 < n; ++k) {
    lower[k] = h[k], diag[k] = 2.0 * (h[k - 1] + h[k]), upper[k] = h[k - 1];
    rhs[k] = 3.0 * (h[k] * d[k - 1] + h[k - 1] * d[k]);
  }
  for (std::size_t k = 1; k < n; ++k) {  // forward elimination
    const double w = lower[k] / diag[k - 1];
    diag[k] -= w * upper[k - 1];
    rhs[k] = rhs[k] - w * rhs[k - 1];
  }
  m[n - 1] = rhs[n - 1] / diag[n - 1];
  for (std::size_t k = n - 1; k-- > 0;) m[k] = (rhs[k] - upper[k] * m[k + 1]) / diag[k];
  return m;
}

/// Monotone cubic slopes (Fritsch-Carlson, with the harmonic weights of Fritsch & Butland) of the
/// samples p[k] at theta[k]: where the chords change sign the slope is zero, so the interpolant
/// never overshoots. Used for the reference's equilibrium pressure p_el(theta), which flattens
/// towards a limit point. End slopes: the end chords.
std::vector<double> monotone_slopes(const std::vector<double>& theta, const std::vector<double>& p);

/// Index k of the segment [theta[k], theta[k+1]] holding x (clamped to the first and last segment).
int path_segment_index(const std::vector<double>& theta, double x);

}  // namespace pneufem
