#pragma once
// Mullins effect: the pseudo-elastic model of Ogden & Roxburgh (1999), "A pseudo-elastic model for
// the Mullins effect in filled rubber", Proc. R. Soc. Lond. A 455, 2861-2877, in the form with the
// extra parameter beta used by Abaqus ("Mullins effect", Theory Manual), OpenRadioss and felupe:
//
//   eta = 1 - (1/r) erf( (W_max - W_dev) / (m + beta W_max) ),          softening variable in (1 - 1/r, 1]
//   W_dev = psi_iso of the base at the current F (the "undamaged" deviatoric energy),
//   W_max = max over the history of W_dev                               (the only history variable),
//   P_iso = eta P0_iso,   psi_iso = eta W_dev + phi(eta).
//
// On the primary (virgin) loading curve W_dev >= W_max_old, so W_max = W_dev and eta = 1 identically:
// the response is the base's, A_iso = A0_iso. The same holds before any loading (W_max_old = 0), so a
// W_dev of -1e-12 Pa from rounding at a pure dilatation does not count as unloading. Below it (unloading / reloading) W_max is frozen and
//   A_iso = eta A0_iso + (d eta / d W_dev) P0_iso (x) P0_iso,
//   d eta / d W_dev = 2 / (r sqrt(pi) (m + beta W_max)) exp(-z^2),   z = (W_max - W_dev)/(m + beta W_max),
// using d W_dev / dF = P0_iso (the base's isochoric energy is a potential of its isochoric stress).
//
// Damage function phi (INCLUDED in the reported psi_iso). Ogden-Roxburgh choose phi so that
// d psi / d eta = W_dev + phi'(eta) = 0 defines eta; inverting the erf law with D = m + beta W_max,
// phi'(eta) = -(W_max - D erfinv(r (1 - eta))), and integrating from phi(1) = 0 with
// int_0^{erf z} erfinv(u) du = (1 - exp(-z^2)) / sqrt(pi):
//   phi(eta) = (1 - eta) W_max - D (1 - exp(-z^2)) / (r sqrt(pi)) >= 0.
// Consequence (tested): P_iso = d psi_iso / dF at a fixed committed W_max, on and off the primary curve.
//
// Limitation for fatigue studies: eta depends only on the PEAK energy W_max, so repeating the same
// load cycle gives the same response from the second cycle on. Mullins alone therefore cannot explain
// a drift that keeps growing over trials 2-10; that needs fatigue damage (fatigue.h) and/or
// viscoelastic creep and recovery (viscoelastic.h).
//
// State per point: [W_max (J/m^3), eta at the last evaluated configuration (output only: fields())].
#include <string>

#include "damage/decorator.h"
#include "materials/material.h"

namespace pneufem {

/// Ogden-Roxburgh parameters: r > 1 (dimensionless; the largest softening is 1/r), m >= 0 (Pa, an
/// energy density), beta >= 0 (dimensionless), and not m = beta = 0.
struct MullinsParams {
  double r = 2.0;
  double m_Pa = 0.0;
  double beta = 0.0;
};

/// Softening variable, its derivative and the damage function at (W_dev, W_max), W_max >= W_dev.
struct MullinsEta {
  double eta = 1.0;
  double deta_dW = 0.0;  ///< d eta / d W_dev at frozen W_max (1/Pa)
  double phi = 0.0;      ///< damage function phi(eta) (J/m^3)
};
MullinsEta ogden_roxburgh(double W_dev, double W_max, const MullinsParams& p);

class Mullins final : public MaterialDecorator {
 public:
  static constexpr int kOwnState = 2;  ///< [W_max, eta_last]

  /// Throws InputError for bad parameters or a base that is not split or whose energy is not a
  /// potential of its stress (fatigue, viscoelastic: wrap those around mullins instead).
  Mullins(MaterialPtr base, const MullinsParams& p);

  void init_state(std::span<double> state) const override;
  void evaluate(std::span<const Mat3> F, const TimeStep& step, std::span<const double> state_old,
                std::span<double> state_new, std::span<PointResponse> out, bool tangent) const override;
  /// Force only: the base's batched stress, then the softening lane by lane (evaluate's bits).
  void stress(StressBatch& b, const TimeStep& step, std::span<const double> state_old,
              std::span<double> state_new) const override;
  /// W_max from this law; damage = 1 - eta_last (x) the base's stiffness fraction; the rest from the base.
  PointFields fields(std::span<const double> state) const override;
  /// Cycle jumping (Material::jump_cycles): W_max is a running maximum; when the structure softens
  /// from cycle to cycle (fatigue) the peak energy of the repeated load grows slowly, and it is
  /// extrapolated linearly, W_max,(k+N) = W_max,k + N max(0, W_max,k - W_max,(k-1)); eta_last is the
  /// last cycle's. jump_error bounds the change of eta that W_max1 < W_max2 (dW = W_max2 - W_max1) can
  /// cause at any W_dev: at W_dev >= W_max1 the first is on its primary curve, and below it
  /// |d eta / d W_max| = (2 / (r sqrt(pi))) exp(-z^2) (m + beta W_dev) / (m + beta W_max)^2 with
  /// z >= (W_max - W_max1) / D2; integrated over W_max in [W_max1, W_max2], with Di = m + beta W_maxi,
  ///   |d eta| <= (D2 / D1) erf(dW / D2) / r     (<= 2 dW / (r sqrt(pi) D1) for small dW; at most 1/r).
  bool jumps_cycles() const override { return base()->jumps_cycles(); }
  void jump_cycles(std::span<const double> before, std::span<const double> after, double cycles,
                   std::span<double> out) const override;
  double jump_error(std::span<const double> predicted, std::span<const double> computed) const override;

  const MullinsParams& params() const { return p_; }

 private:
  MullinsParams p_;
};

}  // namespace pneufem
