#pragma once
// Fatigue as a uniform compliance growth driven by a load-weighted count (issue 35; registered as the
// material effect `fatigue_uniform`, damage/registry.cpp). The threshold fatigue law (fatigue.h)
// damages the silicone where its energy exceeds W_th, i.e. the most strained points first, which bends
// the angle-pressure curve (more at the top). Cyclic softening of elastomers is also reported as a
// softening of the whole loaded material that grows with the number of cycles, at first fast and then
// about as the logarithm of the count (e.g. the stress softening "linear in log N" of cyclically
// loaded rubbers). This law is that reading: every point softens by the same rule of its own count,
//
//   N(t) = int_0^t r dt',   r = W0 / W_max  (<= 1),   compliance 1 + D,   D = a ln(1 + N / t0),
//   P_iso = P0_iso / (1 + D),   psi_iso = W0 / (1 + D),
//
// with W0 the base's (undamaged) isochoric energy and W_max the largest W0 the point has carried. The
// count is weighted by the load as a fraction of the point's own peak load (a Miner-type count in
// which one second at the peak counts one second, a second at a fraction of it that fraction), so
// under proportional loading (W0(x, t) = f(x) h(t), as a pneu-net's walls are loaded by one pressure)
// r, N and D are the same at every loaded point: the silicone softens uniformly, as a stiffness
// growing with the load history, and the static curve keeps its shape (the angle at p after the
// damage is the undamaged angle at (1 + D) p when the silicone carries all the load). Constants: a
// (the compliance growth per e-fold of the count) and t0 (s: the count at which the growth turns from
// linear, D ~ a N / t0, to logarithmic). Over a recording much shorter than t0 only a / t0 shows.
//
// The virgin state: W_max = 0 and nothing counts until W0 exceeds a floor of 1e-6 of the base's initial
// shear modulus (a shear strain of ~0.14 %): a point loaded by rounding only (W0 ~ 1e-17 Pa at F = I)
// would otherwise count at the full rate r = W0 / W_max = 1. Above the floor, first loading is on the
// point's primary curve (W0 = W_max) and counts at r = 1.
//
// Time integration over the physical increment dt: backward Euler, N_new = N_old + dt r(W0(F_new)),
// with W_max the committed one (so r <= 1 and r = 1 on the primary curve). Consistent tangent:
//   A_iso = s A0_iso + (ds/dN) dt (dr/dW0) P0_iso (x) P0_iso,   s = 1 / (1 + D),
//   ds/dN = -s^2 a / (t0 + N_new),   dr/dW0 = 1 / W_max below the peak, 0 on the primary curve,
// which needs the base's psi_iso to be a potential of its stress (require_potential_base). With dt = 0
// (a static solve) the law is the base scaled by the committed 1 / (1 + D).
//
// State per point: [N (s), W_max (Pa)].
#include <string>

#include "damage/decorator.h"
#include "materials/material.h"

namespace pneufem {

struct UniformFatigueParams {
  double a = 0.0;     ///< compliance growth per e-fold of the count (> 0)
  double t0_s = 0.0;  ///< count at the knee (s at the peak load, > 0)
};

class UniformFatigue final : public MaterialDecorator {
 public:
  static constexpr int kOwnState = 2;  ///< [N, W_max]
  /// Floor of W_max below which nothing counts, relative to the base's initial shear modulus (see above).
  static constexpr double kFloorOfMu = 1e-6;

  /// Throws InputError for bad parameters or a base that is not split or whose energy is not a
  /// potential of its stress.
  UniformFatigue(MaterialPtr base, const UniformFatigueParams& p);

  bool isochoric_energy_is_potential() const override { return false; }
  void init_state(std::span<double> state) const override;
  void evaluate(std::span<const Mat3> F, const TimeStep& step, std::span<const double> state_old,
                std::span<double> state_new, std::span<PointResponse> out, bool tangent) const override;
  /// damage = 1 - (1 - d)(1 - base damage) with d = D / (1 + D); W_max from this law; the rest from the base.
  PointFields fields(std::span<const double> state) const override;
  /// Cycle jumping is not overridden: the law does not say how its count extrapolates, so it never
  /// jumps (Material's default for a law with state; decorator.h).

  /// The compliance growth D at count N.
  double growth(double N) const;
  const UniformFatigueParams& params() const { return p_; }

 private:
  UniformFatigueParams p_;
  double floor_Pa_ = 0.0;
};

}  // namespace pneufem
