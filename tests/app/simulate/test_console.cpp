// What `simulate` tells the console at the end (app/simulate/command.h, top_angles_text): the
// angle at the largest reported pressure, per trial, from the last report there.
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "app/simulate/command.h"

namespace pneufem {
namespace {

StateRecord rec(int trial, double p_kPa, double angle, bool extrapolated = false) {
  StateRecord r;
  r.trial = trial;
  r.pressure_Pa = p_kPa * 1e3;
  r.angle_deg = angle;
  r.extrapolated = extrapolated;
  return r;
}

TEST(TopAngles, TheLastReportAtTheTopPressureOfEachTrial) {
  // Each trial: the mark and the end of the top hold at 45 kPa, then the release; trial 3 skipped
  // by a cycle jump.
  const std::vector<StateRecord> r = {rec(1, 40, 50.0), rec(1, 45, 60.0), rec(1, 45, 61.234), rec(1, 0, 0.5),
                                      rec(2, 45, 62.0), rec(2, 45, 63.0), rec(3, 45, 64.0, true)};
  EXPECT_EQ(top_angles_text(r),
            "angle at the top pressure, 45.0 kPa (the last report there): trial 1 61.23 deg, trial 2 63.00 deg, trial 3 64.00 "
            "deg* (* extrapolated by a cycle jump)\n");
  EXPECT_EQ(top_angles_text({}), "");
}

}  // namespace
}  // namespace pneufem
