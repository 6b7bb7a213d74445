#pragma once
// Finite-strain viscoelasticity of the isochoric response with a Prony series of 1-3 terms:
// Simo (1987), "On a fully three-dimensional finite-strain viscoelastic damage model", CMAME 60,
// 153-173; Holzapfel (2000), Nonlinear Solid Mechanics, sec. 6.10 (internal variables Q_a driven by
// the isochoric equilibrium stress, his free-energy factors beta_a^inf are our gamma_i); Abaqus
// Theory Manual, "Finite-strain viscoelasticity" (sec. 4.8.2 of the 6.14 edition), and Abaqus
// Analysis User's Manual, "Time domain viscoelasticity" (the MODULI parameter of *HYPERELASTIC).
//
// The Prony terms. Term i is a Maxwell branch of relative stiffness gamma_i >= 0 (relative to the
// LONG-TERM modulus) and relaxation time tau_i > 0, so a step strain relaxes as
//   G(t) = G_inf (1 + sum gamma_i exp(-t/tau_i)),   G_0 = G(0+) = G_inf (1 + sum gamma).
// Abaqus's g_i are fractions of the INSTANTANEOUS modulus, G(t) = G_0 (1 - sum g_i (1 - exp(-t/tau_i))):
//   g_i = gamma_i / (1 + sum gamma),  gamma_i = g_i / (1 - sum g)   (prony_from_abaqus; needs sum g < 1),
//   1 - sum g = 1 / (1 + sum gamma) = G_inf / G_0.
//
// The two moduli conventions (ViscoModuli): which response the base law's constants describe.
//  * long_term:     the base law W0 is the long-term (equilibrium, fully relaxed) response:
//                   G_inf = mu_base, G_0 = (1 + sum gamma) mu_base; the instantaneous response is stiffer
//                   than the base, creep approaches the base's elastic response from the stiff side.
//  * instantaneous: the base law W0 is the instantaneous (glassy) response, as Abaqus's default
//                   MODULI=INSTANTANEOUS: G_0 = mu_base, G_inf = (1 - sum g) mu_base; the stress at t = 0+
//                   equals the base's and relaxes to (1 - sum g) times it, creep goes beyond the base's
//                   elastic response.
// Only the ISOCHORIC (deviatoric) part is relaxed: the volumetric response is the base's in both
// conventions, i.e. Abaqus's volumetric Prony terms k_i = 0 (nearly incompressible silicone, whose
// bulk relaxation is not measured).
//
// With beta = 1 (long_term) or beta = 1 - sum g = 1 / (1 + sum gamma) (instantaneous) and the branch
// coefficients a_i = beta gamma_i (= gamma_i, or = g_i):
//   S0 = F^{-1} P0_iso                        isochoric 2nd Piola-Kirchhoff stress of the base,
//   dQ_i/dt + Q_i / tau_i = a_i dS0/dt         (Q_i symmetric, reference configuration),
//   P_iso = beta P0_iso + F sum_i Q_i,
// i.e. the long-term law is beta W0 and each branch has stiffness a_i relative to the base. A step
// strain gives P_iso(t) = (beta + sum a_i exp(-t/tau_i)) P0_iso: (1 + sum gamma exp(-t/tau_i)) P0_iso
// long-term, (1 - sum g_i (1 - exp(-t/tau_i))) P0_iso instantaneous.
//
// The internal variables live in the reference configuration (Simo 1987, Holzapfel sec. 6.10);
// Abaqus's hereditary integral convects the instantaneous Kirchhoff stress with the relative
// deformation gradient instead. The two agree for a step strain held constant and at small strain,
// and differ at finite strain under a deformation that changes during relaxation.
//
// Update over the physical increment dt, exact when S0 varies linearly in time over the step
// (x_i = dt / tau_i, k_i = (1 - exp(-x_i)) / x_i -> 1 as dt -> 0):
//   Q_i^{n+1} = exp(-x_i) Q_i^n + a_i k_i (S0^{n+1} - S0^n).
// Since F S0^{n+1} = P0_iso^{n+1}, with H = sum_i [exp(-x_i) Q_i^n - a_i k_i S0^n] (symmetric, fixed by
// the committed state) and the scalar b = beta + sum a_i k_i:
//   P_iso = b P0_iso + F H,     A_iso = b A0_iso + delta_ik H_JL   (the consistent tangent, both conventions).
// b is evaluated as 1 + sum gamma_i k_i (long_term) and 1 - sum g_i (1 - k_i) (instantaneous), so that
// dt = 0 (the instantaneous response from the committed state) gives b = 1 + sum gamma resp. exactly 1.
//
// Reported energy: psi_iso = beta W0 + sum_i |Q_i|^2 / (4 a_i mu_base), the long-term energy plus the
// energy stored in the Maxwell branches (branch shear modulus a_i mu_base = gamma_i mu_inf), exact for the
// small-strain standard linear solid and an estimate at finite strain. Not a potential for P_iso
// (dissipative).
//
// viscous_strain field: |sum_i Q_i| / (2 mu_inf) (Frobenius norm, mu_inf = beta mu_base the long-term shear
// modulus), the small-strain elastic strain of the branches, i.e. how far the point is from its relaxed
// state (0 when fully relaxed); the same for the same physical material in either convention.
//
// State per point: [S0^n (6) | Q_1 (6) | ... | Q_N (6)], symmetric tensors as (11, 22, 33, 23, 13, 12).
#include <array>
#include <string>
#include <vector>

#include "damage/decorator.h"
#include "materials/material.h"

namespace pneufem {

/// Which response the base law's constants describe (see above). Scenes default to instantaneous,
/// as Abaqus (the registry's `moduli` choice, damage/registry.cpp); this struct's default is
/// long_term, the convention the C++ API had before the choice existed.
enum class ViscoModuli { long_term, instantaneous };

/// "long_term" / "instantaneous", the scene's words.
const char* to_string(ViscoModuli m);

/// Prony terms relative to the long-term modulus: gamma_i >= 0, tau_s_i > 0 (s), 1 to 3 terms, and
/// the convention of the base law's constants.
struct ViscoParams {
  std::vector<double> gamma;
  std::vector<double> tau_s;
  ViscoModuli moduli = ViscoModuli::long_term;
};

/// Converts Abaqus-style g_i (fractions of the instantaneous modulus, sum g < 1) to gamma_i, with
/// `moduli` = instantaneous (Abaqus's default: its hyperelastic constants are the instantaneous
/// response; pass the deck's MODULI= otherwise). Throws InputError for negative g_i or sum g >= 1.
ViscoParams prony_from_abaqus(const std::vector<double>& g, const std::vector<double>& tau_s,
                              ViscoModuli moduli = ViscoModuli::instantaneous);

/// The Prony decorator above, on MaterialDecorator (damage/decorator.h): the name "viscoelastic(base)", the
/// state size own + base (own = 6 (1 + terms)), the bulk modulus and the non-local driver (a fatigue law
/// inside keeps its own) are the shared forwarding; this layer overrides the shear modulus (the
/// instantaneous one), the linear drive (its own branches, not the base's) and cycle jumping.
class Viscoelastic final : public MaterialDecorator {
 public:
  static constexpr int kMaxTerms = 3;

  Viscoelastic(MaterialPtr base, const ViscoParams& p);

  bool isochoric_energy_is_potential() const override { return false; }
  void init_state(std::span<double> state) const override;
  void evaluate(std::span<const Mat3> F, const TimeStep& step, std::span<const double> state_old,
                std::span<double> state_new, std::span<PointResponse> out, bool tangent) const override;
  /// Force only: the base's batched stress, then the overstress of all lanes (evaluate's bits).
  void stress(StressBatch& b, const TimeStep& step, std::span<const double> state_old,
              std::span<double> state_new) const override;
  /// viscous_strain from this law, the rest from the base.
  PointFields fields(std::span<const double> state) const override;
  /// The Prony update above is exact for a linearly varying S0 (Material::LinearDrive): D = S0 / (2 mu_inf)
  /// (strain units, the scale of viscous_strain), a_i and tau_i the branches', recovery = 1 / beta:
  /// at fixed load the isochoric stress beta S0 + sum Q_i is fixed, so while the branches relax
  /// fully S0 changes by |sum Q_i| / beta, i.e. D by viscous_strain / beta. Not the base's drive.
  LinearDrive linear_drive() const override;
  void linear_drive_value(std::span<const double> state, std::span<double> out) const override;
  /// The INSTANTANEOUS shear modulus (beta + sum a_i) mu_base = (1 + sum gamma) mu_inf: stable-step
  /// estimates need the stiffest response (mu_base itself in the instantaneous convention).
  double initial_shear_modulus() const override {
    return moduli_ == ViscoModuli::instantaneous ? mu_base_ : (1.0 + gamma_sum_) * mu_base_;
  }
  /// Cycle jumping (Material::jump_cycles): the branches Q_i and S0 are NOT extrapolated. They
  /// follow the load within a cycle and relax during the rest that ends it, so after a jump they are
  /// the last computed cycle's (the first computed cycle after the jump starts from them). The
  /// base's history is extrapolated by the base; jump_error is the base's.
  bool jumps_cycles() const override { return base()->jumps_cycles(); }
  void jump_cycles(std::span<const double> before, std::span<const double> after, double cycles,
                   std::span<double> out) const override;
  double jump_error(std::span<const double> predicted, std::span<const double> computed) const override {
    return base()->jump_error(base_state(predicted), base_state(computed));
  }

  int terms() const { return n_; }
  ViscoModuli moduli() const { return moduli_; }
  /// Long-term (equilibrium) shear modulus beta mu_base: the base's (long_term), (1 - sum g) times it
  /// (instantaneous).
  double long_term_shear_modulus() const { return beta_ * mu_base_; }

 private:
  int n_ = 0;
  ViscoModuli moduli_ = ViscoModuli::long_term;
  std::array<double, kMaxTerms> gamma_{}, tau_{};
  std::array<double, kMaxTerms> a_{};  ///< branch coefficients a_i = beta gamma_i (gamma_i, or Abaqus g_i)
  double gamma_sum_ = 0.0, beta_ = 1.0, mu_base_ = 0.0;

  struct Increment;  ///< exp(-x_i), a_i k_i and b = beta + sum a_i k_i of one increment dt
  Increment increment(double dt_s) const;
};

}  // namespace pneufem
