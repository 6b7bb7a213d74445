// Model equivalence across the rounds of a diagnosis (issue 35, item 2): equivalent_models lists
// the combinations of effects that the selection calibrated and that fit the recording as well as
// the final model (RSS within 25 %), other than the final model and the models it was built through.
// The diagnoses here are written by hand (DiagnosisResult as run_diagnosis fills it), so every
// expectation is exact: which combinations are listed, their constants, their order.
#include <cmath>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "app/diagnose/command.h"

namespace pneufem {
namespace {

CandidateResult candidate(int round, const std::string& effect, int n_params, double nrmse, bool significant) {
  CandidateResult c;
  c.round = round;
  c.effect = effect;
  c.params.assign(static_cast<std::size_t>(n_params), 1.0);
  c.nrmse = nrmse;
  c.significant = significant;
  return c;
}

// The example: creep alone in the long-term convention against stiffness + creep in the
// instantaneous one. Round 1 took stiffness (NRMSE 0.0300); long-term creep fitted almost as well
// (0.0310) and passed; Mullins passed but fits worse. Round 2 took instantaneous creep on top of
// stiffness (final 0.0290, 3 constants).
DiagnosisResult creep_or_stiffness_and_creep() {
  DiagnosisResult r;
  r.baseline_nrmse = 0.10;
  r.candidates = {candidate(1, "stiffness", 1, 0.0300, true), candidate(1, "viscoelastic", 2, 0.0310, true),
                  candidate(1, "mullins", 2, 0.0500, true),   candidate(1, "fatigue", 2, 0.0305, false),
                  candidate(2, "viscoelastic_instantaneous", 2, 0.0290, true), candidate(2, "pressure_lag", 2, 0.0295, true),
                  candidate(2, "gravity", 1, 0.0298, false)};
  r.selected = {"stiffness", "viscoelastic_instantaneous"};
  r.final_nrmse = 0.0290;
  r.final_parameters = 3;
  return r;
}

TEST(EquivalentModels, ASimplerCombinationThatFitsAsWellIsListedFirst) {
  const DiagnosisResult r = creep_or_stiffness_and_creep();
  const std::vector<EquivalentModel> m = equivalent_models(r);
  // 0.0310^2 = 1.143 x 0.0290^2 and 0.0295^2 = 1.035 x: both within 25 %; Mullins (2.97 x) is not,
  // fatigue did not pass its round's tests, stiffness alone is the model the final one was built
  // through, and gravity did not pass.
  ASSERT_EQ(m.size(), 2u);
  EXPECT_EQ(m[0].effects, std::vector<std::string>{"viscoelastic"});
  EXPECT_EQ(m[0].parameters, 2);
  EXPECT_EQ(m[0].round, 1);
  EXPECT_EQ(m[1].effects, (std::vector<std::string>{"stiffness", "pressure_lag"}));
  EXPECT_EQ(m[1].parameters, 3);
  EXPECT_EQ(m[1].round, 2);
  const std::string simpler = equivalent_model_text(m[0], r);
  EXPECT_NE(simpler.find("a simpler model explains the recording as well"), std::string::npos) << simpler;
  EXPECT_NE(simpler.find("stiffness + viscoelastic_instantaneous (3,"), std::string::npos) << simpler;
  const std::string same = equivalent_model_text(m[1], r);
  EXPECT_NE(same.find("does not tell these combinations apart"), std::string::npos) << same;
}

TEST(EquivalentModels, TheToleranceIsTheRssWithinTwentyFivePercent) {
  DiagnosisResult r = creep_or_stiffness_and_creep();
  // Just inside and just outside 1.25 x the final RSS.
  r.candidates[1].nrmse = 0.0290 * std::sqrt(1.249);
  r.candidates[5].nrmse = 0.0290 * std::sqrt(1.251);
  const std::vector<EquivalentModel> m = equivalent_models(r);
  ASSERT_EQ(m.size(), 1u);
  EXPECT_EQ(m[0].effects, std::vector<std::string>{"viscoelastic"});
}

TEST(EquivalentModels, NoneWhenNothingIsSelectedOrNothingElseFitsAsWell) {
  DiagnosisResult none = creep_or_stiffness_and_creep();
  none.selected.clear();
  none.final_nrmse = none.baseline_nrmse;
  EXPECT_TRUE(equivalent_models(none).empty());
  DiagnosisResult sharp = creep_or_stiffness_and_creep();
  sharp.final_nrmse = 0.020;  // the final model fits far better than every alternative
  EXPECT_TRUE(equivalent_models(sharp).empty());
}

TEST(EquivalentModels, AFailedCalibrationAndAConstantAtItsBoundAreHandled) {
  DiagnosisResult r = creep_or_stiffness_and_creep();
  r.candidates[1].error = "no equilibrium";  // failed: never an alternative
  r.candidates[5].at_bound = {"tau2_s"};
  const std::vector<EquivalentModel> m = equivalent_models(r);
  ASSERT_EQ(m.size(), 1u);
  EXPECT_EQ(m[0].effects, (std::vector<std::string>{"stiffness", "pressure_lag"}));
  EXPECT_EQ(m[0].at_bound, std::vector<std::string>{"tau2_s"});
  EXPECT_NE(equivalent_model_text(m[0], r).find("caution: tau2_s at the edge of its range"), std::string::npos);
}

}  // namespace
}  // namespace pneufem
