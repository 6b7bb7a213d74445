// damage/material_point.h: one quadrature point's committed and trial state - a trial leaves the
// committed state and the time alone, commit() makes the trial state the committed one and advances
// the time by the trial's increment, set_committed_state() checks the size it is given.
#include "damage/material_point.h"

#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "damage/effects.h"
#include "materials/hyperelastic.h"
#include "tests/support/input_error.h"

namespace pneufem {
namespace {

// Mullins-softened Yeoh: two doubles of history, the first the largest deviatoric energy seen (W_max).
MaterialPtr softening() {
  return make_mullins(std::make_shared<InvariantMaterial<Yeoh>>(Yeoh(0.02e6, 0.001e6, 0.0, 2e6)), {2.0, 1e3, 0.1});
}

Mat3 stretch(double l) {
  Mat3 F = Mat3::Identity();
  F(0, 0) = l;
  F(1, 1) = F(2, 2) = 1.0 / std::sqrt(l);
  return F;
}

TEST(MaterialPoint, ATrialIsNotCommittedUntilCommit) {
  MaterialPoint p(softening());
  const std::vector<double> virgin(p.committed_state().begin(), p.committed_state().end());
  ASSERT_EQ(virgin.size(), 2u);
  const PointResponse first = p.trial(stretch(1.8), 0.5);
  EXPECT_EQ(std::vector<double>(p.committed_state().begin(), p.committed_state().end()), virgin);
  EXPECT_GT(p.trial_state()[0], virgin[0]);  // the trial saw a larger energy
  EXPECT_EQ(p.time_s(), 0.0);
  // A second trial from the same committed state (a Newton iteration) gives the same response.
  EXPECT_EQ(p.trial(stretch(1.8), 0.5).P(), first.P());
  p.commit();
  EXPECT_EQ(p.time_s(), 0.5);
  EXPECT_EQ(p.committed_state()[0], p.trial_state()[0]);
}

TEST(MaterialPoint, TheCommittedHistorySoftensTheReload) {
  // Mullins: after a stretch to 1.8, reloading to 1.4 is softer than the virgin load to 1.4.
  MaterialPoint virgin(softening()), loaded(softening());
  const double p_virgin = virgin.advance(stretch(1.4), 1.0).P()(0, 0);
  loaded.advance(stretch(1.8), 1.0);
  loaded.advance(stretch(1.0), 1.0);
  const double p_reload = loaded.advance(stretch(1.4), 1.0).P()(0, 0);
  EXPECT_EQ(loaded.time_s(), 3.0);
  EXPECT_LT(p_reload, 0.99 * p_virgin);  // r = 2 softens by far more than 1 % at half the peak energy
}

TEST(MaterialPoint, SetCommittedStateChecksItsSize) {
  MaterialPoint p(softening());
  const std::vector<double> s = {5.0, 0.0};
  p.set_committed_state(s);
  EXPECT_EQ(p.committed_state()[0], 5.0);
  EXPECT_EQ(p.trial_state()[0], 5.0);
  const std::string e = pneufem::test::error_of([&] { p.set_committed_state(std::vector<double>{1.0}); });
  EXPECT_NE(e.find("state of size 1 given, the material '" + p.material().name() + "' needs 2"), std::string::npos) << e;
  EXPECT_NE(pneufem::test::error_of([] { MaterialPoint none(nullptr); }).find("no material given"), std::string::npos);
}

}  // namespace
}  // namespace pneufem
