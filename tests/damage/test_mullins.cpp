// Mullins (Ogden-Roxburgh) decorator: homogeneous uniaxial load / unload / reload / further load
// against the 1-D Ogden-Roxburgh curve computed independently here from the Yeoh formulas.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include "core/errors.h"
#include "damage/effects.h"
#include "damage/material_point.h"
#include "materials/hyperelastic.h"

namespace pneufem {
namespace {

constexpr double C10 = 0.019e6, C20 = 9.0e2, C30 = -4.75;  // Ecoflex 00-50, Pa
constexpr double K = 100.0 * 2.0 * C10;

MaterialPtr ecoflex() { return std::make_shared<InvariantMaterial<Yeoh>>(Yeoh(C10, C20, C30, K)); }

// ---- Independent 1-D reference: F = diag(lambda, s, s), Yeoh written out by hand. ----
struct Uniaxial1D {
  MullinsParams p;
  double W_max = 0.0;  // the reference's own history

  struct Point {
    double W, P11, P22;
  };
  // Yeoh: W = sum C_i0 (I1b - 3)^i, P_iso = W1 dI1b/dF, dI1b/dF_aa = J^{-2/3} (2 F_aa - (2/3) I1 / F_aa);
  // P_vol_aa = K (J - 1) J / F_aa (Abaqus U = K/2 (J - 1)^2). Mullins: P_iso -> eta P_iso.
  Point at(double lambda, double s) const {
    const double J = lambda * s * s, I1 = lambda * lambda + 2.0 * s * s, Jm23 = std::pow(J, -2.0 / 3.0);
    const double x = Jm23 * I1 - 3.0;
    const double W = C10 * x + C20 * x * x + C30 * x * x * x;
    const double W1 = C10 + 2.0 * C20 * x + 3.0 * C30 * x * x;
    double eta = 1.0;
    if (W < W_max) eta = 1.0 - std::erf((W_max - W) / (p.m_Pa + p.beta * W_max)) / p.r;
    const double P11 = eta * W1 * Jm23 * (2.0 * lambda - 2.0 / 3.0 * I1 / lambda) + K * (J - 1.0) * J / lambda;
    const double P22 = eta * W1 * Jm23 * (2.0 * s - 2.0 / 3.0 * I1 / s) + K * (J - 1.0) * J / s;
    return {W, P11, P22};
  }
  // Lateral equilibrium P22 = 0 by bisection: P22 increases with s (the K = 100 mu0 volumetric term
  // dominates), so the bracket [0.2, 1.5] is safe for lambda in [1, 2.5].
  double P11(double lambda) {
    double lo = 0.2, hi = 1.5;
    for (int it = 0; it < 200 && hi - lo > 1e-16 * hi; ++it) {
      const double mid = 0.5 * (lo + hi);
      (at(lambda, mid).P22 > 0.0 ? hi : lo) = mid;
    }
    const Point pt = at(lambda, 0.5 * (lo + hi));
    W_max = std::max(W_max, pt.W);
    return pt.P11;
  }
};

// ---- The decorated material driven through the same path, committed step by step. ----
// Newton on the lateral stretch with the material's own consistent tangent at the fixed committed state.
double material_P11(MaterialPoint& mp, double lambda) {
  const auto F = [lambda](double s) { return Mat3(Vec3(lambda, s, s).asDiagonal()); };
  double s = 1.0 / std::sqrt(lambda);
  for (int it = 0; it < 50; ++it) {
    const PointResponse r = mp.trial(F(s), 0.0);
    const Mat9 A = r.A();
    const double ds = -r.P()(1, 1) / (A(flat(1, 1), flat(1, 1)) + A(flat(1, 1), flat(2, 2)));
    s += ds;
    if (std::abs(ds) <= 1e-15 * s) break;
  }
  const double P11 = mp.trial(F(s), 0.0, false).P()(0, 0);
  mp.commit();
  return P11;
}

std::vector<double> path(double from, double to, int n) {
  std::vector<double> v;
  for (int i = 1; i <= n; ++i) v.push_back(from + (to - from) * i / n);
  return v;
}

TEST(Mullins, UniaxialLoadUnloadReloadMatchesOgdenRoxburgh1D) {
  const MullinsParams p{2.0, 20e3, 0.1};
  MaterialPoint mp(make_mullins(ecoflex(), p));
  MaterialPoint elastic(ecoflex());
  Uniaxial1D ref{p};

  struct Leg {
    const char* name;
    std::vector<double> lambdas, P, P_elastic;
  };
  std::vector<Leg> legs{{"load 1 -> 2", path(1.0, 2.0, 20), {}, {}},
                        {"unload 2 -> 1", path(2.0, 1.0, 20), {}, {}},
                        {"reload 1 -> 2", path(1.0, 2.0, 20), {}, {}},
                        {"load 2 -> 2.5", path(2.0, 2.5, 10), {}, {}}};
  // Tolerance: both sides solve lateral equilibrium to ~1e-15 relative in s and evaluate the same
  // closed forms in a different order, so they agree to ~1e-12 of the stress scale; 1e-9 leaves
  // 1000x headroom while a wrong eta (e.g. evaluated with the updated W_max, or m + beta W instead of
  // m + beta W_max) is off by percents.
  double P_scale = 0.0;
  for (Leg& leg : legs) {
    for (double lambda : leg.lambdas) {
      leg.P.push_back(material_P11(mp, lambda));
      leg.P_elastic.push_back(material_P11(elastic, lambda));
      P_scale = std::max(P_scale, std::abs(leg.P.back()));
      const double expected = ref.P11(lambda);
      // The series of docs/verification.md's figure (docs/figures/verification_figures.py mullins).
      std::printf("mullins series %s: stretch %.17g P11_Pa %.17g reference_Pa %.17g elastic_Pa %.17g\n", leg.name, lambda,
                  leg.P.back(), expected, leg.P_elastic.back());
      EXPECT_NEAR(leg.P.back(), expected, 1e-9 * std::max(std::abs(expected), 2.0 * C10))
          << leg.name << " at lambda = " << lambda;
      EXPECT_NEAR(mp.fields().W_max, ref.W_max, 1e-9 * ref.W_max) << leg.name << " at lambda = " << lambda;
    }
  }
  const Leg &load = legs[0], &unload = legs[1], &reload = legs[2], &further = legs[3];

  // Primary curves are the base's: eta = 1 identically while W_max tracks W_dev.
  for (std::size_t i = 0; i < load.P.size(); ++i) EXPECT_NEAR(load.P[i], load.P_elastic[i], 1e-12 * P_scale);
  for (std::size_t i = 0; i < further.P.size(); ++i) EXPECT_NEAR(further.P[i], further.P_elastic[i], 1e-12 * P_scale);

  // Unloading lies clearly below the primary curve (unload[i] is at lambda = 2 - (i + 1)/20, i.e. load[18 - i]).
  for (std::size_t i = 0; i + 1 < unload.P.size(); ++i) {
    const double primary = load.P[18 - i];
    EXPECT_LT(unload.P[i], primary) << "lambda = " << unload.lambdas[i];
  }
  const std::size_t at15 = 9;  // unload.lambdas[9] = 1.5
  ASSERT_NEAR(unload.lambdas[at15], 1.5, 1e-14);
  EXPECT_LT(unload.P[at15], 0.7 * load.P[9]) << "softening at lambda = 1.5 should exceed 30 % with r = 2";
  // Back at lambda = 1 the Ogden-Roxburgh model leaves no permanent set.
  EXPECT_LE(std::abs(unload.P.back()), 1e-9 * P_scale);

  // Reloading retraces the unloading curve (same W_max, no new history) up to lambda = 2 ...
  for (std::size_t i = 0; i < reload.P.size(); ++i) {
    const double lambda = reload.lambdas[i];
    const std::size_t j = 18 - i;  // unload.lambdas[j] = 2 - (j + 1)/20 = 1 + (i + 1)/20
    if (i + 1 < reload.P.size()) {
      ASSERT_NEAR(unload.lambdas[j], lambda, 1e-14);
      EXPECT_NEAR(reload.P[i], unload.P[j], 1e-10 * P_scale) << "lambda = " << lambda;
    }
  }
  // ... where it rejoins the primary curve, and W_max then grows again.
  EXPECT_NEAR(reload.P.back(), load.P.back(), 1e-10 * P_scale);
  EXPECT_GT(further.P.back(), reload.P.back());
}

TEST(Mullins, RejectsBadParametersAndBases) {
  const auto expect_error = [](const std::function<void()>& f, const std::string& text) {
    try {
      f();
      ADD_FAILURE() << "no InputError; expected one containing '" << text << "'";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
    }
  };
  expect_error([] { make_mullins(ecoflex(), {1.0, 1e3, 0.1}); }, "mullins: r must be > 1");
  expect_error([] { make_mullins(ecoflex(), {2.0, -1.0, 0.1}); }, "mullins: m must be >= 0");
  expect_error([] { make_mullins(ecoflex(), {2.0, 1e3, -0.1}); }, "mullins: beta must be >= 0");
  expect_error([] { make_mullins(ecoflex(), {2.0, 0.0, 0.0}); }, "mullins: m and beta cannot both be 0");
  expect_error([] { make_mullins(ecoflex(), {NAN, 1e3, 0.1}); }, "mullins: r must be a finite number");
  expect_error([] { make_mullins(nullptr, {2.0, 1e3, 0.1}); }, "mullins: no base material");
  expect_error([] { make_mullins(std::make_shared<SaintVenantKirchhoff>(6.5e9, 0.2), {2.0, 1e3, 0.1}); },
               "only applies to split (isochoric/volumetric) laws such as yeoh");
  expect_error([] { make_mullins(make_fatigue(ecoflex(), {2e3, 10.0, 2.0, 0.5}), {2.0, 1e3, 0.1}); },
               "apply the effects in the order viscoelastic(fatigue(mullins(base)))");
  expect_error([] { make_mullins(make_viscoelastic(ecoflex(), {{0.5}, {1.0}}), {2.0, 1e3, 0.1}); },
               "mullins: cannot wrap 'viscoelastic(yeoh)'");
}

}  // namespace
}  // namespace pneufem
