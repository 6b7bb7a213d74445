// analysis/paper_metrics.h: the seed paper's per-trial metrics (NRMSE over the marks, absolute
// error and spread per step) and their JSON.
#include "analysis/paper_metrics.h"

#include <cmath>
#include <cstdlib>
#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/errors.h"
#include "core/json_writer.h"

namespace pneufem {
namespace {

StepAngles angles(int trial, std::vector<double> mark, std::vector<double> end) {
  StepAngles a;
  a.trial = trial;
  a.level_kPa.resize(mark.size());
  a.at_mark_deg = std::move(mark);
  a.at_end_deg = std::move(end);
  return a;
}

// NRMSE = RMSE of the marks / range of the reference's marks; spread = end - mark of the record.
TEST(PaperMetrics, NrmseErrorAndSpread) {
  const StepAngles ref = angles(1, {0.0, 10.0, 20.0}, {0.0, 10.0, 20.0});
  const StepAngles a = angles(3, {1.0, 8.0, 20.0}, {1.5, 8.0, 23.0});
  const TrialMetrics m = paper_metrics(a, ref);
  EXPECT_EQ(m.trial, 3);
  EXPECT_NEAR(m.nrmse, std::sqrt((1.0 + 4.0 + 0.0) / 3.0) / 20.0, 1e-15);
  EXPECT_EQ(m.abs_error_deg, (std::vector<double>{1.0, 2.0, 0.0}));
  EXPECT_EQ(m.spread_deg, (std::vector<double>{0.5, 0.0, 3.0}));
  EXPECT_EQ(m.mark_deg, a.at_mark_deg);
  EXPECT_EQ(m.reference_deg, ref.at_mark_deg);
  EXPECT_FALSE(m.extrapolated);
  EXPECT_EQ(paper_metrics(ref, ref).nrmse, 0.0);
}

TEST(PaperMetrics, MismatchedOrFlatReferencesAreErrors) {
  const StepAngles ref = angles(1, {0.0, 10.0}, {0.0, 10.0});
  try {
    paper_metrics(angles(2, {1.0}, {1.0}), ref);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "metrics: trial 2 has 1 steps, the reference has 2");
  }
  EXPECT_THROW(paper_metrics(angles(1, {}, {}), angles(1, {}, {})), InputError);
  EXPECT_THROW(paper_metrics(ref, angles(1, {5.0, 5.0}, {5.0, 5.0})), InputError);
}

// Non-finite values are null; only an extrapolated trial carries "extrapolated".
TEST(PaperMetrics, JsonOfTheTrials) {
  TrialMetrics t;
  t.trial = 2;
  t.nrmse = 0.125;
  t.abs_error_deg = {1.5, std::numeric_limits<double>::quiet_NaN()};
  t.spread_deg = {0.25};
  t.mark_deg = {3.0};
  t.reference_deg = {2.0};
  TrialMetrics x = t;
  x.trial = 3;
  x.extrapolated = true;
  const std::string j = metrics_json({t, x}, {0.0, 5.0});
  EXPECT_EQ(j,
            "{\n  \"trials\": [\n"
            "    {\"trial\": 2, \"nrmse\": 0.125, \"abs_error_deg\": [1.5, null], \"spread_deg\": [0.25], "
            "\"angle_at_mark_deg\": [3], \"reference_at_mark_deg\": [2]},\n"
            "    {\"trial\": 3, \"nrmse\": 0.125, \"abs_error_deg\": [1.5, null], \"spread_deg\": [0.25], "
            "\"angle_at_mark_deg\": [3], \"reference_at_mark_deg\": [2], \"extrapolated\": true}\n"
            "  ],\n  \"levels_kPa\": [0, 5]\n}\n");
}

// metrics.json keeps every digit that reads back the same double (issue 34: round-trip precision in every
// JSON file; it had 6 significant digits): 1/3 and 0.1 + 0.2 come back bit for bit.
TEST(PaperMetrics, JsonNumbersReadBackExactly) {
  TrialMetrics t;
  t.trial = 1;
  t.nrmse = 1.0 / 3.0;
  t.abs_error_deg = {0.1 + 0.2};
  t.spread_deg = {2.0 / 3.0};
  t.mark_deg = {1e-7 / 3.0};
  t.reference_deg = {12345.678901234567};
  const std::string j = metrics_json({t}, {std::sqrt(2.0)});
  for (const double v : {t.nrmse, t.abs_error_deg[0], t.spread_deg[0], t.mark_deg[0], t.reference_deg[0], std::sqrt(2.0)}) {
    const std::string text = json::num(v);
    ASSERT_NE(j.find(text), std::string::npos) << text << " not in " << j;
    EXPECT_EQ(std::strtod(text.c_str(), nullptr), v) << text;
  }
}

}  // namespace
}  // namespace pneufem
