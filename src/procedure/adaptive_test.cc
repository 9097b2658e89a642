// Adaptive procedures: the staircase's rules by hand, QUEST+ against the closed form and a simulated observer (its
// agreement with python3-questplus is tests/quest_agreement.py), and one state per crossing.
#include "procedure/adaptive.h"

#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "core/error.h"

namespace blurcue::procedure {
namespace {

protocol::Procedure Stairs() {
  protocol::Procedure p;
  p.kind = protocol::Procedure::Kind::kStaircase;
  p.start = 1.0, p.min = 0.1, p.max = 1.5;
  p.up = 1, p.down = 2;
  p.steps = {0.4, 0.2, 0.1};
  return p;
}

TEST(Staircase, TwoDownOneUpWithStepsThatShrinkAtReversals) {
  Staircase s(Stairs());
  EXPECT_DOUBLE_EQ(s.Level(), 1.0);
  s.Update(true);
  EXPECT_DOUBLE_EQ(s.Level(), 1.0);  // one correct is not yet two
  s.Update(true);
  EXPECT_DOUBLE_EQ(s.Level(), 0.6);  // two in a row: down by the first step
  s.Update(false);                   // one wrong: up - a reversal, so the second step
  EXPECT_EQ(s.Reversals(), 1);
  EXPECT_DOUBLE_EQ(s.Level(), 0.8);
  EXPECT_EQ(s.ReversalLevels(), std::vector<double>{0.6});
  s.Update(true);
  s.Update(true);  // down again: the second reversal, the third (last) step
  EXPECT_EQ(s.Reversals(), 2);
  EXPECT_NEAR(s.Level(), 0.7, 1e-12);
  s.Update(true);
  s.Update(false);  // a wrong answer resets the run of correct ones: up, reversal 3, the last step stays
  EXPECT_NEAR(s.Level(), 0.8, 1e-12);
  for (int i = 0; i < 20; ++i) s.Update(false);
  EXPECT_DOUBLE_EQ(s.Level(), 1.5);  // clamped at max
  for (int i = 0; i < 60; ++i) s.Update(true);
  EXPECT_DOUBLE_EQ(s.Level(), 0.1);  // and at min
}

protocol::Procedure Quest() {
  protocol::Procedure p;
  p.kind = protocol::Procedure::Kind::kQuestPlus;
  for (int i = 1; i <= 30; ++i) p.stimuli.push_back(0.1 * i);
  for (int i = 1; i <= 25; ++i) p.thresholds.push_back(0.12 * i);
  p.slopes = {1.5, 2.5, 3.5};
  p.lapses = {0.0, 0.02, 0.05};
  p.guess = 0.5;
  return p;
}

TEST(QuestPlus, PosteriorIsBayesOverTheGridAndConcentratesOnTheObserversThreshold) {
  const protocol::Procedure p = Quest();
  QuestPlus q(p);
  // One update by hand: prior uniform, posterior proportional to the Weibull's p(correct) at x = 1.
  q.Update(1.0, true);
  double sum = 0;
  std::vector<double> expected;
  for (double t : p.thresholds)
    for (double b : p.slopes)
      for (double l : p.lapses) {
        expected.push_back(1 - l - (1 - p.guess - l) * std::exp(-std::pow(1.0 / t, b)));
        sum += expected.back();
      }
  ASSERT_EQ(q.Posterior().size(), expected.size());
  for (size_t k = 0; k < expected.size(); ++k) EXPECT_NEAR(q.Posterior()[k], expected[k] / sum, 1e-12);
  EXPECT_THROW(q.Update(1.05, true), Error);  // not one of its stimuli
  // An observer of threshold 1.2, slope 2.5, no lapses: 200 trials bring the estimate within 0.2 of it (one seeded
  // run; python3-questplus reaches 1.30 on its own such run).
  QuestPlus run(p);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(0, 1);
  for (int i = 0; i < 200; ++i) {
    const double x = run.Next();
    const double pc = 1 - 0.5 * std::exp(-std::pow(x / 1.2, 2.5));
    run.Update(x, u(rng) < pc);
  }
  EXPECT_NEAR(run.MeanThreshold(), 1.2, 0.2);
  EXPECT_GT(run.MeanSlope(), 1.4);
}

TEST(AdaptiveState, EachCrossingRunsItsOwnProcedure) {
  protocol::Protocol protocol;
  protocol::Block block;
  block.name = "stairs";
  block.procedure = Stairs();
  protocol.blocks.push_back(block);
  AdaptiveState state(protocol);
  protocol::Trial a, b;
  a.block = b.block = "stairs";
  a.cell = 0, b.cell = 1;
  a.test_side = b.test_side = "left";
  state.Answer(a, state.Level(a), true);
  state.Answer(a, state.Level(a), true);
  EXPECT_DOUBLE_EQ(state.Level(a), 0.6);
  EXPECT_DOUBLE_EQ(state.Level(b), 1.0);  // untouched by a's answers
  protocol::Trial stray;
  stray.block = "nowhere";
  stray.cell = 0;
  EXPECT_THROW(state.Level(stray), Error);
}

// A stop rule: the staircase ends at its second reversal, by hand: down after two correct (0.6), up after a wrong
// one (reversal 1), down after two correct (reversal 2) - stopped there, and not a trial earlier. Its other
// crossing, untouched, has not stopped.
TEST(AdaptiveState, AStaircaseStopsAtItsReversal) {
  protocol::Protocol protocol;
  protocol::Block block;
  block.name = "stairs";
  block.procedure = Stairs();
  block.procedure->stop_reversals = 2;
  protocol.blocks.push_back(block);
  AdaptiveState state(protocol);
  protocol::Trial a, b;
  a.block = b.block = "stairs";
  a.cell = 0, b.cell = 1;
  for (bool correct : {true, true, false, true}) {
    EXPECT_FALSE(state.Stopped(a));
    state.Answer(a, state.Level(a), correct);
  }
  EXPECT_EQ(state.Reversals(a), 1);
  EXPECT_FALSE(state.Stopped(a));
  state.Answer(a, state.Level(a), true);  // the second reversal
  EXPECT_EQ(state.Reversals(a), 2);
  EXPECT_TRUE(state.Stopped(a));
  EXPECT_FALSE(state.Stopped(b));
}

}  // namespace
}  // namespace blurcue::procedure
