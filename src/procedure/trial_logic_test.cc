// What a session decides between trials (trial_logic.h) and what it prepares before the first (prepare.h), by hand.
#include "procedure/trial_logic.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "core/error.h"
#include "procedure/prepare.h"
#include "stimulus/test_scenes.h"

namespace blurcue::procedure {
namespace {

using stimulus::TrialScene;

// A choice by its record word, as a trial answered by `answer` reads it (a number: a rating point).
Choice Word(const std::string& text, protocol::TaskAnswer answer = protocol::TaskAnswer::kSide) {
  return ParseChoice(text, answer, false).value();
}
KeyPress Press(const std::string& word, double after_ms) {
  return {Action::Answer(Word(word)), after_ms};
}
KeyPress Step(Action::Kind kind, double after_ms) { return {Action::Of(kind), after_ms}; }

TEST(StepLevel, StepsThroughTheLevelsCyclicallyAndIgnoresOtherActions) {
  EXPECT_EQ(StepLevel(1, Action::Kind::kNext, 3), 2);
  EXPECT_EQ(StepLevel(2, Action::Kind::kNext, 3), 0);
  EXPECT_EQ(StepLevel(0, Action::Kind::kPrevious, 3), 2);
  EXPECT_EQ(StepLevel(1, Action::Kind::kAccept, 3), 1);
  EXPECT_EQ(StepLevel(4, Action::Kind::kNext, 0), 4);  // no levels: nothing to step through
}

TEST(StimulusEndS, IsTheEndOfTheMotionOrOfTheLastInterval) {
  protocol::Protocol p;
  TrialScene ball;
  ball.from_y_mm = 25, ball.to_y_mm = 85, ball.speed_mm_s = 30;  // 60 mm at 30 mm/s
  EXPECT_DOUBLE_EQ(StimulusEndS(p.timing, ball), 2.0);
  ball.speed_mm_s = 0;  // at rest: nothing to wait for
  EXPECT_DOUBLE_EQ(StimulusEndS(p.timing, ball), 0.0);
  p.timing.interval_ms = 500, p.timing.isi_ms = 250;
  TrialScene three;
  three.intervals = 3;  // 3 x 500 ms with 2 gaps of 250 ms
  EXPECT_DOUBLE_EQ(StimulusEndS(p.timing, three), 2.0);
}

TEST(CorrectOf, APairIsAnsweredRightByTheSideWithTheLargerRadiusOrCantTellWhenEqual) {
  protocol::Trial trial;
  trial.task = protocol::Task::kForcedChoice;
  TrialScene scene;
  scene.content = protocol::ContentType::kGrid;
  scene.side(protocol::Side::kLeft).r_px = 2, scene.side(protocol::Side::kRight).r_px = 1;
  EXPECT_EQ(CorrectOf(trial, scene, Word("left")), std::optional<bool>(true));
  EXPECT_EQ(CorrectOf(trial, scene, Word("right")), std::optional<bool>(false));
  EXPECT_EQ(CorrectOf(trial, scene, Word("cant_tell")), std::optional<bool>(false));
  scene.side(protocol::Side::kRight).r_px = 2;
  EXPECT_EQ(CorrectOf(trial, scene, Word("cant_tell")), std::optional<bool>(true));
  EXPECT_EQ(CorrectOf(trial, scene, Word("left")), std::optional<bool>(false));
  // A procedure's trial: its test side, whatever the radii.
  trial.test_side = "right";
  scene.side(protocol::Side::kLeft).r_px = 5;
  EXPECT_EQ(CorrectOf(trial, scene, Word("right")), std::optional<bool>(true));
  EXPECT_EQ(CorrectOf(trial, scene, Word("left")), std::optional<bool>(false));
  // An odd one out's: its interval.
  trial.test_side = "3";
  EXPECT_EQ(CorrectOf(trial, scene, *ParseChoice("3", protocol::TaskAnswer::kSide, true)), std::optional<bool>(true));
  EXPECT_EQ(CorrectOf(trial, scene, *ParseChoice("2", protocol::TaskAnswer::kSide, true)), std::optional<bool>(false));
  // Nothing is correct in a yes/no trial without a test side, nor in a picture.
  trial.test_side.clear();
  trial.task = protocol::Task::kYesNo;
  EXPECT_FALSE(CorrectOf(trial, scene, Word("yes", protocol::TaskAnswer::kYesNo)).has_value());
  trial.task = protocol::Task::kForcedChoice;
  scene.content = protocol::ContentType::kPicture;
  EXPECT_FALSE(CorrectOf(trial, scene, Word("left")).has_value());
}

TEST(HeadlessAnswer, AnAnswerAtOrAfterTheDeadlineIsNoAnswer) {
  protocol::Protocol p;
  protocol::Trial trial;
  trial.task = protocol::Task::kForcedChoice;
  TrialScene scene;
  scene.from_y_mm = 0, scene.to_y_mm = 10, scene.speed_mm_s = 10;  // 1 s of motion, watched to its end
  p.timing.deadline_ms = 1500;
  const auto early = HeadlessAnswer(p, trial, scene, {Press("left", 400)});
  EXPECT_EQ(Name(early.first), "left");
  EXPECT_DOUBLE_EQ(early.second, 1400);
  const auto late = HeadlessAnswer(p, trial, scene, {Press("left", 500)});
  EXPECT_EQ(Name(late.first), "none");
  EXPECT_TRUE(std::isnan(late.second));
  EXPECT_EQ(HeadlessAnswer(p, trial, scene, {}).first.kind, Choice::Kind::kNone);
}

TEST(HeadlessAnswer, AnAdjustmentAcceptsTheLevelItsStepsReached) {
  protocol::Protocol p;
  protocol::Trial trial;
  trial.task = protocol::Task::kAdjustment;
  trial.adjust_levels = {10, 20, 40};
  trial.start_index = 0;
  TrialScene scene;
  // previous from 10 wraps to 40, next to 10 again, next to 20: accepted after 100 + 200 + 300 + 400 ms.
  const auto answer =
      HeadlessAnswer(p, trial, scene, {Step(Action::Kind::kPrevious, 100), Step(Action::Kind::kNext, 200),
                                       Step(Action::Kind::kNext, 300), Step(Action::Kind::kAccept, 400)});
  EXPECT_EQ(Name(answer.first), "20");
  EXPECT_DOUBLE_EQ(answer.second, 1000);
  EXPECT_EQ(HeadlessAnswer(p, trial, scene, {Step(Action::Kind::kNext, 100)}).first.kind,
            Choice::Kind::kNone);  // never accepted
}

// A study of grid cards on the thesis's view, prepared without reading a file (PrepareStudy's part given by hand).
PreparedSession Study(const Json& extra = Json::object()) {
  Json json = {{"name", "prepare-test"},
               {"version", 1},
               {"scene", stimulus::fixtures::StandInScene()},
               {"content", {{"type", "grid"}, {"cells", 5}}},
               {"task", "forced_choice"},
               {"factors", {{"edge", {2, 4, 6, 8, 10}}}},
               {"sides", {{"left", "fitted"}, {"right", "none"}}},
               {"responses", {{"left", "Left"}, {"right", "Right"}, {"cant_tell", "Down"}}},
               {"display", {{"width_px", 1280}, {"height_px", 720}}}};
  json.merge_patch(extra);
  PreparedSession s;
  s.protocol = protocol::ParseProtocol(json, "prepare-test.json");
  s.scene = stimulus::fixtures::ThesisScene();
  s.images.photo = cv::Mat(764, 1148, CV_8UC3, cv::Scalar::all(128));
  s.presentation = stimulus::Presentation::Of(s.protocol, s.images, s.display);
  return s;
}

TEST(PrepareParticipant, SameSeedSameTrialsWithOneScenePerTrialPlannedOnTheScreen) {
  PreparedSession a = Study(), b = Study();
  PrepareParticipant(&a, "P1", 7);
  PrepareParticipant(&b, "P1", 7);
  ASSERT_EQ(a.trials.size(), 5u);
  ASSERT_EQ(a.scenes.size(), a.trials.size());
  EXPECT_EQ(a.seed, 7u);
  for (size_t i = 0; i < a.trials.size(); ++i) {
    EXPECT_EQ(a.trials[i].levels, b.trials[i].levels) << i;
    EXPECT_DOUBLE_EQ(a.scenes[i].side(protocol::Side::kLeft).r_px, b.scenes[i].side(protocol::Side::kLeft).r_px) << i;
    // The fitted side is blurred, the other not; the plan on the screen has been worked out (sizes in degrees).
    EXPECT_GT(a.scenes[i].side(protocol::Side::kLeft).r_px, 0) << i;
    EXPECT_EQ(a.scenes[i].side(protocol::Side::kRight).r_px, 0) << i;
    EXPECT_GT(a.scenes[i].side(protocol::Side::kLeft).size_deg, 0) << i;
  }
  // Without a seed, the participant's default seed: another participant gets another one.
  PreparedSession c = Study(), d = Study();
  PrepareParticipant(&c, "P1", std::nullopt);
  PrepareParticipant(&d, "P2", std::nullopt);
  EXPECT_EQ(c.seed, protocol::DefaultSeed("prepare-test", "P1"));
  EXPECT_NE(c.seed, d.seed);
  // Preparing again replaces what was there: still one scene per trial.
  PrepareParticipant(&a, "P2", 8);
  EXPECT_EQ(a.scenes.size(), a.trials.size());
}

TEST(PrepareParticipant, AGroupTheProtocolDoesNotNameIsAnInputErrorNamingGroupsNames) {
  PreparedSession s = Study({{"groups", {{"names", {"near", "far"}}, {"assign", "by_number"}}}});
  PrepareParticipant(&s, "P1", 1, "far");
  EXPECT_EQ(s.group, "far");
  try {
    PrepareParticipant(&s, "P1", 1, "middle");
    ADD_FAILURE() << "a group the protocol does not name was run";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kInput);
    EXPECT_NE(std::string(e.what()).find("/groups/names"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace blurcue::procedure
