#pragma once
// Homogeneous tests of an incompressible isotropic hyperelastic solid, in the conventions of
// Abaqus's *UNIAXIAL, *BIAXIAL and *PLANAR TEST DATA (Abaqus Analysis User's Guide, "Hyperelastic
// behavior of rubberlike materials"): the data are nominal stress (force over undeformed area,
// first Piola-Kirchhoff P11) against nominal strain eps = lambda - 1 along the loaded direction 1,
// the specimen stress-free in direction 3:
//   uniaxial     lambda = (l, l^-1/2, l^-1/2)
//   equibiaxial  lambda = (l, l, l^-2)
//   planar       lambda = (l, 1, l^-1)          (pure shear: the width held by the grips)
//
// With the principal Kirchhoff stresses tau_a = lambda_a dW/dlambda_a of any extension of W off
// J = 1 (a pressure term adds the same amount to every tau_a and cancels), the traction-free
// direction 3 gives sigma_1 = tau_1 - tau_3 and the nominal stress of every mode is
//   P = (tau_1 - tau_3) / l.                                                                    (1)
// For the invariant laws, with W1 = dW/dI1, W2 = dW/dI2 (I1 = sum lambda_a^2, I2 = sum lambda_a^-2
// at J = 1), tau_a = 2 W1 lambda_a^2 - 2 W2 lambda_a^-2, so (1) is the textbook
//   uniaxial P = 2 (l - l^-2)(W1 + W2 / l),  equibiaxial P = 2 (l - l^-5)(W1 + l^2 W2),
//   planar   P = 2 (l - l^-3)(W1 + W2)                               (Holzapfel 2000, sec. 7.3);
// for Ogden in the Abaqus convention W = sum 2 mu_i/alpha_i^2 (sum_a lambda_a^alpha_i - 3),
// tau_a = sum 2 mu_i/alpha_i lambda_a^alpha_i and
//   P = sum 2 mu_i/alpha_i (l^(alpha_i - 1) - l^(-c alpha_i - 1)),  c = 1/2, 2, 1 for the three modes.
// Each law is linear in its moduli (C10, C20, ..., mu_i) at fixed exponents alpha_i; the fit uses
// that (fit.h). The 3D laws of materials/ evaluated at F = diag(lambda) agree with (1) to round-off
// (tests/fit/test_incompressible.cpp).
#include <string>
#include <vector>

#include <Eigen/Core>

#include "materials/material.h"
#include "materials/tensor.h"

namespace pneufem::fit {

enum class TestMode { uniaxial, biaxial, planar };
/// "uniaxial", "biaxial", "planar".
const char* mode_name(TestMode m);
/// Principal stretches of mode `m` at stretch `lambda` along the loaded direction (J = 1).
Vec3 mode_stretches(TestMode m, double lambda);

enum class Law { neo_hookean, mooney_rivlin, yeoh, ogden };
/// The scene's model name: "neo_hookean", "mooney_rivlin", "yeoh", "ogden".
const char* law_name(Law law);

/// A law with its constants in SI units, as a scene's [materials.NAME] table holds them.
struct Constants {
  Law law = Law::yeoh;
  /// The moduli (Pa): neo_hookean {C10}; mooney_rivlin {C10, C01}; yeoh {C10, C20, C30};
  /// ogden {mu_1 .. mu_N} in the Abaqus convention.
  std::vector<double> c;
  std::vector<double> alpha;  ///< ogden's exponents (one per mu_i); empty for the other laws
  /// Initial shear modulus mu0 (Pa): 2 C10, 2 (C10 + C01), 2 C10, sum mu_i.
  double mu0() const;
};

/// Number of moduli of `law` (ogden: `ogden_terms`).
int modulus_count(Law law, int ogden_terms);

/// Principal Kirchhoff stress per unit modulus: row k holds d tau_a / d c_k (a = 1..3) at the
/// principal stretches `lambda` (J = 1), exponents `alpha` for ogden.
Eigen::MatrixXd kirchhoff_basis(Law law, const std::vector<double>& alpha, const Vec3& lambda);
/// Nominal stress per unit modulus in mode `m` at stretch `lambda`: entry k is dP/dc_k of (1).
/// Ogden's entries are evaluated as 2 l^-1 (expm1(alpha L) - expm1(-c alpha L)) / alpha, L = ln l,
/// which stays accurate for small alpha and takes the limit 2 (1 + c) L / l at alpha = 0.
Eigen::VectorXd nominal_stress_basis(Law law, const std::vector<double>& alpha, TestMode m, double lambda);
/// Nominal stress (Pa) of the constants in mode `m` at stretch `lambda`, from (1).
double nominal_stress(const Constants& k, TestMode m, double lambda);
/// Isochoric strain energy density W (Pa) at the principal stretches `lambda` (J = 1): the laws' own
/// W (materials/) for the invariant laws, sum 2 mu_i/alpha_i^2 (sum_a lambda_a^alpha_i - 3) for Ogden.
/// The Mullins law is driven by it (fit/inelastic.h).
double strain_energy(const Constants& k, const Vec3& lambda);

/// The 3D law of materials/ with these constants and bulk modulus K_Pa: the constructor checks
/// them (InputError from the law: yeoh C10 > 0, ogden mu_i > 0, ...).
MaterialPtr make_law_material(const Constants& k, double K_Pa);

}  // namespace pneufem::fit
