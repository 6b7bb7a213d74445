#pragma once
// Ogden (1972) hyperelastic law, decoupled, in the Abaqus convention:
//   psi = W(lb1, lb2, lb3) + U(J),
//   W   = sum_{i=1..N} 2 mu_i / alpha_i^2 (lb1^alpha_i + lb2^alpha_i + lb3^alpha_i - 3),  N = 1..3,
//   U   = K/2 (J - 1)^2   (volumetric_abaqus, the same U as Yeoh / neo-Hookean / Mooney-Rivlin),
// where lb_a = J^{-1/3} lambda_a are the isochoric principal stretches. Initial shear modulus
// mu0 = sum mu_i, bulk modulus K (Pa).
//
// Conventions. Ogden's paper (Proc. R. Soc. Lond. A 326 (1972) 565) and ANSYS write
//   W = sum_p mu_p / alpha_p (lambda_1^alpha_p + lambda_2^alpha_p + lambda_3^alpha_p - 3),
// which equals the form above when mu_i(Abaqus) = mu_p alpha_p / 2 (from_ogden1972() does this).
// Ogden's per-term stability condition mu_p alpha_p > 0 therefore reads mu_i > 0 here and is enforced
// at construction. A 1972-convention set passed in unconverted is caught only when it has a
// negative-alpha term (stable sets have mu_p < 0 there), so convert explicitly.
// Special cases: N = 1, alpha = 2 is neo-Hookean with C10 = mu/2; alpha = -2 adds C01 = mu/2 (I2b).
//
// The isochoric part is evaluated spectrally on the SVD F = U diag(lambda) V^T; see ogden.cpp
// for the tangent and its treatment of equal principal stretches.
#include <array>
#include <string>
#include <vector>

#include "materials/material.h"

namespace pneufem {

class Ogden final : public Material {
 public:
  static constexpr int kMaxTerms = 3;
  static constexpr const char* kName = "ogden";

  /// mu_Pa[i], alpha[i] in the Abaqus convention (1..3 terms), K_Pa > 0. Throws InputError.
  Ogden(const std::vector<double>& mu_Pa, const std::vector<double>& alpha, double K_Pa);
  /// Constants in Ogden's 1972 convention W = sum mu_p/alpha_p (...): mu_i = mu_p alpha_p / 2.
  static Ogden from_ogden1972(const std::vector<double>& mu_p_Pa, const std::vector<double>& alpha, double K_Pa);

  std::string name() const override { return kName; }
  /// Precondition: det F > 0 at every point (the assembler checks it before evaluating).
  void evaluate(std::span<const Mat3> F, const TimeStep& step, std::span<const double> state_old,
                std::span<double> state_new, std::span<PointResponse> out, bool tangent) const override;
  double initial_shear_modulus() const override { return mu0_; }
  double initial_bulk_modulus() const override { return K_; }

  int terms() const { return n_; }
  double mu(int i) const { return mu_[i]; }        ///< Abaqus mu_i (Pa)
  double alpha(int i) const { return alpha_[i]; }  ///< alpha_i (dimensionless)

 private:
  /// psi_iso, P_iso and (when `tangent`) A_iso of one point; the vol part is filled by the caller.
  void CalcIsochoric(const Mat3& F, bool tangent, PointResponse& out) const;

  int n_ = 0;
  std::array<double, kMaxTerms> mu_{}, alpha_{};
  double K_ = 0.0, mu0_ = 0.0;
};

}  // namespace pneufem
