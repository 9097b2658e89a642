#include "procedure/answer.h"

#include <gtest/gtest.h>

#include <cmath>

#include "procedure/observer.h"
#include "protocol/protocol.h"
#include "store/record.h"

namespace blurcue::procedure {

using stimulus::Presentation;
using stimulus::TrialScene;
namespace {

double Phi(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }

// A presentation of `scale` screen px per photo px on the default monitor (24-inch 1920 x 1080 at 60 cm).
Presentation At(double scale) {
  Presentation p;
  p.scale = scale;
  return p;
}

// The task decides the question: each trial gets the answer of the observer method its task names, from the same
// seed, and nothing else.
TEST(AnswerTrial, EachTaskAsksItsQuestion) {
  protocol::Protocol protocol;
  protocol.responses.cant_tell = "Down";
  protocol.responses.rating = {"1", "2", "3", "4", "5"};
  TrialScene scene;
  scene.side(protocol::Side::kLeft).r_px = 2.0, scene.side(protocol::Side::kRight).r_px = 2.6, scene.r_scene_px = 2.1;
  const Presentation shown = At(0.9);
  const PairView view = ViewOf(scene, shown);
  EXPECT_DOUBLE_EQ(view.arcmin_per_px, shown.Arcmin(1));
  const ObserverParams params;
  for (uint64_t seed = 1; seed <= 30; ++seed) {
    protocol::Trial trial;
    auto answer = [&](const protocol::Trial& t, const TrialScene& s) {
      SimulatedObserver o(params, seed);
      const auto presses = AnswerTrial(o, protocol, t, s, shown);
      EXPECT_EQ(presses.size(), 1u);
      return Name(presses.front().action);
    };
    trial.task = protocol::Task::kForcedChoice;  // "which fits the scene?", can't tell allowed
    EXPECT_EQ(answer(trial, scene), Name(SimulatedObserver(params, seed).ChooseSide(view, true).action));
    trial.cell = 0;  // a procedure's trial: "which is more blurred?"
    EXPECT_EQ(answer(trial, scene), Name(SimulatedObserver(params, seed).ChooseBlurrier(view).action));
    trial.cell = -1;
    trial.task = protocol::Task::kYesNo;
    EXPECT_EQ(answer(trial, scene), Name(SimulatedObserver(params, seed).SayYesNo(view).action));
    trial.task = protocol::Task::kRating;
    EXPECT_EQ(answer(trial, scene), Name(SimulatedObserver(params, seed).Rate(view, 5).action));
    trial.task = protocol::Task::kForcedChoice;
    trial.test_side = "3";
    TrialScene odd = scene;
    odd.intervals = 4;
    EXPECT_EQ(answer(trial, odd), Name(SimulatedObserver(params, seed).ChooseOdd(view, 4, 3).action));
  }
}

// Through AnswerTrial the arcmin observer sees what the presentation shows: the same photo radii shown at a quarter of
// the scale are told apart less often, and each rate is the model's probability.
TEST(AnswerTrial, SeesTheRadiiAtThePresentationsScale) {
  protocol::Protocol protocol;
  protocol::Trial trial;
  trial.cell = 0;
  TrialScene scene;
  scene.side(protocol::Side::kLeft).r_px = 1.0, scene.side(protocol::Side::kRight).r_px = 0.5;
  ObserverParams params;
  params.lapse = 0;
  const int draws = 6000;
  const double se = std::sqrt(0.25 / draws);
  double rate[2];
  for (int k = 0; k < 2; ++k) {
    const Presentation shown = At(k == 0 ? 1.0 : 0.25);
    int left = 0;
    for (int i = 0; i < draws; ++i) {
      SimulatedObserver o(params, TrialSeed(11, i));
      left += Name(AnswerTrial(o, protocol, trial, scene, shown).front().action) == "left";
    }
    rate[k] = left / double(draws);
    // The model written out: s = r / 2 in arcmin, E = sqrt(s^2 + s_i^2), P = Phi(z75 ln(E_l / E_r) / ln(1 + w)).
    const double k_arcmin = shown.Arcmin(1);
    auto e = [&](double r_px) { return std::hypot(r_px * k_arcmin / 2, params.intrinsic_arcmin); };
    const double truth = Phi(0.6744897501960817 * std::log(e(1.0) / e(0.5)) / std::log(1 + params.weber));
    EXPECT_NEAR(rate[k], truth, 4 * se) << "scale " << shown.scale;
  }
  EXPECT_GT(rate[0], rate[1] + 0.05);
}

TEST(AnswerTrial, SeedsDifferPerTrialAndRepeat) {
  EXPECT_EQ(TrialSeed(5, 3), TrialSeed(5, 3));
  EXPECT_NE(TrialSeed(5, 3), TrialSeed(5, 4));
  EXPECT_NE(TrialSeed(5, 3), TrialSeed(6, 3));
}

}  // namespace
}  // namespace blurcue::procedure

namespace blurcue::procedure {
namespace {

using protocol::TaskAnswer;

// Every kind of choice reads back from its word as the kind of task that records it.
TEST(Choice, EachKindReadsBackFromItsName) {
  struct Case {
    Choice choice;
    TaskAnswer answer;
    bool intervals;
    const char* word;
  };
  const Case cases[] = {
      {Choice::Of(protocol::Side::kLeft), TaskAnswer::kSide, false, "left"},
      {Choice::Of(protocol::Side::kRight), TaskAnswer::kSide, false, "right"},
      {Choice::Of(Choice::Kind::kCantTell), TaskAnswer::kSide, false, "cant_tell"},
      {Choice::Of(Choice::Kind::kCantTell), TaskAnswer::kSide, true, "cant_tell"},
      {Choice::Numbered(Choice::Kind::kInterval, 3), TaskAnswer::kSide, true, "3"},
      {Choice::Of(Choice::Kind::kYes), TaskAnswer::kYesNo, false, "yes"},
      {Choice::Of(Choice::Kind::kNo), TaskAnswer::kYesNo, false, "no"},
      {Choice::Numbered(Choice::Kind::kRating, 5), TaskAnswer::kRatingPoint, false, "5"},
      {Choice::Level(0.35), TaskAnswer::kLevel, false, "0.35"},
      {Choice::Level(12), TaskAnswer::kLevel, false, "12"},
      {Choice::Of(Choice::Kind::kNone), TaskAnswer::kSide, false, "none"},
      {Choice::Of(Choice::Kind::kSkipped), TaskAnswer::kLevel, false, "skipped"},
  };
  for (const Case& c : cases) {
    EXPECT_EQ(Name(c.choice), c.word);
    const std::optional<Choice> read = ParseChoice(c.word, c.answer, c.intervals);
    ASSERT_TRUE(read.has_value()) << c.word;
    EXPECT_EQ(*read, c.choice) << c.word;
  }
  // The record's two non-answers are store's words.
  EXPECT_EQ(Name(Choice::Of(Choice::Kind::kNone)), store::kChoiceNone);
  EXPECT_EQ(Name(Choice::Of(Choice::Kind::kSkipped)), store::kChoiceSkipped);
}

// A word the task has no answer for, or another spelling of one it has, is no choice: a resumed record that holds
// one is refused.
TEST(Choice, ReadsOnlyTheTasksAnswersInTheFormNameWrites) {
  EXPECT_FALSE(ParseChoice("left", TaskAnswer::kSide, true));     // an odd one out names intervals
  EXPECT_FALSE(ParseChoice("2", TaskAnswer::kSide, false));       // a pair names sides
  EXPECT_FALSE(ParseChoice("yes", TaskAnswer::kSide, false));
  EXPECT_FALSE(ParseChoice("cant_tell", TaskAnswer::kYesNo, false));
  EXPECT_FALSE(ParseChoice("Left", TaskAnswer::kSide, false));
  EXPECT_FALSE(ParseChoice("03", TaskAnswer::kRatingPoint, false));
  EXPECT_FALSE(ParseChoice("+3", TaskAnswer::kRatingPoint, false));
  EXPECT_FALSE(ParseChoice("0.350", TaskAnswer::kLevel, false));  // %g writes 0.35
  EXPECT_FALSE(ParseChoice(" 1", TaskAnswer::kLevel, false));
  EXPECT_FALSE(ParseChoice("left", TaskAnswer::kLevel, false));
  EXPECT_FALSE(ParseChoice("", TaskAnswer::kRatingPoint, false));
}

TEST(Action, NamesAnAnswerByItsChoiceAndAStepByItsResponsesField) {
  EXPECT_EQ(Name(Action::Answer(Choice::Of(protocol::Side::kRight))), "right");
  EXPECT_EQ(Name(Action::Of(Action::Kind::kNext)), "next");
  EXPECT_EQ(Name(Action::Of(Action::Kind::kPrevious)), "previous");
  EXPECT_EQ(Name(Action::Of(Action::Kind::kAccept)), "accept");
  EXPECT_EQ(Name(Action{}), "");
}

}  // namespace
}  // namespace blurcue::procedure
