// Mullins and Prony constants (fit/inelastic.h): the 1-D models against the 3D decorators of damage/
// at the homogeneous state, and round trips from known constants.
#include <gtest/gtest.h>

#include <cmath>

#include "damage/mullins.h"
#include "damage/viscoelastic.h"
#include "fit/inelastic.h"
#include "tests/support/input_error.h"

namespace pneufem::fit {
namespace {

using test::error_of;
constexpr double kMPa = 1e6;

Constants kulkarni() { return {Law::yeoh, {0.019 * kMPa, 9.0e-4 * kMPa, -4.75e-6 * kMPa}, {}}; }

PointResponse eval(const Material& m, const Mat3& F, const TimeStep& step, std::span<const double> old_state,
                   std::span<double> new_state) {
  PointResponse r;
  m.evaluate(std::span<const Mat3>(&F, 1), step, old_state, new_state, std::span<PointResponse>(&r, 1), false);
  return r;
}

/// Nominal stress of a 3D response at F = diag(s), J = 1: (sigma_11 - sigma_33)/s_1 with sigma = P F^T.
double nominal(const PointResponse& r, const Vec3& s) { return (r.P()(0, 0) * s[0] - r.P()(2, 2) * s[2]) / s[0]; }

// eta P0 along a loading-unloading path against damage/'s Mullins decorator evaluated in 3D at
// F = diag(mode_stretches), its state committed at each step. Same W (the base's psi_iso at J = 1 is
// strain_energy), same eta function; the 3D path adds the invariant kernel's round-off: 1e-11 (|P| + mu0).
TEST(MullinsModel, EqualsThe3DDecoratorAtTheHomogeneousState) {
  const Constants base = kulkarni();
  const MullinsParams p{1.8, 0.004 * kMPa, 0.15};
  const Mullins m(make_law_material(base, 100.0 * base.mu0()), p);
  for (TestMode mode : {TestMode::uniaxial, TestMode::biaxial, TestMode::planar}) {
    TestCurve path{mode, "path", {}};
    for (double l : {1.2, 1.6, 2.0, 1.7, 1.3, 1.0, 1.5, 2.0, 2.4, 1.8, 1.1}) path.points.push_back({l, 0.0, 0});
    const std::vector<double> P1d = mullins_stress(path, base, p);
    std::vector<double> state(m.state_size()), next(m.state_size());
    m.init_state(state);
    for (std::size_t i = 0; i < path.points.size(); ++i) {
      SCOPED_TRACE(std::string(mode_name(mode)) + " point " + std::to_string(i));
      const Vec3 s = mode_stretches(mode, path.points[i].stretch);
      const double P3d = nominal(eval(m, Mat3(s.asDiagonal()), TimeStep{}, state, next), s);
      state = next;
      EXPECT_NEAR(P1d[i], P3d, 1e-11 * (std::abs(P3d) + base.mu0()));
    }
  }
}

// g_R(t) against damage/'s viscoelastic decorator (Abaqus g_i converted by prony_from_abaqus, moduli
// instantaneous) under a uniaxial step held for 200 s in steps of 0.5 s: the decorator's update is
// exact for a held strain (its header), so only round-off separates them: 1e-12.
TEST(PronyModel, EqualsThe3DDecoratorUnderAHeldStep) {
  const std::vector<double> g{0.2, 0.1}, tau{2.0, 40.0};
  const Constants base = kulkarni();
  const Viscoelastic v(make_law_material(base, 100.0 * base.mu0()), prony_from_abaqus(g, tau));
  const Vec3 s = mode_stretches(TestMode::uniaxial, 1.8);
  const Mat3 F = s.asDiagonal();
  std::vector<double> state(v.state_size()), next(v.state_size());
  v.init_state(state);
  const double P0 = nominal(eval(v, F, TimeStep{0.0, 0.0}, state, next), s);
  EXPECT_NEAR(P0, nominal_stress(base, TestMode::uniaxial, 1.8), 1e-11 * base.mu0());  // instantaneous = base
  state = next;
  for (int k = 1; k <= 400; ++k) {
    const double t = 0.5 * k;
    const double P = nominal(eval(v, F, TimeStep{t, 0.5}, state, next), s);
    state = next;
    EXPECT_NEAR(P / P0, prony_relaxation(g, tau, t), 1e-12) << "t = " << t;
  }
}

/// Three loading-unloading cycles to increasing peaks, each back to l = 1.05, as a machine records
/// them (every 0.05 of stretch).
TestCurve cycles(const Constants& base, const MullinsParams& p, TestMode mode) {
  TestCurve c{mode, "cycles.csv", {}};
  int line = 1;
  const auto go = [&](double from, double to) {
    const int n = static_cast<int>(std::round(std::abs(to - from) / 0.05));
    for (int i = 1; i <= n; ++i) c.points.push_back({from + (to - from) * i / n, 0.0, ++line});
  };
  go(1.0, 1.5);
  go(1.5, 1.05);
  go(1.05, 2.0);
  go(2.0, 1.05);
  go(1.05, 2.5);
  go(2.5, 1.05);
  const std::vector<double> P = mullins_stress(c, base, p);
  for (std::size_t i = 0; i < P.size(); ++i) c.points[i].P_Pa = P[i];
  return c;
}

// Noise-free cycles from a known base and known r, m, beta: the base comes back from the primary
// loading points alone (the primary curve is the base's: exact linear least squares) and r, m, beta
// from the rest (the truth is a zero of the objective, the global minimum): 1e-5 relative.
TEST(MullinsFit, RoundTripFromCyclesRecoversTheConstants) {
  const Constants truth = kulkarni();
  const MullinsParams p{1.8, 0.004 * kMPa, 0.15};
  const std::vector<TestCurve> tests = {cycles(truth, p, TestMode::uniaxial)};
  const FitResult base = fit_hyperelastic({primary_loading(tests[0])}, FitOptions{});
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(base.constants.c[i], truth.c[i], 1e-6 * std::abs(truth.c[i]) + 1e-9 * truth.c[0]);
  const MullinsFit f = fit_mullins(tests, base.constants, Weighting::relative);
  EXPECT_EQ(f.unloading_points, 9 + 8 + 19 + 18 + 29);  // unloading, and reloading below the last peak
  EXPECT_NEAR(f.params.r, p.r, 1e-5 * p.r);
  EXPECT_NEAR(f.params.m_Pa, p.m_Pa, 1e-5 * p.m_Pa);
  EXPECT_NEAR(f.params.beta, p.beta, 1e-5 * p.beta);
  EXPECT_GT(f.r2[0], 1.0 - 1e-12);
}

// Noise-free relaxation sampled log-uniformly from 0.05 to 500 s: g and tau come back to 1e-5.
TEST(PronyFit, RoundTripRecoversTwoTerms) {
  const std::vector<double> g{0.2, 0.1}, tau{1.5, 60.0};
  RelaxationCurve c{"relax.csv", {}};
  for (int k = 0; k <= 60; ++k) {
    const double t = 0.05 * std::pow(10.0, 4.0 * k / 60.0);
    c.points.push_back({t, prony_relaxation(g, tau, t), k + 2});
  }
  const PronyFit f = fit_prony(c, 2);
  ASSERT_EQ(f.g.size(), 2u);
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR(f.g[i], g[i], 1e-5 * g[i]);
    EXPECT_NEAR(f.tau_s[i], tau[i], 1e-5 * tau[i]);
  }
}

TEST(InelasticFitErrors, MonotonicDataHoldNoMullinsInformation) {
  const Constants truth = kulkarni();
  TestCurve c{TestMode::uniaxial, "pull.csv", {}};
  for (int i = 1; i <= 20; ++i) c.points.push_back({1.0 + 0.1 * i, nominal_stress(truth, TestMode::uniaxial, 1.0 + 0.1 * i), i + 1});
  const std::string e = error_of([&] { fit_mullins({c}, truth, Weighting::relative); });
  EXPECT_NE(e.find("needs unloading or reloading points"), std::string::npos) << e;
  EXPECT_NE(e.find("pull.csv has 0"), std::string::npos) << e;
}

TEST(InelasticFitErrors, RelaxationThatDoesNotFallOrFallsToNothing) {
  RelaxationCurve flat{"flat.csv", {}};
  for (int k = 0; k < 10; ++k) flat.points.push_back({1.0 + k, 1.0, k + 2});
  EXPECT_NE(error_of([&] { fit_prony(flat, 1); }).find("flat.csv: the normalised stress does not fall over time"),
            std::string::npos);
  RelaxationCurve gone{"gone.csv", {}};
  for (int k = 0; k < 30; ++k) {
    const double t = 0.1 * std::pow(10.0, 3.0 * k / 29.0);
    gone.points.push_back({t, std::exp(-t / 2.0), k + 2});  // relaxes to zero
  }
  const std::string e = error_of([&] { fit_prony(gone, 1); });
  EXPECT_NE(e.find("gone.csv: the fitted Prony terms sum to g = "), std::string::npos) << e;
  EXPECT_NE(e.find("no long-term modulus"), std::string::npos) << e;
  flat.points.resize(4);
  EXPECT_NE(error_of([&] { fit_prony(flat, 3); }).find("flat.csv: 3 Prony term(s) have 6 constants and need at least as many points"),
            std::string::npos);
}

}  // namespace
}  // namespace pneufem::fit
