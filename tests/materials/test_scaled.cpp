// materials/scaled.h: a law's stiffness scaled by s - energy, stress and tangent exactly s times the
// base's, and a scale that is not a finite number > 0 refused.
#include "materials/scaled.h"

#include <cmath>
#include <limits>
#include <string>

#include <gtest/gtest.h>

#include "materials/hyperelastic.h"
#include "tests/support/input_error.h"

namespace pneufem {
namespace {

using pneufem::test::error_of;

TEST(ScaledMaterial, EnergyStressAndTangentAreExactlyScaled) {
  const double C10 = 0.019e6, s = 1.7;
  const std::vector<MaterialPtr> bases = {
      std::make_shared<InvariantMaterial<Yeoh>>(Yeoh(C10, 900.0, -4.75, 100 * 2 * C10)),
      std::make_shared<SaintVenantKirchhoff>(6.5e9, 0.2)};
  Mat3 F;
  F << 1.2, 0.1, -0.05, 0.02, 0.9, 0.1, 0.0, -0.1, 1.05;
  for (const MaterialPtr& base : bases) {
    const ScaledMaterial m(base, s);
    PointResponse r0, r;
    base->evaluate(std::span<const Mat3>(&F, 1), {}, {}, {}, std::span<PointResponse>(&r0, 1), true);
    m.evaluate(std::span<const Mat3>(&F, 1), {}, {}, {}, std::span<PointResponse>(&r, 1), true);
    // One multiplication per entry: exact (the same operation as s * x).
    EXPECT_EQ(r.psi_iso, s * r0.psi_iso);
    EXPECT_EQ(r.psi_vol, s * r0.psi_vol);
    EXPECT_EQ(r.P_iso, (s * r0.P_iso).eval());
    EXPECT_EQ(r.P_vol, (s * r0.P_vol).eval());
    EXPECT_EQ(r.A_iso, (s * r0.A_iso).eval());
    EXPECT_EQ(r.A_vol, (s * r0.A_vol).eval());
    EXPECT_EQ(m.initial_shear_modulus(), s * base->initial_shear_modulus());
    EXPECT_EQ(m.initial_bulk_modulus(), s * base->initial_bulk_modulus());
    EXPECT_EQ(m.is_split(), base->is_split());
  }
  EXPECT_EQ(scale_material(bases[0], 1.0), bases[0]);  // scale 1: the law itself, bit for bit
}

TEST(ScaledMaterial, RejectsNonPositiveScale) {
  const MaterialPtr base = std::make_shared<SaintVenantKirchhoff>(1e6, 0.3);
  for (double s : {0.0, -1.0, std::nan(""), std::numeric_limits<double>::infinity()})
    EXPECT_NE(error_of([&] { ScaledMaterial(base, s); }).find("stiffness_scale must be a finite number > 0"), std::string::npos) << s;
}

}  // namespace
}  // namespace pneufem
