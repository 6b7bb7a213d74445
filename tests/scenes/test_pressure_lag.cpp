// scenes/pressure_lag.h: the chamber pressure lag (load.pressure_lag_s, load.pressure_lag2_s) - the
// exact first- and second-order responses against the textbook closed forms, the breakpoints against
// their tolerance, the scene keys lagging the staircase, and bad values.
#include "scenes/pressure_lag.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <limits>

#include <gtest/gtest.h>

#include "core/errors.h"
#include "scenes/build_model.h"
#include "tests/support/input_error.h"
#include "tests/support/tiny_scene.h"

namespace pneufem {
namespace {

using pneufem::test::error_of;
using pneufem::test::tiny;  // 3 chambers at h = 6 mm

// ---- Pressure lag ----

TrialLoad step_load(double p_Pa, double t_jump, double T) {
  TrialLoad tl;
  tl.time_s = {0.0, t_jump, t_jump + 1e-9, T};
  tl.pressure_Pa = {0.0, 0.0, p_Pa, p_Pa};
  return tl;
}

// Step response p_c = P (1 - exp(-(t - t0)/tau)) and ramp response p_c = b (t - tau (1 - exp(-t/tau)))
// (the solutions of tau p' = p_in - p with p(0) = 0), evaluated through the closed form (1): agreement
// to rounding (1e-12 of the step; the 1e-9 s jump shifts the step response by <= P 1e-9/tau = 2e-9 P).
TEST(PressureLag, ClosedFormMatchesStepAndRampResponses) {
  const double tau = 0.5, P = 5e3;
  const TrialLoad step = step_load(P, 1.0, 6.0);
  for (double t : {0.5, 1.1, 1.5, 2.0, 3.7, 6.0, 7.0}) {
    const double exact = t <= 1.0 ? 0.0 : P * (1.0 - std::exp(-(t - 1.0) / tau));
    EXPECT_NEAR(lagged_pressure(step, tau, t), exact, 3e-9 * P) << t;
  }
  TrialLoad ramp;
  ramp.time_s = {0.0, 2.0, 5.0};
  ramp.pressure_Pa = {0.0, 2.0 * P, 2.0 * P};  // b = P per second, then hold
  const double b = P;
  for (double t : {0.1, 0.7, 1.9, 2.0}) EXPECT_NEAR(lagged_pressure(ramp, tau, t), b * (t - tau * -std::expm1(-t / tau)), 1e-12 * P);
  const double p2 = b * (2.0 - tau * -std::expm1(-2.0 / tau));
  for (double t : {2.5, 4.0}) EXPECT_NEAR(lagged_pressure(ramp, tau, t), 2 * P + (p2 - 2 * P) * std::exp(-(t - 2.0) / tau), 1e-12 * P);
}

// The emitted piecewise-linear history is within the tolerance everywhere (dense check), and not
// needlessly dense: per step of size P the breakpoints needed are about the integral of 1/h(s) =
// 2 sqrt(P / (8 tol)) (h(s) from the header), 10 for tol = 0.5 % of P; allow 2x.
TEST(PressureLag, BreakpointsMeetTheToleranceWithoutWaste) {
  const double tau = 0.5, P = 5e3, tol = 0.005 * P;
  LoadHistory h;
  h.trials.push_back(step_load(P, 1.0, 9.0));
  TrialLoad ramp;
  ramp.time_s = {0.0, 0.5, 4.0, 4.3, 9.0};
  ramp.pressure_Pa = {0.0, P, P, 0.3 * P, 0.3 * P};
  h.trials.push_back(ramp);
  const LoadHistory lag = apply_pressure_lag(h, tau, tol);
  for (std::size_t k = 0; k < h.trials.size(); ++k) {
    double worst = 0.0;
    for (double t = 0.0; t <= 9.0; t += 1e-4)
      worst = std::max(worst, std::abs(lag.trials[k].pressure(t) - lagged_pressure(h.trials[k], tau, t)));
    EXPECT_LE(worst, tol) << "trial " << k;
    EXPECT_GT(worst, 0.2 * tol) << "trial " << k << ": breakpoints denser than needed";
  }
  EXPECT_LE(lag.trials[0].time_s.size(), h.trials[0].time_s.size() + 20);
  // Only the pressure breakpoints change: reports, steps and marks refer to the inlet command times.
  EXPECT_EQ(lag.trials[1].output_s, h.trials[1].output_s);
}

TEST(PressureLag, SceneKeyLagsTheStaircaseAndKeepsItsMetadata) {
  const std::vector<std::string> load = {"load.max_kPa=10", "load.step_kPa=5", "load.hold_s=3", "load.ramp_s=0.5",
                                         "load.mark_s=1"};
  std::vector<std::string> lagged = load, zero = load;
  lagged.push_back("load.pressure_lag_s=0.4");
  zero.push_back("load.pressure_lag_s=0");
  const auto a = build_model(Scene::load("", tiny(load))), b = build_model(Scene::load("", tiny(lagged))),
             z = build_model(Scene::load("", tiny(zero)));
  const TrialLoad &ta = a->load.trials[0], &tb = b->load.trials[0];
  EXPECT_EQ(z->load.trials[0].time_s, ta.time_s);  // lag 0: the staircase itself
  EXPECT_EQ(z->load.trials[0].pressure_Pa, ta.pressure_Pa);
  EXPECT_EQ(tb.output_s, ta.output_s);
  EXPECT_EQ(tb.step_start_s, ta.step_start_s);
  EXPECT_EQ(tb.step_level_Pa, ta.step_level_Pa);
  EXPECT_GT(tb.time_s.size(), ta.time_s.size());
  // Exact response of the ramp to 5 kPa at 3..3.5 s: at the ramp's end the chamber lags the inlet by
  // b (t - tau (1 - e^{-t/tau})) = 2.9 kPa; at the hold's end (2.5 s = 6 tau later) it has caught up
  // to within 5 kPa e^-6.
  const double tol = 0.005 * 5e3;
  EXPECT_NEAR(tb.pressure(4.0), lagged_pressure(ta, 0.4, 4.0), tol);
  EXPECT_LT(tb.pressure(3.5), ta.pressure(3.5) - 500.0);
  EXPECT_NEAR(tb.pressure(6.0), 5e3, 5e3 * std::exp(-6.0) + tol);
  const std::string e = error_of([&] { build_model(Scene::load("", tiny({"load.pressure_lag_s=-1"}))); });
  EXPECT_NE(e.find("load.pressure_lag_s"), std::string::npos) << e;
}

// ---- Second-order pressure lag (load.pressure_lag2_s) ----

// Closed forms of tau2^2 x'' + tau x' + x = u from rest, written per damping regime as the textbooks
// do (not through the code's unified basis (3)): the response to a unit step at s = 0, and to a
// unit ramp u = s. Omega = 1/tau2, zeta = tau/(2 tau2); over-damped as two first-order stages in
// series, T1,2 = (tau +- sqrt(tau^2 - 4 tau2^2))/2.
struct SecondOrder {
  double tau, tau2;
  double zeta() const { return tau / (2.0 * tau2); }
  double step(double s) const {
    if (s <= 0.0) return 0.0;
    const double z = zeta(), w = 1.0 / tau2;
    if (z < 1.0) {
      const double wd = w * std::sqrt(1.0 - z * z);
      return 1.0 - std::exp(-z * w * s) * (std::cos(wd * s) + z / std::sqrt(1.0 - z * z) * std::sin(wd * s));
    }
    if (z == 1.0) return 1.0 - (1.0 + s / tau2) * std::exp(-s / tau2);
    const auto [T1, T2] = stages();
    return 1.0 - (T1 * std::exp(-s / T1) - T2 * std::exp(-s / T2)) / (T1 - T2);
  }
  double ramp(double s) const {
    if (s <= 0.0) return 0.0;
    const double z = zeta(), w = 1.0 / tau2;
    if (z < 1.0) {
      const double wd = w * std::sqrt(1.0 - z * z);
      return s - 2.0 * z / w + std::exp(-z * w * s) * (2.0 * z / w * std::cos(wd * s) + (2.0 * z * z - 1.0) / wd * std::sin(wd * s));
    }
    if (z == 1.0) return s - 2.0 * tau2 + (2.0 * tau2 + s) * std::exp(-s / tau2);
    const auto [T1, T2] = stages();
    return s - (T1 + T2) + (T1 * T1 * std::exp(-s / T1) - T2 * T2 * std::exp(-s / T2)) / (T1 - T2);
  }
  std::pair<double, double> stages() const {
    const double d = std::sqrt(tau * tau - 4.0 * tau2 * tau2);
    return {0.5 * (tau + d), 0.5 * (tau - d)};
  }
};

// The three regimes: under-damped (the othermeans recording's f_n 0.6 Hz, zeta 0.45: tau2 = 1/(2 pi
// 0.6) s, tau = 2 zeta tau2), critically damped, and two RC stages of 0.4 and 0.1 s in series.
const std::vector<SecondOrder> kRegimes = {{2.0 * 0.45 / (2.0 * M_PI * 0.6), 1.0 / (2.0 * M_PI * 0.6)},
                                           {0.5, 0.25},
                                           {0.5, std::sqrt(0.4 * 0.1)}};

// A ramp of rate P/s over [0, 2] s, then a hold (trial 0), and a 1e-9 s step of P at 1 s (trial 1):
// by superposition their exact responses are P (R(t) - R(t - 2)) and P S(t - 1) (the 1e-9 s jump
// shifts the step by half of it: < P 1e-9 max|S'| < 1e-8 P).
LoadHistory ramp_and_step(double P) {
  LoadHistory h;
  TrialLoad ramp;
  ramp.time_s = {0.0, 2.0, 9.0};
  ramp.pressure_Pa = {0.0, 2.0 * P, 2.0 * P};
  h.trials.push_back(ramp);
  h.trials.push_back(step_load(P, 1.0, 9.0));
  return h;
}

double exact_ramp_and_step(const SecondOrder& so, std::size_t trial, double P, double t) {
  return trial == 0 ? P * (so.ramp(t) - so.ramp(t - 2.0)) : P * so.step(t - 1.0);
}

// The exact solution (3) of the code against the textbook closed forms: to rounding, 1e-8 of the
// step (the 1e-9 s jump above), in all three regimes, through the breakpoints and past the last one.
TEST(PressureLag2, ClosedFormMatchesStepAndRampResponsesInEveryRegime) {
  const double P = 5e3;
  const LoadHistory h = ramp_and_step(P);
  for (const SecondOrder& so : kRegimes)
    for (std::size_t k = 0; k < 2; ++k)
      for (double t : {0.0, 0.3, 1.0, 1.2, 1.9, 2.0, 2.4, 3.7, 6.0, 9.0, 11.0})
        EXPECT_NEAR(lagged_pressure(h.trials[k], PressureLag{so.tau, so.tau2}, t), exact_ramp_and_step(so, k, P, t), 1e-8 * P)
            << "zeta " << so.zeta() << " trial " << k << " t " << t;
  // The under-damped chamber overshoots a step by exp(-pi zeta / sqrt(1 - zeta^2)) = 20.5 % at zeta 0.45.
  const SecondOrder& u = kRegimes[0];
  const double t_peak = 1.0 + M_PI * u.tau2 / std::sqrt(1.0 - u.zeta() * u.zeta());
  EXPECT_NEAR(lagged_pressure(h.trials[1], PressureLag{u.tau, u.tau2}, t_peak) / P - 1.0,
              std::exp(-M_PI * 0.45 / std::sqrt(1.0 - 0.45 * 0.45)), 1e-8);
}

// The emitted piecewise-linear history against the closed forms, densely: within the breakpoint
// tolerance, since that is what apply_pressure_lag promises of its linear interpolation of the
// exact response (the header's energy bound on p_c''), plus the 1e-8 P of the 1e-9 s jump; and not
// needlessly dense: the worst error is more than a fifth of the tolerance (the bound is not loose)
// and the breakpoints per trial are tens, not thousands.
TEST(PressureLag2, BreakpointsMeetTheToleranceWithoutWaste) {
  const double P = 5e3, tol = 0.005 * P;
  const LoadHistory h = ramp_and_step(P);
  for (const SecondOrder& so : kRegimes) {
    const LoadHistory lag = apply_pressure_lag(h, PressureLag{so.tau, so.tau2}, tol);
    for (std::size_t k = 0; k < 2; ++k) {
      double worst = 0.0;
      for (double t = 0.0; t <= 9.0; t += 1e-4)
        worst = std::max(worst, std::abs(lag.trials[k].pressure(t) - exact_ramp_and_step(so, k, P, t)));
      EXPECT_LE(worst, tol + 1e-8 * P) << "zeta " << so.zeta() << " trial " << k;
      EXPECT_GT(worst, 0.2 * tol) << "zeta " << so.zeta() << " trial " << k << ": breakpoints denser than needed";
      EXPECT_LE(lag.trials[k].time_s.size(), 200u) << "zeta " << so.zeta() << " trial " << k;
      std::printf("zeta %.3f trial %zu: %zu breakpoints, worst %.3g of the tolerance\n", so.zeta(), k,
                  lag.trials[k].time_s.size(), worst / tol);
      // The series of docs/verification.md's figure (docs/figures/verification_figures.py lag).
      for (std::size_t i = 0; i < lag.trials[k].time_s.size(); ++i)
        std::printf("lag breakpoint zeta %.3f trial %zu: t_s %.17g p_Pa %.17g\n", so.zeta(), k, lag.trials[k].time_s[i],
                    lag.trials[k].pressure_Pa[i]);
      for (int i = 0; i <= 150; ++i)
        std::printf("lag exact zeta %.3f trial %zu: t_s %.17g p_Pa %.17g inlet_Pa %.17g\n", so.zeta(), k, 0.04 * i,
                    exact_ramp_and_step(so, k, P, 0.04 * i), h.trials[k].pressure(0.04 * i));
    }
    EXPECT_EQ(lag.trials[1].output_s, h.trials[1].output_s);  // reports stay at the inlet command times
  }
}

// A second-order constant far below the inlet's sampling (tau2 -> 0, as a calibration may try: a
// diagnosis once grew to 24 GB here) either gives a history within the breakpoint bound (64 per
// inlet point + 1e5, scenes/pressure_lag.cpp) or a PhysicsError naming both keys; never more, and
// quickly. Measured: 1e-4 to 1e-7 s are resolved within the bound (each the first-order lag within
// the tolerance); at 1e-9 s the step, whose second and third derivatives are differences divided by
// tau2^2, falls to its floor of 1e-9 of a segment and the history passes the bound: refused.
TEST(PressureLag2, AVanishingSecondConstantIsBoundedOrAClearError) {
  const double P = 5e3, tol = 0.005 * P;
  const LoadHistory h = ramp_and_step(P);
  int errors = 0;
  for (double tau2 : {1e-4, 1e-6, 1e-7, 1e-9}) {
    try {
      const LoadHistory lag = apply_pressure_lag(h, PressureLag{0.3, tau2}, tol);
      for (const TrialLoad& tl : lag.trials) EXPECT_LE(tl.time_s.size(), 64u * 3u + 100000u) << "tau2 " << tau2;
      // Resolved: the history is the first-order lag's within the tolerance (the fast stage is gone).
      const LoadHistory first = apply_pressure_lag(h, PressureLag{0.3, 0.0}, tol);
      for (std::size_t k = 0; k < 2; ++k)
        for (double t = 0.5; t <= 9.0; t += 0.5)
          EXPECT_NEAR(lag.trials[k].pressure(t), first.trials[k].pressure(t), 2.0 * tol) << "tau2 " << tau2 << " t " << t;
    } catch (const PhysicsError& e) {
      ++errors;
      std::printf("tau2 %g s refused: %s\n", tau2, e.what());
      EXPECT_NE(std::string(e.what()).find("load.pressure_lag2_s"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("breakpoints"), std::string::npos) << e.what();
    }
  }
  std::printf("vanishing tau2: %d of 4 refused\n", errors);
}

// tau2 = 0 is the first-order lag bit for bit: the same breakpoints and pressures, the same exact
// values, and a scene with load.pressure_lag2_s = 0 builds the load of one without the key set.
TEST(PressureLag2, ZeroSecondConstantIsTheFirstOrderLagBitForBit) {
  const double P = 5e3, tol = 0.005 * P, tau = 0.4;
  const LoadHistory h = ramp_and_step(P);
  const LoadHistory one = apply_pressure_lag(h, tau, tol), two = apply_pressure_lag(h, PressureLag{tau, 0.0}, tol);
  for (std::size_t k = 0; k < 2; ++k) {
    EXPECT_EQ(two.trials[k].time_s, one.trials[k].time_s);
    EXPECT_EQ(two.trials[k].pressure_Pa, one.trials[k].pressure_Pa);
    for (double t : {0.5, 1.5, 2.5, 10.0})
      EXPECT_EQ(lagged_pressure(h.trials[k], PressureLag{tau, 0.0}, t), lagged_pressure(h.trials[k], tau, t));
  }
  EXPECT_EQ(two.description, one.description);
  const std::vector<std::string> load = {"load.max_kPa=10", "load.step_kPa=5", "load.hold_s=3", "load.pressure_lag_s=0.4"};
  std::vector<std::string> zero = load;
  zero.push_back("load.pressure_lag2_s=0");
  const LoadHistory a = chamber_load(Scene::load("", tiny(load))), b = chamber_load(Scene::load("", tiny(zero)));
  EXPECT_EQ(b.trials[0].time_s, a.trials[0].time_s);
  EXPECT_EQ(b.trials[0].pressure_Pa, a.trials[0].pressure_Pa);
}

// The scene key lags the staircase through (2): the under-damped chamber overshoots each 5 kPa
// level (by 20 % of the step at zeta 0.45, less the ramp's smoothing), within the staircase's
// tolerance of the exact response, and keeps the inlet's reports, steps and marks.
TEST(PressureLag2, SceneKeyLagsTheStaircaseAndKeepsItsMetadata) {
  const SecondOrder& u = kRegimes[0];
  const std::vector<std::string> load = {"load.max_kPa=10", "load.step_kPa=5", "load.hold_s=3", "load.ramp_s=0.2",
                                         "load.mark_s=1"};
  std::vector<std::string> lagged = load;
  lagged.push_back("load.pressure_lag_s=" + std::to_string(u.tau));
  lagged.push_back("load.pressure_lag2_s=" + std::to_string(u.tau2));
  const Scene s = Scene::load("", tiny(lagged));
  const PressureLag lag = scene_pressure_lag(s);
  const TrialLoad ta = inlet_load(s).trials[0], tb = chamber_load(s).trials[0];
  EXPECT_EQ(tb.output_s, ta.output_s);
  EXPECT_EQ(tb.step_start_s, ta.step_start_s);
  EXPECT_EQ(tb.step_level_Pa, ta.step_level_Pa);
  const double tol = 0.005 * 5e3;
  double peak = 0.0;
  for (double t = 0.0; t <= ta.duration(); t += 1e-3) {
    EXPECT_NEAR(tb.pressure(t), lagged_pressure(ta, lag, t), tol) << t;
    peak = std::max(peak, tb.pressure(t));
  }
  const double top = *std::max_element(ta.pressure_Pa.begin(), ta.pressure_Pa.end());
  EXPECT_GT(peak, top + 0.1 * 5e3);  // above the last level: an overshoot no first-order lag makes
  EXPECT_NE(chamber_load(s).description.find("second order"), std::string::npos);
}

// A bad second constant is an error naming its key: negative, NaN, or a second order without the
// first constant (an undamped chamber); apply_pressure_lag refuses the same values.
TEST(PressureLag2, BadValuesAreErrorsNamingTheKey) {
  for (const std::string bad : {"load.pressure_lag2_s=-0.1", "load.pressure_lag2_s=nan"}) {
    const std::string e = error_of([&] { build_model(Scene::load("", tiny({"load.pressure_lag_s=0.3", bad}))); });
    EXPECT_NE(e.find("load.pressure_lag2_s"), std::string::npos) << bad << ": " << e;
  }
  const std::string e = error_of([&] { chamber_load(Scene::load("", tiny({"load.pressure_lag2_s=0.2"}))); });
  EXPECT_NE(e.find("load.pressure_lag2_s"), std::string::npos) << e;
  EXPECT_NE(e.find("load.pressure_lag_s"), std::string::npos) << e;
  const LoadHistory h = ramp_and_step(5e3);
  for (double bad : {-0.1, std::numeric_limits<double>::quiet_NaN()}) {
    const std::string a = error_of([&] { apply_pressure_lag(h, PressureLag{0.3, bad}, 25.0); });
    EXPECT_NE(a.find("load.pressure_lag2_s"), std::string::npos) << a;
  }
}

}  // namespace
}  // namespace pneufem
