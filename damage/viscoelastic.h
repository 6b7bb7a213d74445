#pragma once
// Finite-strain viscoelasticity of the isochoric response with a Prony series of 1-3 terms:
// Simo (1987), "On a fully three-dimensional finite-strain viscoelastic damage model", CMAME 60,
// 153-173; Holzapfel (2000), Nonlinear Solid Mechanics, sec. 6.10 (internal variables Q_a driven by
// the isochoric equilibrium stress, his free-energy factors beta_a^inf are our gamma_i).
//
// Convention: the base law is the LONG-TERM (equilibrium, fully relaxed) response. Term i adds a
// Maxwell branch of relative stiffness gamma_i >= 0 and relaxation time tau_i > 0:
//   S0 = F^{-1} P0_iso                       isochoric 2nd Piola-Kirchhoff stress of the base,
//   dQ_i/dt + Q_i / tau_i = gamma_i dS0/dt   (Q_i symmetric, reference configuration),
//   P_iso = P0_iso + F sum_i Q_i.
// The instantaneous isochoric stiffness is therefore (1 + sum gamma) times the base's, and a
// step strain relaxes as G(t) = G_inf (1 + sum gamma_i exp(-t/tau_i)).
//
// From Abaqus (*VISCOELASTIC, TIME=PRONY), whose g_i are fractions of the INSTANTANEOUS modulus,
// G(t) = G_0 (1 - sum g_i (1 - exp(-t/tau_i))): G_inf = G_0 (1 - sum g) and gamma_i G_inf = g_i G_0, so
//   gamma_i = g_i / (1 - sum g)     (prony_from_abaqus; needs sum g < 1).
// Note that the Abaqus base law is the instantaneous one; here it is the long-term one.
//
// Update over the physical increment dt, exact when S0 varies linearly in time over the step
// (x_i = dt / tau_i, k_i = (1 - exp(-x_i)) / x_i -> 1 as dt -> 0):
//   Q_i^{n+1} = exp(-x_i) Q_i^n + gamma_i k_i (S0^{n+1} - S0^n).
// Since F S0^{n+1} = P0_iso^{n+1}, with c = sum gamma_i k_i and H = sum_i [exp(-x_i) Q_i^n - gamma_i k_i S0^n]
// (symmetric, fixed by the committed state):
//   P_iso = (1 + c) P0_iso + F H,     A_iso = (1 + c) A0_iso + delta_ik H_JL.
// dt = 0 gives the instantaneous (glassy) response from the committed state.
//
// Reported energy: psi_iso = W0 + sum_i |Q_i|^2 / (4 gamma_i mu_inf), the base energy plus the energy
// stored in the Maxwell branches, exact for the small-strain standard linear solid (branch shear
// modulus gamma_i mu_inf) and an estimate at finite strain. Not a potential for P_iso (dissipative).
//
// viscous_strain field: |sum_i Q_i| / (2 mu_inf) (Frobenius norm), the small-strain elastic strain of
// the branches, i.e. how far the point is from its relaxed state (0 when fully relaxed).
//
// State per point: [S0^n (6) | Q_1 (6) | ... | Q_N (6)], symmetric tensors as (11, 22, 33, 23, 13, 12).
#include <array>
#include <string>
#include <vector>

#include "materials/material.h"

namespace pneufem {

/// Prony terms relative to the long-term modulus: gamma_i >= 0, tau_s_i > 0 (s), 1 to 3 terms.
struct ViscoParams {
  std::vector<double> gamma;
  std::vector<double> tau_s;
};

/// Converts Abaqus-style g_i (fractions of the instantaneous modulus, sum g < 1) to gamma_i.
/// Throws InputError for negative g_i or sum g >= 1.
ViscoParams prony_from_abaqus(const std::vector<double>& g, const std::vector<double>& tau_s);

class Viscoelastic final : public Material {
 public:
  static constexpr int kMaxTerms = 3;

  Viscoelastic(MaterialPtr base, const ViscoParams& p);

  std::string name() const override { return "viscoelastic(" + base_->name() + ")"; }
  int own_state_size() const { return 6 * (1 + n_); }
  int state_size() const override { return own_state_size() + base_->state_size(); }
  void init_state(std::span<double> state) const override;
  void evaluate(std::span<const Mat3> F, const TimeStep& step, std::span<const double> state_old,
                std::span<double> state_new, std::span<PointResponse> out, bool tangent) const override;
  /// Force only: the base's batched stress, then the overstress of all lanes (evaluate's bits).
  void stress(StressBatch& b, const TimeStep& step, std::span<const double> state_old,
              std::span<double> state_new) const override;
  /// viscous_strain from this law, the rest from the base.
  PointFields fields(std::span<const double> state) const override;
  /// The INSTANTANEOUS shear modulus (1 + sum gamma) mu_inf: stable-step estimates need the stiffest response.
  double initial_shear_modulus() const override { return (1.0 + gamma_sum_) * mu_inf_; }
  double initial_bulk_modulus() const override { return base_->initial_bulk_modulus(); }
  /// Forwarded to the base (its slice of the state): a fatigue law inside keeps its non-local driver.
  NonlocalSpec nonlocal() const override { return base_->nonlocal(); }
  double nonlocal_driver(const Mat3& F, std::span<const double> state) const override {
    return base_->nonlocal_driver(F, state.subspan(static_cast<std::size_t>(own_state_size())));
  }
  void set_nonlocal_driver(std::span<double> state, double local, double average) const override {
    base_->set_nonlocal_driver(state.subspan(static_cast<std::size_t>(own_state_size())), local, average);
  }

  int terms() const { return n_; }
  const MaterialPtr& base() const { return base_; }
  /// Long-term (equilibrium) shear modulus, the base's.
  double long_term_shear_modulus() const { return mu_inf_; }

 private:
  MaterialPtr base_;
  int n_ = 0;
  std::array<double, kMaxTerms> gamma_{}, tau_{};
  double gamma_sum_ = 0.0, mu_inf_ = 0.0;

  struct Increment;  ///< exp(-x_i), gamma_i k_i and c = sum gamma_i k_i of one increment dt
  Increment increment(double dt_s) const;
};

}  // namespace pneufem
