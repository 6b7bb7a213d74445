// The derivative battery for every decorated material, at a FIXED committed
// history state and increment dt, plus the state layout of nested decorators and their neutral limits.
//
// "Consistent tangent" here means A = dP/dF of the map F -> P(F; committed state, dt) that evaluate()
// implements, where the trial state (W_max, d, Q_i) is itself a function of F.
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <iterator>
#include <ostream>
#include <limits>
#include <random>
#include <string>
#include <vector>

#include "core/errors.h"
#include "damage/effects.h"
#include "damage/material_point.h"
#include "materials/hyperelastic.h"
#include "materials/scaled.h"

namespace pneufem {
namespace {

constexpr double C10 = 0.019e6, C20 = 9.0e2, C30 = -4.75;  // Ecoflex 00-50, Pa
constexpr double K = 100.0 * 2.0 * C10;
constexpr double mu0 = 2.0 * C10;
constexpr double kEps = std::numeric_limits<double>::epsilon();

// Central differences with h = cbrt(eps) s (s = RMS stretch ~ 1.2) balance truncation h^2/6 |P'''| against
// round-off ~c eps |P| / h; tests/materials bounds both for the base laws by kFdTol = 1e-7 M, with
// M = max(|A_iso|, mu0) the tangent scale (c ~ 1e3 makes the round-off 3.7e-8 M).
// A decorator multiplies P0 by a smooth scalar of a driver X (eta(W), 1/(1 + a(X))) or adds a term linear
// in F, so its extra truncation error is ~ h^2/6 (|dX/dF| / X_scale)^3 |P0|, X_scale being the range over
// which the scalar varies: m + beta W_max = 32 kPa for Mullins, x W_th / q ~ 1-5 kPa for fatigue, with
// |dX/dF| = |P0| <~ 1e4 Pa: (1e4 / 1e3)^3 h^2/6 |P0| ~ 1e3 * 9e-12 |P0| < 1e-8 M. The same kFdTol = 1e-7 M
// therefore bounds the error. Observed worst: 1.5e-10 M. Scaling any one consistent-tangent term by
// 1 + 1e-3 (Mullins d eta/dW, fatigue d d/dX and dlambda/dF, viscoelastic c and H) was caught when
// tried, and the guard below asserts the history terms are >= 1e3 kFdTol M (observed >= 5e-2 M), so
// the comparison is never vacuous.
const double kStep = std::cbrt(kEps);
constexpr double kFdTol = 1e-7;
// Identities exact in exact arithmetic (objectivity, zero stress at I) hold to the rounding of a few
// dozen operations on O(M) numbers: 1e-10 M is ~5e5 eps of headroom.
constexpr double kRoundTol = 1e-10;

MaterialPtr ecoflex() { return std::make_shared<InvariantMaterial<Yeoh>>(Yeoh(C10, C20, C30, K)); }

Mat3 uniaxial(double lambda) { return Vec3(lambda, 1.0 / std::sqrt(lambda), 1.0 / std::sqrt(lambda)).asDiagonal(); }

template <class Derived>
double max_abs(const Eigen::MatrixBase<Derived>& a) {
  return a.cwiseAbs().maxCoeff();
}

Mat3 random_rotation(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Eigen::Quaterniond q(n(rng), n(rng), n(rng), n(rng));
  q.normalize();
  return q.toRotationMatrix();
}

Mat9 kron(const Mat3& A, const Mat3& B) {
  Mat9 Kr;
  for (int p = 0; p < 3; ++p)
    for (int q = 0; q < 3; ++q) Kr.block<3, 3>(3 * p, 3 * q) = A(p, q) * B;
  return Kr;
}

/// One evaluation from an explicit committed state; the trial state goes to *trial when given.
PointResponse eval(const Material& m, const Mat3& F, double dt, std::span<const double> committed,
                   std::vector<double>* trial = nullptr, bool tangent = true) {
  std::vector<double> scratch(committed.size());
  std::vector<double>& t = trial ? *trial : scratch;
  t.assign(committed.size(), std::numeric_limits<double>::quiet_NaN());
  PointResponse r;
  m.evaluate(std::span<const Mat3>(&F, 1), TimeStep{1.0 + dt, dt}, committed, t, std::span<PointResponse>(&r, 1),
             tangent);
  return r;
}

struct State {
  std::string label;
  Mat3 F;
};

/// F = I, a rotated uniaxial stretch, a rotated dilatation (zero isochoric energy) and 6 random
/// F = R1 diag(d) R2^T with d in [0.75, 1.45], J in [0.8, 1.25]: moderate enough to stay below the
/// preloaded Mullins peak, distinct principal stretches for the stretch driver.
std::vector<State> battery_states() {
  std::mt19937 rng(20240611);
  const Mat3 R1 = random_rotation(rng), R2 = random_rotation(rng);
  std::vector<State> s{{"identity", Mat3::Identity()},
                       {"uniaxial 1.4 (rotated)", R1 * uniaxial(1.4) * R2.transpose()},
                       {"dilatation 1.05 I (rotated)", R1 * (1.05 * Mat3::Identity()) * R2.transpose()}};
  std::uniform_real_distribution<double> u(0.75, 1.45);
  while (s.size() < 9) {
    const Vec3 d(u(rng), u(rng), u(rng));
    if (d.prod() < 0.8 || d.prod() > 1.25) continue;
    s.push_back({"random " + std::to_string(s.size() - 2), random_rotation(rng) * d.asDiagonal() * random_rotation(rng).transpose()});
  }
  return s;
}

// ---- The decorated materials and the histories that build their committed states. ----
const MullinsParams kMullins{2.0, 20e3, 0.3};
const FatigueParams kFatigue{2e3, 100.0, 2.0, 0.5};
const FatigueParams kFatigueStretch{0.0, 100.0, 2.5, 0.5, FatigueDriver::max_principal_stretch, 1.2};
const ViscoParams kVisco{{0.5, 0.3}, {0.1, 2.0}};  // long_term: the base is the relaxed response
// The same terms with the base as the instantaneous response (Abaqus's MODULI=INSTANTANEOUS).
const ViscoParams kViscoInstantaneous{{0.5, 0.3}, {0.1, 2.0}, ViscoModuli::instantaneous};
const FatigueParams kFatigueInStack{2e3, 50.0, 2.0, 0.95};  // d_fail above the damage the cases reach
// Saturating law (integrity exponent n = 3): the tangent goes through the scalar Newton's ds/da.
const FatigueParams kFatigueSaturating{0.0, 100.0, 2.5, 0.5, FatigueDriver::max_principal_stretch, 1.2, 3.0};

// Non-local drivers (radius 1 mm): the law multiplies its driver by rho = average / local, which
// the engine stores in the committed state; the cases below set rho != 1 both ways.
FatigueParams nonlocal(FatigueParams p) {
  p.nonlocal_radius_m = 1e-3;
  return p;
}
/// Sets rho = average / local in mp's committed state through the material's own protocol.
void set_rho(MaterialPoint& mp, double rho) {
  std::vector<double> s(mp.committed_state().begin(), mp.committed_state().end());
  mp.material().set_nonlocal_driver(s, 1.0, rho);
  mp.set_committed_state(s);
}

MaterialPtr stack() {
  return make_viscoelastic(make_fatigue(make_mullins(ecoflex(), kMullins), kFatigueInStack), kVisco);
}

/// Returns the magnitude of the part of A_iso that is not the base tangent scaled like P0 (the
/// history-dependent term the FD comparison must see), or a negative value when not applicable.
using ExtraTerm = std::function<double(const Mat3& F, double dt, const PointResponse& r)>;

double scaled_extra(const Mat3& F, double, const PointResponse& r) {  // P_iso = s P0_iso, s scalar
  const PointResponse r0 = eval(*ecoflex(), F, 0.0, {});
  const double s = r.P_iso.cwiseProduct(r0.P_iso).sum() / r0.P_iso.squaredNorm();
  return max_abs(r.A_iso - s * r0.A_iso);
}

// P_iso = b P0 + F H with b = beta + sum a_i k_i, a_i = beta gamma_i, beta = 1 (long_term) or
// 1 / (1 + sum gamma) (instantaneous): the part of A_iso beyond b A0_iso is delta (x) H.
ExtraTerm visco_extra(const ViscoParams& p) {
  return [p](const Mat3& F, double dt, const PointResponse& r) {
    const PointResponse r0 = eval(*ecoflex(), F, 0.0, {});
    double sum = 0.0;
    for (double g : p.gamma) sum += g;
    const double beta = p.moduli == ViscoModuli::instantaneous ? 1.0 / (1.0 + sum) : 1.0;
    double b = beta;
    for (std::size_t i = 0; i < p.gamma.size(); ++i) {
      const double x = dt / p.tau_s[i];
      b += beta * p.gamma[i] * (x > 0.0 ? -std::expm1(-x) / x : 1.0);
    }
    return max_abs(r.A_iso - b * r0.A_iso);
  };
}

struct Case {
  std::string name;
  std::function<MaterialPtr()> make;
  std::function<void(MaterialPoint&)> history;
  double dt;       ///< increment of the battery evaluations (s)
  bool potential;  ///< P_iso = d psi_iso / dF at the fixed committed state
  ExtraTerm extra;
};

std::vector<Case> cases() {
  return {
      {"mullins_virgin", [] { return make_mullins(ecoflex(), kMullins); }, [](MaterialPoint&) {}, 0.0, true, nullptr},
      {"mullins_preloaded", [] { return make_mullins(ecoflex(), kMullins); },
       [](MaterialPoint& mp) { mp.advance(uniaxial(2.0), 0.0); }, 0.0, true, scaled_extra},
      {"fatigue_energy", [] { return make_fatigue(ecoflex(), kFatigue); },
       [](MaterialPoint& mp) { mp.advance(uniaxial(1.8), 0.5); },  // 1 - d = 0.56
       1.0, false, scaled_extra},
      {"fatigue_energy_static", [] { return make_fatigue(ecoflex(), kFatigue); },  // dt = 0: elastic, scaled
       [](MaterialPoint& mp) { mp.advance(uniaxial(1.8), 0.5); }, 0.0, true, nullptr},
      {"fatigue_stretch", [] { return make_fatigue(ecoflex(), kFatigueStretch); },
       [](MaterialPoint& mp) {
         for (int n = 0; n < 3; ++n) mp.advance(uniaxial(1.8), 10.0);
       },
       10.0, false, nullptr},  // dX/dF = F n n / lambda is not P0: no simple guard, exercised by the FD
      {"fatigue_stretch_saturating", [] { return make_fatigue(ecoflex(), kFatigueSaturating); },
       [](MaterialPoint& mp) {
         for (int n = 0; n < 3; ++n) mp.advance(uniaxial(1.8), 10.0);
       },
       10.0, false, nullptr},
      {"fatigue_energy_nonlocal_below_average", [] { return make_fatigue(ecoflex(), nonlocal(kFatigue)); },
       [](MaterialPoint& mp) {
         mp.advance(uniaxial(1.8), 0.5);
         set_rho(mp, 1.25);  // a point below its neighbourhood: damage driven harder
       },
       1.0, false, scaled_extra},
      {"fatigue_stretch_nonlocal_above_average", [] { return make_fatigue(ecoflex(), nonlocal(kFatigueStretch)); },
       [](MaterialPoint& mp) {
         for (int n = 0; n < 3; ++n) mp.advance(uniaxial(1.8), 10.0);
         set_rho(mp, 0.9);  // a hot spot: capped at its neighbourhood's average
       },
       10.0, false, nullptr},
      {"viscoelastic", [] { return make_viscoelastic(ecoflex(), kVisco); },
       [](MaterialPoint& mp) {
         std::mt19937 rng(5);
         const Mat3 R = random_rotation(rng);
         for (int n = 1; n <= 5; ++n) mp.advance(R * uniaxial(1.0 + 0.1 * n), 0.05);
       },
       0.05, false, visco_extra(kVisco)},
      {"viscoelastic_instantaneous", [] { return make_viscoelastic(ecoflex(), kViscoInstantaneous); },
       [](MaterialPoint& mp) {
         std::mt19937 rng(5);
         const Mat3 R = random_rotation(rng);
         for (int n = 1; n <= 5; ++n) mp.advance(R * uniaxial(1.0 + 0.1 * n), 0.05);
       },
       0.05, false, visco_extra(kViscoInstantaneous)},
      {"viscoelastic_instantaneous_glassy", [] { return make_viscoelastic(ecoflex(), kViscoInstantaneous); },
       [](MaterialPoint& mp) {  // dt = 0 from a loaded state: b = 1 exactly, the H term alone
         for (int n = 1; n <= 3; ++n) mp.advance(uniaxial(1.0 + 0.15 * n), 0.3);
       },
       0.0, false, visco_extra(kViscoInstantaneous)},
      {"visco_fatigue_mullins_stack", stack,
       [](MaterialPoint& mp) {
         mp.advance(uniaxial(2.0), 0.0);                             // Mullins preload, no time
         for (int n = 0; n < 3; ++n) mp.advance(uniaxial(1.6), 1.0);  // fatigue damage, visco relaxes
         for (int n = 1; n <= 3; ++n) mp.advance(uniaxial(1.6 - 0.1 * n), 0.05);  // leaves overstress Q_i
       },
       0.05, false, nullptr},
  };
}

void PrintTo(const Case& c, std::ostream* os) { *os << c.name; }

class DecoratorBattery : public ::testing::TestWithParam<Case> {
 protected:
  void SetUp() override {
    material = GetParam().make();
    MaterialPoint mp(material);
    GetParam().history(mp);
    committed = std::vector<double>(mp.committed_state().begin(), mp.committed_state().end());
  }
  MaterialPtr material;
  std::vector<double> committed;
};

// (c) A = dP/dF by central differences at the fixed committed state; the volumetric part is the
// base's, bit for bit.
TEST_P(DecoratorBattery, TangentIsConsistentDerivativeOfStress) {
  const double dt = GetParam().dt;
  double extra_max = 0.0, M_max = 0.0;
  for (const State& st : battery_states()) {
    SCOPED_TRACE(st.label);
    const PointResponse r = eval(*material, st.F, dt, committed);
    const double h = kStep * st.F.norm() / std::sqrt(3.0);
    Mat9 A_fd;
    for (int k = 0; k < 3; ++k)
      for (int L = 0; L < 3; ++L) {
        Mat3 Fp = st.F, Fm = st.F;
        Fp(k, L) += h;
        Fm(k, L) -= h;
        const PointResponse rp = eval(*material, Fp, dt, committed, nullptr, false);
        const PointResponse rm = eval(*material, Fm, dt, committed, nullptr, false);
        A_fd.col(flat(k, L)) = flatten(rp.P_iso - rm.P_iso) / (2.0 * h);
      }
    const double M = std::max(max_abs(r.A_iso), mu0);
    EXPECT_LE(max_abs(A_fd - r.A_iso), kFdTol * M) << "A_iso =\n" << r.A_iso << "\nFD =\n" << A_fd;
    const PointResponse r0 = eval(*ecoflex(), st.F, 0.0, {});
    EXPECT_EQ(r.P_vol, r0.P_vol);
    EXPECT_EQ(r.A_vol, r0.A_vol);
    EXPECT_EQ(r.psi_vol, r0.psi_vol);
    if (GetParam().extra) extra_max = std::max(extra_max, GetParam().extra(st.F, dt, r) / M);
    M_max = std::max(M_max, M);
  }
  // Guard: the history-dependent tangent terms are large enough for the comparison to see them.
  if (GetParam().extra) {
    EXPECT_GT(extra_max, 1e3 * kFdTol);
  }
}

// (b) Where the law is hyperelastic at a fixed committed state (Mullins, with the damage function
// phi in psi_iso; fatigue at dt = 0, a static solve), P_iso = d psi_iso / dF. The other cases are
// dissipative within the increment and are not instantiated here.
class HyperelasticBattery : public DecoratorBattery {};

TEST_P(HyperelasticBattery, StressIsEnergyGradient) {
  const double dt = GetParam().dt;
  for (const State& st : battery_states()) {
    SCOPED_TRACE(st.label);
    const PointResponse r = eval(*material, st.F, dt, committed, nullptr, false);
    const double h = kStep * st.F.norm() / std::sqrt(3.0);
    Mat3 P_fd;
    for (int k = 0; k < 3; ++k)
      for (int L = 0; L < 3; ++L) {
        Mat3 Fp = st.F, Fm = st.F;
        Fp(k, L) += h;
        Fm(k, L) -= h;
        P_fd(k, L) = (eval(*material, Fp, dt, committed, nullptr, false).psi_iso -
                      eval(*material, Fm, dt, committed, nullptr, false).psi_iso) /
                     (2.0 * h);
      }
    EXPECT_LE(max_abs(P_fd - r.P_iso), kFdTol * std::max(max_abs(r.P_iso), mu0)) << "P_iso =\n" << r.P_iso << "\nFD =\n" << P_fd;
  }
}

// (a) Zero energy and stress at F = I from the virgin state, with and without elapsed time, whether
// the virgin state is passed explicitly or as an empty span; at dt = 0 the tangent there is the
// isotropic small-strain tangent of the moduli the law reports (the instantaneous ones).
TEST_P(DecoratorBattery, ZeroStressAtIdentityFromVirginState) {
  std::vector<double> virgin(static_cast<std::size_t>(material->state_size()));
  material->init_state(virgin);
  for (double dt : {0.0, GetParam().dt, 10.0}) {
    for (const bool explicit_state : {true, false}) {
      const PointResponse r =
          eval(*material, Mat3::Identity(), dt, explicit_state ? std::span<const double>(virgin) : std::span<const double>{});
      EXPECT_LE(std::abs(r.psi_iso) + std::abs(r.psi_vol), kRoundTol * mu0) << "dt = " << dt;
      EXPECT_LE(max_abs(r.P_iso) + max_abs(r.P_vol), kRoundTol * mu0) << "dt = " << dt;
      if (dt != 0.0) continue;
      const double mu = material->initial_shear_modulus(), Kb = material->initial_bulk_modulus();
      Mat9 expected = Mat9::Zero();
      for (int i = 0; i < 3; ++i)
        for (int k = 0; k < 3; ++k) {
          expected(flat(i, i), flat(k, k)) += Kb - 2.0 * mu / 3.0;
          expected(flat(i, k), flat(i, k)) += mu;
          expected(flat(i, k), flat(k, i)) += mu;
        }
      EXPECT_LE(max_abs(r.A() - expected), kRoundTol * Kb);
    }
  }
}

// (e) Objectivity with a history: the committed state lives in the reference configuration, so
// psi(QF) = psi(F), P(QF) = Q P(F), A(QF) = (I kron Q) A(F) (I kron Q)^T, and the trial state is unchanged.
TEST_P(DecoratorBattery, ObjectiveWithHistory) {
  std::mt19937 rng(7);
  const double dt = GetParam().dt;
  for (const State& st : battery_states()) {
    SCOPED_TRACE(st.label);
    std::vector<double> trial, trial_q;
    const PointResponse r = eval(*material, st.F, dt, committed, &trial);
    const double MP = std::max(max_abs(r.P()), mu0), MA = std::max(max_abs(r.A()), mu0);
    for (int n = 0; n < 2; ++n) {
      const Mat3 Q = random_rotation(rng);
      const Mat9 left = kron(Mat3::Identity(), Q);
      const PointResponse rq = eval(*material, Q * st.F, dt, committed, &trial_q);
      EXPECT_LE(std::abs(rq.psi() - r.psi()), kRoundTol * std::max(std::abs(r.psi()), mu0));
      EXPECT_LE(max_abs(rq.P() - Q * r.P()), kRoundTol * MP);
      EXPECT_LE(max_abs(rq.A() - left * r.A() * left.transpose()), kRoundTol * MA);
      for (std::size_t i = 0; i < trial.size(); ++i)
        EXPECT_NEAR(trial_q[i], trial[i], kRoundTol * std::max(1.0, std::abs(trial[i]))) << "state[" << i << "]";
    }
  }
}

// Purity: evaluate() reads the committed state only; the response and trial state do not depend on
// whether a tangent or a trial state is requested, and repeated calls agree bit for bit.
TEST_P(DecoratorBattery, EvaluationIsPure) {
  const double dt = GetParam().dt;
  const std::vector<double> before = committed;
  for (const State& st : battery_states()) {
    SCOPED_TRACE(st.label);
    std::vector<double> t1, t2;
    const PointResponse a = eval(*material, st.F, dt, committed, &t1, true);
    const PointResponse b = eval(*material, st.F, dt, committed, &t2, false);
    EXPECT_EQ(a.P_iso, b.P_iso);
    EXPECT_EQ(a.psi_iso, b.psi_iso);
    EXPECT_EQ(t1, t2);
    PointResponse c;
    material->evaluate(std::span<const Mat3>(&st.F, 1), TimeStep{1.0 + dt, dt}, committed, {},
                       std::span<PointResponse>(&c, 1), true);
    EXPECT_EQ(a.P_iso, c.P_iso);
    EXPECT_EQ(a.A_iso, c.A_iso);
  }
  EXPECT_EQ(committed, before);
}

// Several points in one call: point q's block is [q * state_size, (q + 1) * state_size).
TEST_P(DecoratorBattery, MultiPointCallMatchesSinglePoints) {
  const double dt = GetParam().dt;
  const std::vector<State> states = battery_states();
  const std::size_t n = states.size(), ss = static_cast<std::size_t>(material->state_size());
  std::vector<Mat3> F;
  std::vector<double> old_all, new_all(n * ss);
  for (std::size_t q = 0; q < n; ++q) {  // a different committed state per point: history then one more step
    F.push_back(states[q].F);
    MaterialPoint mp(material);
    mp.set_committed_state(committed);
    mp.advance(states[(q + 1) % n].F, dt);
    old_all.insert(old_all.end(), mp.committed_state().begin(), mp.committed_state().end());
  }
  std::vector<PointResponse> out(n);
  material->evaluate(F, TimeStep{1.0 + dt, dt}, old_all, new_all, out, true);
  for (std::size_t q = 0; q < n; ++q) {
    std::vector<double> trial;
    const PointResponse r = eval(*material, F[q], dt, std::span<const double>(old_all).subspan(q * ss, ss), &trial);
    EXPECT_EQ(out[q].P_iso, r.P_iso) << "point " << q;
    EXPECT_EQ(out[q].A_iso, r.A_iso) << "point " << q;
    EXPECT_EQ(std::vector<double>(new_all.begin() + q * ss, new_all.begin() + (q + 1) * ss), trial) << "point " << q;
  }
}

// The force kernel's batched entry point (Material::stress) of a law with history: the engine
// passes one element's points (4 for a quadratic tet) with their state blocks. psi, P and the
// trial state must be evaluate()'s bit for bit. DecoratorBatch below covers the nestings, batch
// sizes, mixed histories and state conventions.
TEST_P(DecoratorBattery, StressBatchIsEvaluateBitForBit) {
  const double dt = GetParam().dt;
  const std::vector<State> states = battery_states();
  const std::size_t n = 4, ss = static_cast<std::size_t>(material->state_size());
  StressBatch b;
  b.n = static_cast<int>(n);
  std::vector<double> old_all, new_all(n * ss, std::numeric_limits<double>::quiet_NaN());
  for (std::size_t q = 0; q < n; ++q) {
    b.set_F(static_cast<int>(q), states[q + 1].F);
    old_all.insert(old_all.end(), committed.begin(), committed.end());
  }
  b.pad();
  material->stress(b, TimeStep{1.0 + dt, dt}, old_all, new_all);
  for (std::size_t q = 0; q < n; ++q) {
    const int l = static_cast<int>(q);
    std::vector<double> trial;
    const PointResponse r = eval(*material, states[q + 1].F, dt, committed, &trial, false);
    EXPECT_EQ(b.psi_iso[l], r.psi_iso) << "point " << q;
    EXPECT_EQ(b.psi_vol[l], r.psi_vol) << "point " << q;
    EXPECT_EQ(b.F_of(l), states[q + 1].F);
    for (int k = 0; k < 9; ++k) {
      EXPECT_EQ(b.P_iso[k][l], r.P_iso(k)) << "point " << q << " component " << k;
      EXPECT_EQ(b.P_vol[k][l], r.P_vol(k)) << "point " << q << " component " << k;
    }
    EXPECT_EQ(std::vector<double>(new_all.begin() + q * ss, new_all.begin() + (q + 1) * ss), trial) << "point " << q;
  }
}

std::string case_name(const ::testing::TestParamInfo<Case>& i) { return i.param.name; }

std::vector<Case> hyperelastic_cases() {
  std::vector<Case> all = cases(), out;
  std::copy_if(all.begin(), all.end(), std::back_inserter(out), [](const Case& c) { return c.potential; });
  return out;
}

INSTANTIATE_TEST_SUITE_P(Decorated, DecoratorBattery, ::testing::ValuesIn(cases()), case_name);
INSTANTIATE_TEST_SUITE_P(Decorated, HyperelasticBattery, ::testing::ValuesIn(hyperelastic_cases()), case_name);

// ---- The batched force-only path (Material::stress) of every nesting. ----
//
// Each decorator overrides stress(): the base's batched stress (stress_base gathers the base's state
// slices), then its own arithmetic (Viscoelastic in structure-of-arrays form, with Eigen's summation
// orders; fatigue's stretch driver skips the eigenvalues below a bound). psi, P and the trial state
// must be evaluate()'s bit for bit, signed zeros included, for every base law, nesting, batch size,
// history, increment and state convention (empty state_old = virgin, empty state_new = no trial).

bool same_bits(double a, double b) { return (std::isnan(a) && std::isnan(b)) || std::memcmp(&a, &b, sizeof a) == 0; }

// The story's effects (scenes/examples/paper_story.toml): stretch-driven saturating fatigue.
const MullinsParams kMullinsStory{8.0, 10e3, 0.1};
const FatigueParams kFatigueStory{0.0, 160.0, 1.0, 0.9, FatigueDriver::max_principal_stretch, 1.6, 10.0};
const ViscoParams kViscoStory{{0.1}, {6.0}};

struct BatchCase {
  std::string name;
  MaterialPtr material;
};

std::vector<BatchCase> batch_cases() {
  const MaterialPtr yeoh = ecoflex(), scaled = scale_material(ecoflex(), 0.7);
  const MaterialPtr mooney = std::make_shared<InvariantMaterial<MooneyRivlin>>(MooneyRivlin(0.6 * C10, 0.4 * C10, K));
  const ViscoParams visco3{{0.4, 0.0, 0.2}, {0.05, 1.0, 20.0}};  // gamma = 0: a branch without energy
  const auto story = [](MaterialPtr base, const FatigueParams& f) {
    return decorate(std::move(base), {kMullinsStory, f, kViscoStory});
  };
  return {
      {"mullins", make_mullins(yeoh, kMullins)},
      {"fatigue_energy", make_fatigue(yeoh, kFatigue)},
      {"fatigue_stretch", make_fatigue(yeoh, kFatigueStretch)},
      {"fatigue_stretch_saturating", make_fatigue(yeoh, kFatigueSaturating)},
      {"viscoelastic", make_viscoelastic(yeoh, kVisco)},
      {"viscoelastic_3_terms", make_viscoelastic(yeoh, visco3)},
      {"viscoelastic_instantaneous", make_viscoelastic(yeoh, kViscoInstantaneous)},
      {"viscoelastic_3_terms_instantaneous",
       make_viscoelastic(yeoh, ViscoParams{visco3.gamma, visco3.tau_s, ViscoModuli::instantaneous})},
      {"stack_energy_instantaneous", decorate(scaled, {kMullins, kFatigueInStack, kViscoInstantaneous})},
      {"fatigue_mullins", make_fatigue(make_mullins(yeoh, kMullins), kFatigueInStack)},
      {"viscoelastic_mullins", make_viscoelastic(make_mullins(yeoh, kMullins), kVisco)},
      {"stack_energy", stack()},
      {"stack_energy_scaled", decorate(scaled, {kMullins, kFatigueInStack, kVisco})},
      {"story_stack", story(yeoh, kFatigueStory)},
      {"story_stack_scaled", story(scaled, kFatigueStory)},
      {"story_stack_mooney_rivlin", story(mooney, kFatigueStory)},  // a base law of I2b: no batched kernel
      {"story_stack_nonlocal", story(yeoh, nonlocal(kFatigueStory))},  // rho != 1 in the committed states
      {"fatigue_energy_nonlocal", make_fatigue(yeoh, nonlocal(kFatigue))},
      // The outer base's state (2 x 24 doubles) exceeds stress_base's buffers: the point-by-point path.
      {"viscoelastic_nested_deep",
       make_viscoelastic(make_viscoelastic(make_viscoelastic(yeoh, visco3), visco3), visco3)},
  };
}

/// The batches' deformation gradients: F = I, small strains around I (where another summation order
/// would show in the last bits), a dilatation, an inverted point (NaN must stay NaN), stretches either
/// side of the stretch thresholds 1.2 and 1.6 - inside and outside the 1e-6 margin of fatigue's
/// eigenvalue-skipping bound, which is tight for a uniaxial stretch - and rotated finite strains
/// with principal stretches in [0.6, 2.2].
std::vector<Mat3> batch_F() {
  std::mt19937 rng(99);
  std::uniform_real_distribution<double> U(-1.0, 1.0), stretch(0.6, 2.2);
  std::vector<Mat3> Fs{Mat3::Identity(), 1.05 * Mat3::Identity(), Vec3(1.0, 1.0, -0.5).asDiagonal()};
  for (int i = 0; i < 8; ++i) {
    Mat3 H;
    for (int k = 0; k < 9; ++k) H(k) = U(rng);
    Fs.push_back(Mat3::Identity() + std::pow(10.0, -6.0 + 5.0 * (U(rng) + 1.0) / 2.0) * H);
  }
  for (double th : {1.2, 1.6})
    for (double rel : {-1e-3, -2e-6, -5e-7, -2e-7, 0.0, 2e-7, 5e-7, 1e-3}) {
      const double lambda = th * (1.0 + rel);
      const Mat3 R1 = random_rotation(rng), R2 = random_rotation(rng);
      Fs.push_back(R1 * uniaxial(lambda) * R2.transpose());
      Fs.push_back(R1 * Vec3(lambda, 1.0, 1.0 / lambda).asDiagonal() * R2.transpose());
    }
  while (Fs.size() < 64) {
    const Vec3 d(stretch(rng), stretch(rng), stretch(rng));
    Fs.push_back(random_rotation(rng) * d.asDiagonal() * random_rotation(rng).transpose());
  }
  return Fs;
}

/// Committed states of `m`: virgin, a Mullins preload, a preload held (fatigue damage, relaxation), an
/// overload to fatigue failure (the integrity floor), and random three-step histories.
std::vector<std::vector<double>> committed_states(const MaterialPtr& m, const std::vector<Mat3>& Fs) {
  std::vector<std::vector<double>> out;
  const auto keep = [&out](const MaterialPoint& mp) {
    out.emplace_back(mp.committed_state().begin(), mp.committed_state().end());
  };
  keep(MaterialPoint(m));
  MaterialPoint pre(m);
  pre.advance(uniaxial(2.0), 0.0);
  keep(pre);
  for (int n = 0; n < 3; ++n) pre.advance(uniaxial(1.8), 10.0);
  keep(pre);
  MaterialPoint failed(m);
  failed.advance(uniaxial(2.2), 1e15);  // also saturating laws (n = 10: s ~ a^(-1/10))
  keep(failed);
  std::mt19937 rng(17);
  std::uniform_int_distribution<std::size_t> pick(3, Fs.size() - 1);  // no inverted F in a history
  const double dts[] = {0.0, 0.05, 1.0, 10.0};
  for (int h = 0; h < 8; ++h) {
    MaterialPoint mp(m);
    for (int n = 0; n < 3; ++n) mp.advance(Fs[pick(rng)], dts[(h + n) % 4]);
    keep(mp);
  }
  if (m->nonlocal().radius_m > 0.0) {  // each history also with rho below and above 1
    const std::size_t n = out.size();
    for (std::size_t i = 0; i < n; ++i)
      for (double rho : {0.8, 1.2}) {
        out.push_back(out[i]);
        m->set_nonlocal_driver(out.back(), 1.0, rho);
      }
  }
  return out;
}

TEST(DecoratorBatch, StressIsEvaluateBitForBit) {
  const std::vector<Mat3> Fs = batch_F();
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const BatchCase& c : batch_cases()) {
    SCOPED_TRACE(c.name);
    const Material& m = *c.material;
    const std::size_t ss = static_cast<std::size_t>(m.state_size());
    const std::vector<std::vector<double>> pool = committed_states(c.material, Fs);
    std::mt19937 rng(3);
    std::uniform_int_distribution<std::size_t> pick_F(0, Fs.size() - 1), pick_state(0, pool.size() - 1);
    int mismatches = 0, unloading = 0, growing = 0, at_floor = 0;
    for (double dt : {0.0, 0.05, 1.0, 10.0})
      for (int n : {1, 4, StressBatch::kLanes})
        for (int rep = 0; rep < 6; ++rep) {
          std::vector<std::size_t> fi(n), si(n);
          std::vector<double> old_all;
          for (int l = 0; l < n; ++l) {
            fi[l] = pick_F(rng);
            si[l] = pick_state(rng);
            old_all.insert(old_all.end(), pool[si[l]].begin(), pool[si[l]].end());
          }
          for (const bool virgin : {false, true})
            for (const bool trial : {true, false}) {
              StressBatch b;
              b.n = n;
              for (int l = 0; l < n; ++l) b.set_F(l, Fs[fi[l]]);
              b.pad();
              std::vector<double> new_all(trial ? n * ss : 0, nan);
              const TimeStep ts{1.0 + dt, dt};
              m.stress(b, ts, virgin ? std::span<const double>{} : std::span<const double>(old_all), new_all);
              for (int l = 0; l < n; ++l) {
                const std::span<const double> committed = virgin ? std::span<const double>{} : std::span<const double>(pool[si[l]]);
                std::vector<double> t(trial ? ss : 0, nan);
                PointResponse r;
                m.evaluate(std::span<const Mat3>(&Fs[fi[l]], 1), ts, committed, t, std::span<PointResponse>(&r, 1), false);
                bool same = same_bits(b.psi_iso[l], r.psi_iso) && same_bits(b.psi_vol[l], r.psi_vol);
                for (int k = 0; k < 9; ++k)
                  same = same && same_bits(b.P_iso[k][l], r.P_iso(k)) && same_bits(b.P_vol[k][l], r.P_vol(k));
                for (std::size_t i = 0; i < t.size(); ++i) same = same && same_bits(new_all[l * ss + i], t[i]);
                if (!same && ++mismatches <= 3)
                  ADD_FAILURE() << "dt = " << dt << ", n = " << n << ", lane " << l << (virgin ? ", virgin" : "")
                                << (trial ? "" : ", no trial state") << ", F =\n" << Fs[fi[l]] << "\nbatch psi_iso "
                                << b.psi_iso[l] << " P_iso(0) " << b.P_iso[0][l] << ", evaluate " << r.psi_iso << " "
                                << r.P_iso(0);
                // Guard (story stack [visco 12 | 1 - d | W_max, eta]): the branches that modify the
                // response are exercised, not only the neutral ones.
                if (c.name == "story_stack" && !virgin && trial && std::isfinite(r.psi_iso)) {
                  unloading += t[14] < 1.0;
                  growing += t[12] < pool[si[l]][12];
                  at_floor += t[12] == 1.0 - kFatigueStory.d_fail;
                }
              }
            }
        }
    EXPECT_EQ(mismatches, 0);
    if (c.name == "story_stack") {
      EXPECT_GT(unloading, 20);
      EXPECT_GT(growing, 20);
      EXPECT_GT(at_floor, 5);
    }
  }
}

// ---- State layout of nested decorators. ----

TEST(DecoratorLayout, StackNamesSizesAndVirginState) {
  const MaterialPtr m = stack();
  EXPECT_EQ(m->name(), "viscoelastic(fatigue(mullins(yeoh)))");
  // [visco: S0 + 2 Q_i = 18 | fatigue: 1 - d | mullins: W_max, eta | yeoh: none]
  ASSERT_EQ(m->state_size(), 18 + 1 + 2);
  std::vector<double> s(21, -7.0);
  m->init_state(s);
  for (int i = 0; i < 18; ++i) EXPECT_EQ(s[i], 0.0) << i;
  EXPECT_EQ(s[18], 1.0);  // integrity
  EXPECT_EQ(s[19], 0.0);  // W_max
  EXPECT_EQ(s[20], 1.0);  // eta
  EXPECT_EQ(m->initial_shear_modulus(), (1.0 + 0.5 + 0.3) * mu0);
  EXPECT_EQ(m->initial_bulk_modulus(), K);
}

// Each layer hands its base the tail of the block untouched: the inner laws evaluated alone on their
// slices give the same trial slices, and the outer stress is the outer law applied to the inner one.
TEST(DecoratorLayout, BaseSlicesPassThrough) {
  const MaterialPtr m = stack();
  const MaterialPtr fm = make_fatigue(make_mullins(ecoflex(), kMullins), kFatigueInStack);
  const MaterialPtr mm = make_mullins(ecoflex(), kMullins);
  MaterialPoint mp(m);
  mp.advance(uniaxial(2.0), 0.0);
  for (int n = 0; n < 3; ++n) mp.advance(uniaxial(1.7), 0.5);
  const std::vector<double> old(mp.committed_state().begin(), mp.committed_state().end());
  ASSERT_GT(old[18], 0.0);
  ASSERT_LT(old[18], 1.0);  // some fatigue damage
  ASSERT_GT(old[19], 0.0);  // a Mullins peak

  const Mat3 F = uniaxial(1.4);
  const double dt = 0.3;
  std::vector<double> t_all, t_fm, t_mm;
  eval(*m, F, dt, old, &t_all);
  const PointResponse r_fm = eval(*fm, F, dt, std::span<const double>(old).subspan(18), &t_fm);
  eval(*mm, F, dt, std::span<const double>(old).subspan(19), &t_mm);
  EXPECT_EQ(std::vector<double>(t_all.begin() + 18, t_all.end()), t_fm);
  EXPECT_EQ(std::vector<double>(t_all.begin() + 19, t_all.end()), t_mm);
  EXPECT_LT(t_fm[0], old[18]);  // damage grew in this increment (driver above threshold)

  // The viscoelastic layer sees fatigue(mullins) as its base: a viscoelastic wrapper of the same base
  // object on the same own slice gives the same stress.
  const MaterialPtr v_fm = make_viscoelastic(fm, kVisco);
  const PointResponse r_all = eval(*m, F, dt, old), r_vfm = eval(*v_fm, F, dt, old);
  EXPECT_EQ(r_all.P_iso, r_vfm.P_iso);
  EXPECT_NE(r_all.P_iso, r_fm.P_iso);  // and it does add an overstress

  // Fields combine: W_max from Mullins, damage = 1 - eta (1 - d), viscous strain from the Prony terms.
  const PointFields f = m->fields(old);
  EXPECT_EQ(f.W_max, old[19]);
  EXPECT_NEAR(f.damage, 1.0 - old[20] * old[18], 1e-15);
  EXPECT_GT(f.viscous_strain, 0.0);
  EXPECT_EQ(f.failed, 1.0 - old[18] >= kFatigueInStack.d_fail);
}

// Neutral limits reproduce the base: Mullins on the primary curve and fatigue below the threshold
// (from the virgin state, any dt) bit for bit; viscoelastic fully relaxed, i.e. an increment dt much
// longer than every tau_i, where c = sum gamma_i k_i -> sum gamma_i tau_i / dt:
//  * from the virgin state P_iso = (1 + c) P0_iso exactly, so |P_iso - P0_iso| <= c |P0_iso|;
//  * after a hold at F (Q_i decayed by exp(-1000), S0_old = S0), P_iso - P0_iso = c (P0 - F sym(F^-1 P0))
//    is rounding, while the tangent keeps (1 + c) A0_iso - c delta (x) S0_old.
TEST(DecoratorLayout, NeutralEffectsReproduceTheBase) {
  const MaterialPtr base = ecoflex();
  const MaterialPtr mullins = make_mullins(base, kMullins), fatigue = make_fatigue(base, kFatigue),
                    visco = make_viscoelastic(base, kVisco);
  std::vector<double> v_m(2), v_f(1);
  mullins->init_state(v_m);
  fatigue->init_state(v_f);
  int below = 0;
  for (const State& st : battery_states()) {
    SCOPED_TRACE(st.label);
    const PointResponse r0 = eval(*base, st.F, 0.0, {});
    const PointResponse rm = eval(*mullins, st.F, 0.0, v_m);
    EXPECT_EQ(rm.P_iso, r0.P_iso);
    EXPECT_EQ(rm.A_iso, r0.A_iso);
    EXPECT_EQ(rm.psi_iso, r0.psi_iso);
    if (r0.psi_iso < kFatigue.W_th_Pa) {
      ++below;
      const PointResponse rf = eval(*fatigue, st.F, 100.0, v_f);
      EXPECT_EQ(rf.P_iso, r0.P_iso);
      EXPECT_EQ(rf.A_iso, r0.A_iso);
      EXPECT_EQ(rf.psi_iso, r0.psi_iso);
    }
    const double dt_relax = 1000.0 * 2.0;  // 1000 tau_max
    const double c = (0.5 * 0.1 + 0.3 * 2.0) / dt_relax;
    const double M = std::max(max_abs(r0.P_iso), mu0);
    const PointResponse rv0 = eval(*visco, st.F, dt_relax, {});
    EXPECT_LE(max_abs(rv0.P_iso - r0.P_iso), c * max_abs(r0.P_iso) + kRoundTol * M);
    MaterialPoint mp(visco);
    for (int n = 1; n <= 4; ++n) mp.advance(st.F, 0.05);  // loaded quickly: overstress
    mp.advance(st.F, dt_relax);
    EXPECT_LE(mp.fields().viscous_strain, 1e-12);
    const PointResponse rv = eval(*visco, st.F, dt_relax, mp.committed_state());
    EXPECT_LE(max_abs(rv.P_iso - r0.P_iso), kRoundTol * M);
    const Mat3 S0 = st.F.inverse() * r0.P_iso;
    EXPECT_LE(max_abs(rv.A_iso - r0.A_iso), c * (max_abs(r0.A_iso) + max_abs(S0)) + kRoundTol * M);
  }
  EXPECT_GE(below, 2);  // identity and dilatation at least
}

// Bad parameters of all three effects are rejected with a message naming the parameter.
TEST(DecoratorLayout, BadParametersAreRejectedWithTheParameterNamed) {
  using ::testing::HasSubstr;
  EXPECT_THAT([] { make_mullins(ecoflex(), {0.5, 1e3, 0.0}); },
              ::testing::ThrowsMessage<InputError>(HasSubstr("mullins: r must be > 1")));
  EXPECT_THAT([] { make_fatigue(ecoflex(), {-1.0, 1.0, 2.0, 0.5}); },
              ::testing::ThrowsMessage<InputError>(HasSubstr("fatigue: W_th must be > 0 Pa")));
  EXPECT_THAT([] { make_viscoelastic(ecoflex(), {{0.5}, {-1.0}}); },
              ::testing::ThrowsMessage<InputError>(HasSubstr("viscoelastic: tau_1 must be > 0 s")));
  EXPECT_THAT([] { decorate(std::make_shared<SaintVenantKirchhoff>(6.5e9, 0.2), {kMullins, {}, {}}); },
              ::testing::ThrowsMessage<InputError>(HasSubstr("only applies to split (isochoric/volumetric) laws")));
  // The canonical order always works; decorate() with nothing requested returns the base itself.
  const MaterialPtr base = ecoflex();
  EXPECT_EQ(decorate(base, {}), base);
  EXPECT_EQ(decorate(base, {kMullins, kFatigue, kVisco})->name(), "viscoelastic(fatigue(mullins(yeoh)))");
}

}  // namespace
}  // namespace pneufem
