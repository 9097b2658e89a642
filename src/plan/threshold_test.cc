// The plan's truth about thresholds against hand-worked cases: Levitt's convergence points, the Weibull's threshold
// point, the report's turning-point rule and QUEST+'s posterior median and the pixel observer's closed form Phi(dr / jnd) solved by hand.
#include "plan/threshold.h"

#include <cmath>

#include <gtest/gtest.h>

namespace blurcue::plan {
namespace {

TEST(DownRunFirst, OneUpIsPToTheDownAndOneDownIsOneMinusQToTheUp) {
  EXPECT_NEAR(DownRunFirst(0.6, 1, 2), 0.36, 1e-12);          // two right in a row before one wrong: p^2
  EXPECT_NEAR(DownRunFirst(0.6, 2, 1), 1 - 0.16, 1e-12);      // one right before two wrong in a row: 1 - q^2
  EXPECT_NEAR(DownRunFirst(0.5, 2, 2), 0.5, 1e-12);           // symmetric rule at p = 1/2
}

TEST(TargetShare, LevittPointsAndTheWeibullThreshold) {
  protocol::Procedure staircase;
  staircase.up = 1, staircase.down = 2;
  EXPECT_NEAR(TargetShare(staircase, 0), std::sqrt(0.5), 1e-9);  // 70.7 %
  staircase.down = 3;
  EXPECT_NEAR(TargetShare(staircase, 0), std::cbrt(0.5), 1e-9);  // 79.4 %
  protocol::Procedure quest;
  quest.kind = protocol::Procedure::Kind::kQuestPlus;
  quest.guess = 0.5;
  EXPECT_NEAR(TargetShare(quest, 0), 1 - 0.5 / M_E, 1e-12);      // 81.6 %
  EXPECT_NEAR(TargetShare(quest, 0.02), 0.5 + 0.48 * (1 - 1 / M_E), 1e-12);
}

// A 1-up/2-down staircase from 1.0, steps 0.4 then 0.2, answered C C C C W C C W W C C W C C, worked by hand: it
// shows 1, 1, .6, .6, .2, .4, .4, .2, .4, .6, .6, .4, .6, .6 and turns (the level shown on the answer whose step goes
// the other way) at trials 5, 7, 8, 11, 12, 14: .2 .4 .2 .6 .4 .6, mean 2.4 / 6 = 0.4. The levels after each turn
// (the rule of before) would give .4 .2 .4 .4 .6 and a sixth level never shown.
TEST(TurningPoints, StaircaseReplayedByHand) {
  protocol::Procedure staircase;
  staircase.start = 1, staircase.min = 0, staircase.max = 3, staircase.up = 1, staircase.down = 2;
  staircase.steps = {0.4, 0.2};
  const std::vector<double> levels = {1, 1, 0.6, 0.6, 0.2, 0.4, 0.4, 0.2, 0.4, 0.6, 0.6, 0.4, 0.6, 0.6};
  const std::vector<bool> correct = {true, true, true, true, false, true, true,
                                     false, false, true, true, false, true, true};
  const std::vector<double> turns = TurningPoints(staircase, correct);
  const std::vector<double> by_hand = {0.2, 0.4, 0.2, 0.6, 0.4, 0.6};
  ASSERT_EQ(turns.size(), by_hand.size());
  for (size_t i = 0; i < turns.size(); ++i) EXPECT_NEAR(turns[i], by_hand[i], 1e-12) << i;
  // The plan's track estimate is the staircase posterior at the rule's target (procedure/threshold_fit.h).
  const procedure::TrackThreshold t = TrackEstimate(staircase, levels, correct);
  const procedure::TrackThreshold direct =
      procedure::StaircasePosterior({0.5, std::sqrt(0.5), 0, 3}, levels, correct);
  EXPECT_EQ(t.determined, direct.determined);
  EXPECT_NEAR(t.estimate, direct.estimate, 1e-6 * direct.estimate);
  EXPECT_FALSE(TrackEstimate(staircase, {}, {}).determined);
}

// A 1-up/1-down staircase in a 2AFC converges on 50 % correct, what guessing gives: no threshold, said in words
// (the posterior refuses such a target; this was an exception before). An odd one out of 3 guesses 1/3 (the
// protocol parser sets it) and its 1-up/1-down target, 50 %, is above guessing: fitted.
TEST(TrackEstimate, AStaircaseConvergingOnGuessingHasNoThreshold) {
  protocol::Procedure staircase;
  staircase.start = 1, staircase.min = 0.02, staircase.max = 3, staircase.up = 1, staircase.down = 1;
  staircase.steps = {0.1};
  std::vector<double> levels(20, 0.5);
  std::vector<bool> correct(20, false);
  for (size_t i = 0; i < 20; i += 2) correct[i] = true;
  const procedure::TrackThreshold t = TrackEstimate(staircase, levels, correct);
  EXPECT_FALSE(t.determined);
  EXPECT_EQ(t.why, "not determined: a 1-up/1-down staircase converges on 50.0 % correct, at or below what guessing gives");
  staircase.guess = 1.0 / 3;
  EXPECT_EQ(TrackEstimate(staircase, levels, correct).why.find("converges"), std::string::npos);
}

// QUEST+ over thresholds {1, 2, 3}, slope 2, no lapse, guess 0.5, after one correct answer at 1: each threshold's
// likelihood 1 - 0.5 exp(-(1 / t)^2), the marginal their share, the median interpolated in the cumulative mass.
TEST(TrackEstimate, QuestPlusPosteriorMedianByHand) {
  protocol::Procedure quest;
  quest.kind = protocol::Procedure::Kind::kQuestPlus;
  quest.thresholds = {1, 2, 3}, quest.slopes = {2}, quest.lapses = {0}, quest.stimuli = {0.5, 1, 2, 4};
  quest.guess = 0.5;
  double w[3], sum = 0;
  for (int t = 0; t < 3; ++t) sum += w[t] = 1 - 0.5 * std::exp(-std::pow(1.0 / (t + 1), 2));
  const double p1 = w[0] / sum, p2 = w[1] / sum;
  ASSERT_LT(p1, 0.5);
  EXPECT_NEAR(TrackEstimate(quest, {1}, {true}).estimate, 1 + (0.5 - p1) / p2, 1e-12);
  // Wrong at 4 twice: half the mass or more on the largest threshold - above what the grid tested, no number.
  EXPECT_FALSE(TrackEstimate(quest, {4, 4, 4}, {false, false, false}).determined);
}

// A pair at 2 px both sides, the right one the test side, seen by the pixel observer (jnd 0.6 px): a relative level
// x makes the right side 2 (1 + x) px, and P(correct) = Phi(2 x / 0.6) before lapses.
struct PixelPair {
  procedure::ObserverParams observer = procedure::ParseObserver("sim:model=pixel,jnd=0.6,lapse=0");
  protocol::Trial trial;
  stimulus::TrialScene scene;
  stimulus::Presentation presentation;
  PixelPair() {
    trial.cell = 0, trial.test_side = "right";
    scene.side(protocol::Side::kLeft).r_px = scene.side(protocol::Side::kRight).r_px = 2;
  }
};

TEST(ObserverThreshold, PixelObserverByTheClosedForm) {
  PixelPair pair;
  protocol::Procedure quest;
  quest.kind = protocol::Procedure::Kind::kQuestPlus;
  quest.thresholds = {0.05, 0.1, 0.5, 1};
  // QUEST+: Phi(x / 0.3) = 1 - 0.5 / e, x = 0.3 x 0.9004525966 (scipy norm.ppf).
  TrueThreshold t = ObserverThreshold(pair.observer, quest, pair.trial, pair.scene, pair.presentation);
  ASSERT_TRUE(t.determined) << t.why;
  EXPECT_NEAR(t.level, 0.3 * 0.9004525966377902, 1e-9);
  // Its slope on a log axis there, x phi(x / 0.3) / 0.3 = z phi(z), is a Weibull's (1 - 0.5) slope / e.
  const double z = 0.9004525966377902, phi = std::exp(-z * z / 2) / std::sqrt(2 * M_PI);
  EXPECT_NEAR(t.weibull_slope, z * phi * std::exp(1.0) / 0.5, 1e-5);
  // A 1-up/2-down staircase with 4 % lapses: (1 - 0.04) Phi(x / 0.3) + 0.02 = sqrt(1/2), x = 0.3 x 0.5702214.
  protocol::Procedure staircase;
  staircase.min = 0.01, staircase.max = 3;
  pair.observer.lapse = 0.04;
  t = ObserverThreshold(pair.observer, staircase, pair.trial, pair.scene, pair.presentation);
  ASSERT_TRUE(t.determined) << t.why;
  EXPECT_NEAR(t.level, 0.17106642182615864, 1e-9);
}

TEST(ObserverThreshold, OutsideTheRangeIsSaidInWords) {
  PixelPair pair;
  protocol::Procedure quest;
  quest.kind = protocol::Procedure::Kind::kQuestPlus;
  quest.thresholds = {0.5, 1, 2};  // the truth, 0.27, is below
  TrueThreshold t = ObserverThreshold(pair.observer, quest, pair.trial, pair.scene, pair.presentation);
  EXPECT_FALSE(t.determined);
  EXPECT_EQ(t.why, "below the tested range (0.5 to 2)");
  quest.thresholds = {0.01, 0.1};
  t = ObserverThreshold(pair.observer, quest, pair.trial, pair.scene, pair.presentation);
  EXPECT_EQ(t.why, "above the tested range (0.01 to 0.1)");
  // Lapses that keep the observer below the staircase's 70.7 %: never reached.
  protocol::Procedure staircase;
  pair.observer.lapse = 0.9;
  t = ObserverThreshold(pair.observer, staircase, pair.trial, pair.scene, pair.presentation);
  EXPECT_FALSE(t.determined);
  EXPECT_NE(t.why.find("never reached"), std::string::npos) << t.why;
}

// QUEST+ shows only its stimuli: a truth (0.27) inside its threshold grid but below every stimulus is not measured
// (the estimate is its prior's; the plan printed sd 0.016 and "power 1.000 at N = 2" for a declared difference), and
// stimuli wholly outside the grid measure nothing. Stimuli spanning the truth keep it, the range their overlap.
TEST(ObserverThreshold, QuestPlusStimuliBoundWhatItMeasures) {
  PixelPair pair;
  protocol::Procedure quest;
  quest.kind = protocol::Procedure::Kind::kQuestPlus;
  quest.thresholds = {0.05, 0.1, 0.5, 1};
  quest.stimuli = {0.4, 0.6, 0.8};
  TrueThreshold t = ObserverThreshold(pair.observer, quest, pair.trial, pair.scene, pair.presentation);
  EXPECT_FALSE(t.determined);
  EXPECT_EQ(t.why, "below the tested range (0.4 to 0.8)");
  quest.stimuli = {2, 3};
  t = ObserverThreshold(pair.observer, quest, pair.trial, pair.scene, pair.presentation);
  EXPECT_FALSE(t.determined);
  EXPECT_EQ(t.why, "not measured: QUEST+'s stimuli (2 to 3) lie outside its threshold grid (0.05 to 1)");
  EXPECT_GT(t.range_lo, t.range_hi);
  quest.stimuli = {0.1, 0.2, 0.4, 2};
  t = ObserverThreshold(pair.observer, quest, pair.trial, pair.scene, pair.presentation);
  ASSERT_TRUE(t.determined) << t.why;
  EXPECT_NEAR(t.level, 0.3 * 0.9004525966377902, 1e-9);
  EXPECT_EQ(t.range_lo, 0.1);
  EXPECT_EQ(t.range_hi, 1);
}

}  // namespace
}  // namespace blurcue::plan
