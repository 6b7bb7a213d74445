// The material test battery: every material runs the same parameterised
// suite, and every family's parameter validation is checked with its message.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <random>

#include "core/errors.h"
#include "materials/hyperelastic.h"
#include "materials/ogden.h"
#include "materials/scaled.h"
#include "tests/materials/material_test_utils.h"

namespace pneufem {
namespace {

using test::battery_states;
using test::eval;
using test::max_abs;
using ::testing::HasSubstr;

constexpr double kEps = std::numeric_limits<double>::epsilon();

// Central differences with h = cbrt(eps) s (s = RMS stretch |F|/sqrt(3)) balance the truncation error
// h^2/6 |f'''| against the round-off ~c eps |f|/h: both are then eps^{2/3} = 3.7e-11 times the stress or
// tangent scale M (largest |P| or |A| entry at the state, at least mu0) times a law-dependent constant.
// Truncation: for power-law terms lambda^alpha, |f'''| ~ (|alpha| + 2)^3/6 (s/lambda_min)^2 M/s, i.e. ~360
// for alpha = 5, lambda_min = 0.6 -> 1.3e-8 M. Round-off: c ~ 1e3 covers the cancellation in the
// deviatoric projections and in J - 1 with K = 100 mu0 -> 3.7e-8 M. kFdTol = 1e-7 M bounds the sum. The
// worst observed error is 1.5e-10 M (7e-10 M for a 1-term Ogden with alpha = -6), while scaling one
// term of the kernel tangent by 1 + 1e-4 was caught when tried.
const double kStep = std::cbrt(kEps);
constexpr double kFdTol = 1e-7;
// Identities that hold exactly in exact arithmetic (objectivity, isotropy, symmetry, F = I) differ only
// by the rounding of a few dozen operations on O(M) numbers: 1e-10 M is ~5e5 eps of headroom.
constexpr double kRoundTol = 1e-10;

struct MaterialCase {
  std::string name;
  std::function<MaterialPtr()> make;
};

template <class Law>
MaterialPtr invariant(Law law) {
  return std::make_shared<InvariantMaterial<Law>>(law);
}

MaterialPtr treloar_ogden(int terms) {
  return std::make_shared<Ogden>(test::treloar_ogden1972(100.0, terms));
}

const std::vector<MaterialCase>& material_cases() {
  constexpr double C10 = 0.019e6, C20 = 9.0e2, C30 = -4.75;  // Ecoflex 00-50, Pa
  constexpr double K = 100.0 * 2.0 * C10;
  static const std::vector<MaterialCase> cases{
      {"yeoh_order1", [] { return invariant(Yeoh(C10, 0.0, 0.0, K)); }},
      {"yeoh_order2", [] { return invariant(Yeoh(C10, C20, 0.0, K)); }},
      {"yeoh_ecoflex0050", [] { return invariant(Yeoh(C10, C20, C30, K)); }},
      {"neo_hookean", [] { return invariant(NeoHookean(0.1e6, 20e6)); }},
      {"mooney_rivlin", [] { return invariant(MooneyRivlin(0.08e6, 0.02e6, 20e6)); }},
      {"ogden_1term", [] { return treloar_ogden(1); }},
      {"ogden_2terms", [] { return treloar_ogden(2); }},
      {"ogden_3terms", [] { return treloar_ogden(3); }},
      {"saint_venant_kirchhoff", [] { return std::make_shared<SaintVenantKirchhoff>(6.5e9, 0.2); }},
  };
  return cases;
}

/// Kronecker product of two 3x3 matrices: vec(B X A^T) = kron(A, B) vec(X) for column-major vec.
Mat9 kron(const Mat3& A, const Mat3& B) {
  Mat9 K;
  for (int p = 0; p < 3; ++p)
    for (int q = 0; q < 3; ++q) K.block<3, 3>(3 * p, 3 * q) = A(p, q) * B;
  return K;
}

double scale_P(const PointResponse& r, double mu0) { return std::max({max_abs(r.P_iso), max_abs(r.P_vol), mu0}); }
double scale_A(const PointResponse& r, double mu0) { return std::max({max_abs(r.A_iso), max_abs(r.A_vol), mu0}); }

class MaterialBattery : public ::testing::TestWithParam<MaterialCase> {
 protected:
  void SetUp() override {
    material = GetParam().make();
    mu0 = material->initial_shear_modulus();
  }
  MaterialPtr material;
  double mu0 = 0.0;
};

// (a) Zero energy and stress in the reference state, and the tangent there equals the isotropic
// small-strain moduli the material reports (used by the engine for stable-step estimates):
// A_iJkL(I) = (K - 2 mu0/3) d_iJ d_kL + mu0 (d_ik d_JL + d_iL d_Jk).
TEST_P(MaterialBattery, ZeroStressAtIdentityAndTangentGivesInitialModuli) {
  const PointResponse r = eval(*material, Mat3::Identity());
  EXPECT_LE(std::abs(r.psi_iso) + std::abs(r.psi_vol), kRoundTol * mu0);
  EXPECT_LE(max_abs(r.P_iso) + max_abs(r.P_vol), kRoundTol * mu0);
  const double K = material->initial_bulk_modulus(), lambda = K - 2.0 * mu0 / 3.0;
  Mat9 expected = Mat9::Zero();
  for (int i = 0; i < 3; ++i)
    for (int k = 0; k < 3; ++k) {
      expected(flat(i, i), flat(k, k)) += lambda;
      expected(flat(i, k), flat(i, k)) += mu0;
      expected(flat(i, k), flat(k, i)) += mu0;
    }
  EXPECT_LE(max_abs(r.A() - expected), kRoundTol * std::max(K, mu0)) << "\nA(I) =\n" << r.A();
}

// (b) P = dpsi/dF, separately for the isochoric and volumetric parts.
TEST_P(MaterialBattery, StressIsEnergyGradient) {
  for (const test::State& st : battery_states()) {
    SCOPED_TRACE(st.label);
    const PointResponse r = eval(*material, st.F, false);
    const double h = kStep * st.F.norm() / std::sqrt(3.0);
    Mat3 P_iso_fd, P_vol_fd;
    for (int k = 0; k < 3; ++k)
      for (int L = 0; L < 3; ++L) {
        Mat3 Fp = st.F, Fm = st.F;
        Fp(k, L) += h;
        Fm(k, L) -= h;
        const PointResponse rp = eval(*material, Fp, false), rm = eval(*material, Fm, false);
        P_iso_fd(k, L) = (rp.psi_iso - rm.psi_iso) / (2.0 * h);
        P_vol_fd(k, L) = (rp.psi_vol - rm.psi_vol) / (2.0 * h);
      }
    const double M = scale_P(r, mu0);
    EXPECT_LE(max_abs(P_iso_fd - r.P_iso), kFdTol * M) << "P_iso =\n" << r.P_iso << "\nFD =\n" << P_iso_fd;
    EXPECT_LE(max_abs(P_vol_fd - r.P_vol), kFdTol * M) << "P_vol =\n" << r.P_vol << "\nFD =\n" << P_vol_fd;
    if (st.generic) {  // guard against a vacuous pass on all-zero stresses
      EXPECT_GT(max_abs(r.P_iso), 1e-3 * mu0);
      if (material->is_split()) {
        EXPECT_GT(max_abs(r.P_vol), 1e-3 * mu0);
      }
    }
  }
}

// (c) A = dP/dF: isochoric, volumetric and total tangents against central differences of P.
TEST_P(MaterialBattery, TangentIsStressGradient) {
  for (const test::State& st : battery_states()) {
    SCOPED_TRACE(st.label);
    const PointResponse r = eval(*material, st.F);
    const double h = kStep * st.F.norm() / std::sqrt(3.0);
    Mat9 A_iso_fd, A_vol_fd;
    for (int k = 0; k < 3; ++k)
      for (int L = 0; L < 3; ++L) {
        Mat3 Fp = st.F, Fm = st.F;
        Fp(k, L) += h;
        Fm(k, L) -= h;
        const PointResponse rp = eval(*material, Fp, false), rm = eval(*material, Fm, false);
        A_iso_fd.col(flat(k, L)) = flatten(rp.P_iso - rm.P_iso) / (2.0 * h);
        A_vol_fd.col(flat(k, L)) = flatten(rp.P_vol - rm.P_vol) / (2.0 * h);
      }
    const double M = scale_A(r, mu0);
    EXPECT_LE(max_abs(A_iso_fd - r.A_iso), kFdTol * M);
    EXPECT_LE(max_abs(A_vol_fd - r.A_vol), kFdTol * M);
    EXPECT_LE(max_abs(A_iso_fd + A_vol_fd - r.A()), 2.0 * kFdTol * M);
    EXPECT_GT(max_abs(r.A_iso), 1e-3 * mu0);
    if (material->is_split()) {
      EXPECT_GT(max_abs(r.A_vol), 1e-3 * mu0);
    }
  }
}

// (c') Why the battery's step is cbrt(eps) s: the tangent's central-difference error against the
// step is a V, truncation ~h^2 on its right arm and round-off ~eps/h on its left, and the battery's
// step lies near its bottom. On the first random state, h/s from 1e-1 to 1e-10 (two per decade):
// the error at the battery's step is within kFdTol and below the error at both ends of the range
// (where one arm dominates). The series are docs/verification.md's figure
// (docs/figures/verification_figures.py derivative).
TEST_P(MaterialBattery, TangentDifferenceErrorIsAVInTheStep) {
  const auto states = battery_states();
  const test::State& st = *std::find_if(states.begin(), states.end(), [](const test::State& x) { return x.generic; });
  const PointResponse r = eval(*material, st.F);
  const double s = st.F.norm() / std::sqrt(3.0), M = scale_A(r, mu0);
  const auto error = [&](double h) {
    Mat9 A_fd;
    for (int k = 0; k < 3; ++k)
      for (int L = 0; L < 3; ++L) {
        Mat3 Fp = st.F, Fm = st.F;
        Fp(k, L) += h;
        Fm(k, L) -= h;
        A_fd.col(flat(k, L)) = flatten(eval(*material, Fp, false).P() - eval(*material, Fm, false).P()) / (2.0 * h);
      }
    return max_abs(A_fd - r.A()) / M;
  };
  for (int i = 2; i <= 20; ++i) {
    const double step = std::pow(10.0, -0.5 * i);
    std::printf("fd series %s: step %.17g error %.17g\n", GetParam().name.c_str(), step, error(step * s));
  }
  const double at_battery = error(kStep * s);
  std::printf("fd battery %s: step %.17g error %.17g\n", GetParam().name.c_str(), kStep, at_battery);
  EXPECT_LE(at_battery, kFdTol);
  EXPECT_LT(at_battery, error(1e-1 * s));   // the truncation arm
  EXPECT_LT(at_battery, error(1e-10 * s));  // the round-off arm
}

// (d) Hyperelastic, so A is a Hessian: A(iJ, kL) = A(kL, iJ).
TEST_P(MaterialBattery, TangentHasMajorSymmetry) {
  for (const test::State& st : battery_states()) {
    const PointResponse r = eval(*material, st.F);
    EXPECT_LE(max_abs(r.A() - r.A().transpose()), kRoundTol * scale_A(r, mu0)) << st.label;
  }
}

// (e) Objectivity: psi(QF) = psi(F), P(QF) = Q P(F), A(QF) = (I kron Q) A(F) (I kron Q)^T.
// (f) Isotropy:    psi(FQ) = psi(F), P(FQ) = P(F) Q, A(FQ) = (Q^T kron I) A(F) (Q^T kron I)^T.
TEST_P(MaterialBattery, ObjectiveAndIsotropic) {
  std::mt19937 rng(7);
  for (const test::State& st : battery_states()) {
    SCOPED_TRACE(st.label);
    const PointResponse r = eval(*material, st.F);
    const double Mpsi = std::max(std::abs(r.psi_iso) + std::abs(r.psi_vol), mu0);
    const double MP = scale_P(r, mu0), MA = scale_A(r, mu0);
    for (int n = 0; n < 3; ++n) {
      const Mat3 Q = test::random_rotation(rng);
      const Mat9 left = kron(Mat3::Identity(), Q), right = kron(Q.transpose(), Mat3::Identity());
      const PointResponse rl = eval(*material, Q * st.F), rr = eval(*material, st.F * Q);
      EXPECT_LE(std::abs(rl.psi() - r.psi()), kRoundTol * Mpsi);
      EXPECT_LE(max_abs(rl.P() - Q * r.P()), kRoundTol * MP);
      EXPECT_LE(max_abs(rl.A() - left * r.A() * left.transpose()), kRoundTol * MA);
      EXPECT_LE(std::abs(rr.psi() - r.psi()), kRoundTol * Mpsi);
      EXPECT_LE(max_abs(rr.P() - r.P() * Q), kRoundTol * MP);
      EXPECT_LE(max_abs(rr.A() - right * r.A() * right.transpose()), kRoundTol * MA);
    }
  }
}

// The split damage/ relies on: psi_iso is invariant under dilatation, hence P_iso : F = 0, and
// psi_vol depends on J only. Unsplit laws must report an empty volumetric part.
TEST_P(MaterialBattery, IsochoricVolumetricSplit) {
  for (const test::State& st : battery_states()) {
    SCOPED_TRACE(st.label);
    const PointResponse r = eval(*material, st.F);
    if (!material->is_split()) {
      EXPECT_EQ(r.psi_vol, 0.0);
      EXPECT_EQ(max_abs(r.P_vol), 0.0);
      EXPECT_EQ(max_abs(r.A_vol), 0.0);
      continue;
    }
    const double J = st.F.determinant();
    const PointResponse dilated = eval(*material, 1.3 * st.F, false);
    const PointResponse spherical = eval(*material, std::cbrt(J) * Mat3::Identity(), false);
    const double Mpsi = std::max(std::abs(r.psi_iso) + std::abs(r.psi_vol), mu0);
    EXPECT_LE(std::abs(dilated.psi_iso - r.psi_iso), kRoundTol * Mpsi);
    EXPECT_LE(std::abs(spherical.psi_vol - r.psi_vol), kRoundTol * Mpsi);
    EXPECT_LE(std::abs((r.P_iso.array() * st.F.array()).sum()), kRoundTol * scale_P(r, mu0) * st.F.norm());
  }
}

// (h) The force kernel's batched entry point (Material::stress, structure-of-arrays) returns what
// evaluate() does, bit for bit: the engine's force-only and force + tangent paths, and 1 or N
// threads, must give identical results. A NaN (inverted point) must stay a NaN.
bool same_bits(double a, double b) { return (std::isnan(a) && std::isnan(b)) || std::memcmp(&a, &b, sizeof a) == 0; }

void expect_batch_matches_evaluate(const Material& m, const std::vector<Mat3>& Fs) {
  for (std::size_t first = 0; first < Fs.size(); first += StressBatch::kLanes) {
    StressBatch b;
    b.n = static_cast<int>(std::min<std::size_t>(StressBatch::kLanes, Fs.size() - first));
    for (int l = 0; l < b.n; ++l) b.set_F(l, Fs[first + l]);
    b.pad();
    m.stress(b, TimeStep{}, {}, {});
    for (int l = 0; l < b.n; ++l) {
      const PointResponse r = eval(m, Fs[first + l], false);
      SCOPED_TRACE("point " + std::to_string(first + l) + ", F =\n" + ::testing::PrintToString(Fs[first + l]));
      EXPECT_PRED2(same_bits, b.psi_iso[l], r.psi_iso);
      EXPECT_PRED2(same_bits, b.psi_vol[l], r.psi_vol);
      for (int k = 0; k < 9; ++k) {
        EXPECT_PRED2(same_bits, b.P_iso[k][l], r.P_iso(k)) << "component " << k;
        EXPECT_PRED2(same_bits, b.P_vol[k][l], r.P_vol(k)) << "component " << k;
      }
    }
  }
}

/// The battery's states, small strains around I (the engine's usual regime, where a different
/// summation order would show in the last bits), and an inverted F; 3 x 8 + 3 points, so the last
/// batch is partial.
std::vector<Mat3> batch_states() {
  std::vector<Mat3> Fs;
  for (const test::State& st : battery_states()) Fs.push_back(st.F);
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> U(-1.0, 1.0);
  while (Fs.size() < 26) {
    Mat3 H;
    for (int k = 0; k < 9; ++k) H(k) = U(rng);
    Fs.push_back(Mat3::Identity() + std::pow(10.0, -6.0 + 5.0 * (U(rng) + 1.0) / 2.0) * H);
  }
  Fs.push_back(Vec3(1.0, 1.0, -0.5).asDiagonal());  // J < 0
  return Fs;
}

TEST_P(MaterialBattery, StressBatchIsEvaluateBitForBit) { expect_batch_matches_evaluate(*material, batch_states()); }

TEST(StressBatch, ScaledMaterialIsEvaluateBitForBit) {
  for (const MaterialCase& c : material_cases()) {
    SCOPED_TRACE(c.name);
    expect_batch_matches_evaluate(*scale_material(c.make(), 0.8), batch_states());
  }
}

INSTANTIATE_TEST_SUITE_P(AllMaterials, MaterialBattery, ::testing::ValuesIn(material_cases()),
                         [](const ::testing::TestParamInfo<MaterialCase>& p) { return p.param.name; });

// (g) Parameter validation: each bad input throws InputError naming the offending key.
template <class Make>
std::string input_error(Make make) {
  try {
    make();
  } catch (const InputError& e) {
    return e.what();
  }
  return "<no InputError thrown>";
}

TEST(MaterialValidation, InvariantLaws) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THAT(input_error([] { Yeoh(0.0, 9e2, -4.75, 1e6); }), HasSubstr("C10 must be > 0"));
  EXPECT_THAT(input_error([] { Yeoh(1.9e4, 9e2, -4.75, -1.0); }), HasSubstr("bulk modulus K"));
  EXPECT_THAT(input_error([=] { Yeoh(1.9e4, nan, -4.75, 1e6); }), HasSubstr("finite"));
  EXPECT_THAT(input_error([] { NeoHookean(-1.0, 1e6); }), HasSubstr("C10 must be > 0"));
  EXPECT_THAT(input_error([] { NeoHookean(1e4, 0.0); }), HasSubstr("bulk modulus K"));
  EXPECT_THAT(input_error([] { MooneyRivlin(1e4, -2e4, 1e6); }), HasSubstr("C10 + C01"));
  EXPECT_THAT(input_error([] { MooneyRivlin(1e4, 1e3, 0.0); }), HasSubstr("bulk modulus K"));
  EXPECT_THAT(input_error([] { bulk_from_ratio(1e4, 0.0); }), HasSubstr("K0/mu0"));
  EXPECT_THAT(input_error([] { Yeoh(1.9e4, 9e2, -4.75, 1e6); }), HasSubstr("no InputError"));
}

TEST(MaterialValidation, SaintVenantKirchhoff) {
  EXPECT_THAT(input_error([] { SaintVenantKirchhoff(0.0, 0.2); }), HasSubstr("Young's modulus E"));
  EXPECT_THAT(input_error([] { SaintVenantKirchhoff(6.5e9, 0.5); }), HasSubstr("Poisson ratio"));
  EXPECT_THAT(input_error([] { SaintVenantKirchhoff(6.5e9, -1.0); }), HasSubstr("Poisson ratio"));
}

TEST(MaterialValidation, Ogden) {
  const double inf = std::numeric_limits<double>::infinity();
  EXPECT_THAT(input_error([] { Ogden({}, {}, 1e6); }), HasSubstr("1 to 3 terms"));
  EXPECT_THAT(input_error([] { Ogden({1e4, 1e4, 1e4, 1e4}, {1, 2, 3, 4}, 1e6); }), HasSubstr("1 to 3 terms"));
  EXPECT_THAT(input_error([] { Ogden({1e4, 1e4}, {2.0}, 1e6); }), HasSubstr("same number of terms"));
  EXPECT_THAT(input_error([] { Ogden({1e4, 1e4}, {2.0, 0.0}, 1e6); }), HasSubstr("alpha_2 must be non-zero"));
  EXPECT_THAT(input_error([=] { Ogden({1e4}, {inf}, 1e6); }), HasSubstr("finite"));
  EXPECT_THAT(input_error([=] { Ogden({1e4}, {2.0}, inf); }), HasSubstr("finite"));
  EXPECT_THAT(input_error([] { Ogden({-1e4}, {2.0}, 1e6); }), HasSubstr("mu0 = sum mu_i must be > 0"));
  EXPECT_THAT(input_error([] { Ogden({1e4}, {2.0}, 0.0); }), HasSubstr("bulk modulus K"));
  // Treloar's set in Ogden's convention passed unconverted: mu_3 = -0.01 MPa with alpha_3 = -2.
  const std::string msg = input_error([] { Ogden({0.63e6, 0.0012e6, -0.01e6}, {1.3, 5.0, -2.0}, 1e9); });
  EXPECT_THAT(msg, HasSubstr("mu_3"));
  EXPECT_THAT(msg, HasSubstr("mu_p alpha_p > 0"));
  EXPECT_THAT(msg, HasSubstr("from_ogden1972"));
  EXPECT_THAT(input_error([] { Ogden::from_ogden1972({0.63e6, 0.0012e6, -0.01e6}, {1.3, 5.0, -2.0}, 1e9); }),
              HasSubstr("no InputError"));
}

}  // namespace
}  // namespace pneufem
