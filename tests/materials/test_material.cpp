// materials/material.h: the default Material::stress(), which a law without a batched kernel of its
// own inherits - it must return what evaluate() does, bit for bit, with the state handed through in
// evaluate's layout (the force-only path and the tangent path of the engine must agree exactly).
#include "materials/material.h"

#include <span>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace pneufem {
namespace {

/// A made-up law with one double of history per point and no batched kernel: psi_iso = c |F|^2 with
/// c the committed history + 1, P_iso = 2 c F, psi_vol = J; the trial history is |F|^2.
class Toy final : public Material {
 public:
  std::string name() const override { return "toy"; }
  int state_size() const override { return 1; }
  void evaluate(std::span<const Mat3> F, const TimeStep& step, std::span<const double> state_old,
                std::span<double> state_new, std::span<PointResponse> out, bool tangent) const override {
    for (std::size_t q = 0; q < F.size(); ++q) {
      const double c = 1.0 + (state_old.empty() ? 0.0 : state_old[q]) + step.dt_s;
      out[q].psi_iso = c * F[q].squaredNorm();
      out[q].P_iso = 2.0 * c * F[q];
      out[q].psi_vol = F[q].determinant();
      out[q].P_vol = Mat3::Zero();
      if (tangent) out[q].A_iso = 2.0 * c * Mat9::Identity();
      if (!state_new.empty()) state_new[q] = F[q].squaredNorm();
    }
  }
  double initial_shear_modulus() const override { return 1.0; }
  double initial_bulk_modulus() const override { return 1.0; }
};

TEST(Material, DefaultStressIsEvaluateBitForBit) {
  const Toy law;
  StressBatch b;
  b.n = 5;  // three padding lanes
  std::vector<Mat3> F(b.n);
  for (int l = 0; l < b.n; ++l) {
    F[l] << 1.0 + 0.1 * l, 0.02, -0.01 * l, 0.03, 0.95, 0.0, 0.01 * l, -0.02, 1.05;
    b.set_F(l, F[l]);
  }
  b.pad();
  const std::vector<double> old = {0.1, 0.2, 0.3, 0.4, 0.5};
  std::vector<double> fresh(b.n, -1.0), fresh_ref(b.n, -1.0);
  const TimeStep step{2.0, 0.25};
  law.stress(b, step, old, fresh);
  std::vector<PointResponse> ref(b.n);
  law.evaluate(F, step, old, fresh_ref, ref, false);
  for (int l = 0; l < b.n; ++l) {
    EXPECT_EQ(b.psi_iso[l], ref[l].psi_iso) << l;
    EXPECT_EQ(b.psi_vol[l], ref[l].psi_vol) << l;
    for (int k = 0; k < 9; ++k) {
      EXPECT_EQ(b.P_iso[k][l], ref[l].P_iso(k)) << l << k;
      EXPECT_EQ(b.P_vol[k][l], ref[l].P_vol(k)) << l << k;
    }
  }
  EXPECT_EQ(fresh, fresh_ref);  // the trial state, in evaluate's layout
  // An empty committed state (the virgin state) and no trial state wanted are handed through as such.
  law.stress(b, step, {}, {});
  EXPECT_EQ(b.psi_iso[0], 1.25 * F[0].squaredNorm());
}

}  // namespace
}  // namespace pneufem
