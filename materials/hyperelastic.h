#pragma once
// Isotropic hyperelastic laws. Each law is a small immutable value type: parameters validated at
// construction (InputError with an actionable message), then pure functions of F.
//
// Decoupled laws (Yeoh, neo-Hookean, Mooney-Rivlin) follow the Abaqus definitions
//   psi = W(I1b, I2b) + K/2 (J - 1)^2,   K = 2/D1,
// so constants from an Abaqus/CalculiX deck carry over unchanged. Inputs are in Pa.
#include <array>
#include <string>

#include "materials/invariant_kernel.h"

namespace pneufem {

/// Yeoh (1993) polynomial in I1b of order 1..3:  W = sum_i C_i0 (I1b - 3)^i.
/// Initial shear modulus mu0 = 2 C10. Ecoflex 00-50 (Kulkarni 2015, used by the seed paper):
/// C10 = 0.019 MPa, C20 = 9.0e-4 MPa, C30 = -4.75e-6 MPa. The paper prints C10 as "1.9 x 10^2";
/// 1.9 x 10^-2 MPa is the value consistent with the datasheet's 100 % modulus of 12 psi.
struct Yeoh {
  double C10, C20, C30, K;  // Pa
  Yeoh(double C10_Pa, double C20_Pa, double C30_Pa, double K_Pa);
  InvariantDerivatives derivatives(const Invariants& v) const;
  double mu0() const { return 2.0 * C10; }
  /// I1b - 3 beyond which dW/dI1b <= 0 (loss of Drucker stability); +inf if never.
  double stability_limit_I1b_minus_3() const;
  static constexpr const char* kName = "yeoh";
  static constexpr bool kUsesI2 = false;  ///< W depends on I1b alone (invariant_stress_batch)
};

/// Neo-Hookean: W = C10 (I1b - 3), mu0 = 2 C10.
struct NeoHookean {
  double C10, K;
  NeoHookean(double C10_Pa, double K_Pa);
  InvariantDerivatives derivatives(const Invariants& v) const;
  double mu0() const { return 2.0 * C10; }
  static constexpr const char* kName = "neo_hookean";
  static constexpr bool kUsesI2 = false;
};

/// Mooney-Rivlin: W = C10 (I1b - 3) + C01 (I2b - 3), mu0 = 2 (C10 + C01).
struct MooneyRivlin {
  double C10, C01, K;
  MooneyRivlin(double C10_Pa, double C01_Pa, double K_Pa);
  InvariantDerivatives derivatives(const Invariants& v) const;
  double mu0() const { return 2.0 * (C10 + C01); }
  static constexpr const char* kName = "mooney_rivlin";
  static constexpr bool kUsesI2 = true;
};

// The laws' scalar derivatives are inline, so that the batched stress (invariant_stress_batch) is
// compiled per law into loops without what the stress does not use (I2 and W11 for Yeoh).
inline InvariantDerivatives Yeoh::derivatives(const Invariants& v) const {
  const double x = v.I1b - 3.0;
  InvariantDerivatives d;
  d.W = x * (C10 + x * (C20 + x * C30));
  d.W1 = C10 + x * (2.0 * C20 + 3.0 * C30 * x);
  d.W11 = 2.0 * C20 + 6.0 * C30 * x;
  volumetric_abaqus(K, v.J, d);
  return d;
}

inline InvariantDerivatives NeoHookean::derivatives(const Invariants& v) const {
  InvariantDerivatives d;
  d.W = C10 * (v.I1b - 3.0);
  d.W1 = C10;
  volumetric_abaqus(K, v.J, d);
  return d;
}

inline InvariantDerivatives MooneyRivlin::derivatives(const Invariants& v) const {
  InvariantDerivatives d;
  d.W = C10 * (v.I1b - 3.0) + C01 * (v.I2b - 3.0);
  d.W1 = C10;
  d.W2 = C01;
  volumetric_abaqus(K, v.J, d);
  return d;
}

/// Wraps an invariant law as a Material (no history).
template <class Law>
class InvariantMaterial final : public Material {
 public:
  explicit InvariantMaterial(Law law) : law_(law) {}
  const Law& law() const { return law_; }
  std::string name() const override { return Law::kName; }
  void evaluate(std::span<const Mat3> F, const TimeStep&, std::span<const double>, std::span<double>,
                std::span<PointResponse> out, bool tangent) const override {
    for (std::size_t q = 0; q < F.size(); ++q) {
      const Invariants v = isochoric_invariants(F[q]);
      invariant_response(F[q], v, law_.derivatives(v), tangent, out[q]);
    }
  }
  void stress(StressBatch& b, const TimeStep&, std::span<const double>, std::span<double>) const override {
    invariant_stress_batch(law_, b);
  }
  double initial_shear_modulus() const override { return law_.mu0(); }
  double initial_bulk_modulus() const override { return law_.K; }

 private:
  Law law_;
};

/// St Venant-Kirchhoff ("linear elastic" at finite rotation, as Abaqus/CalculiX *ELASTIC with
/// NLGEOM): S = lambda tr(E) I + 2 mu E, E = (C - I)/2. Used for the fabric layer
/// (E = 6.5 GPa, nu = 0.2). Not split: its whole response is reported as "iso".
class SaintVenantKirchhoff final : public Material {
 public:
  SaintVenantKirchhoff(double E_Pa, double nu);
  std::string name() const override { return "linear_elastic"; }
  void evaluate(std::span<const Mat3> F, const TimeStep&, std::span<const double>, std::span<double>,
                std::span<PointResponse> out, bool tangent) const override;
  void stress(StressBatch& b, const TimeStep&, std::span<const double>, std::span<double>) const override;
  double initial_shear_modulus() const override { return mu_; }
  double initial_bulk_modulus() const override { return lambda_ + 2.0 * mu_ / 3.0; }
  bool is_split() const override { return false; }
  double youngs_modulus() const { return E_; }
  double poisson_ratio() const { return nu_; }

 private:
  double E_, nu_, lambda_, mu_;
};

/// Bulk modulus from the initial shear modulus and the ratio K0/mu0 (scene parameter, default 100).
double bulk_from_ratio(double mu0_Pa, double K_over_mu);

}  // namespace pneufem
