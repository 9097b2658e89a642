// Whole small sessions through the trial loop without GL: a fake presenter that records what it is asked to show (on
// a simulated clock, as headless), a responder that answers as told, and a record in memory or in a temp file.
#include <unistd.h>
#include "session/trial_loop.h"

#include <gtest/gtest.h>

#include <cmath>
#include <deque>
#include <filesystem>
#include <limits>
#include <string>
#include <vector>

#include "core/error.h"
#include "session/keys.h"
#include "procedure/trial_logic.h"
#include "stimulus/test_scenes.h"
#include "store/sqlite.h"

namespace blurcue::session {
namespace {

using render::InputEvent;
using stimulus::TrialScene;

// A protocol of grid cards on the thesis's view; `extra` is merged over it (blocks, practice, timing...).
Json GridProtocol(const Json& extra) {
  Json p = {{"name", "runner-test"},
            {"version", 1},
            {"scene", stimulus::fixtures::StandInScene()},
            {"content", {{"type", "grid"}, {"cells", 5}}},
            {"task", "forced_choice"},
            {"sides", {{"left", 2.0}, {"right", "none"}}},
            {"instructions", "Which one is more blurred?"},
            {"responses", {{"left", "Left"}, {"right", "Right"}, {"cant_tell", "Down"}}},
            {"timing", {{"stimulus_ms", "until_response"}, {"inter_trial_ms", 500}}},
            {"display", {{"width_px", 1280}, {"height_px", 720}}}};
  p.merge_patch(extra);
  return p;
}

// The session `blurcue run` prepares from a protocol, with the calibration and the photo given here instead of read.
procedure::PreparedSession Prepare(const Json& json, const std::string& participant = "P1", uint64_t seed = 42) {
  procedure::PreparedSession s;
  s.protocol_text = json.dump();
  s.protocol = protocol::ParseProtocol(json, "runner-test.json");
  s.scene = stimulus::fixtures::ThesisScene();
  s.images.photo = cv::Mat(764, 1148, CV_8UC3, cv::Scalar::all(128));
  s.images.texture = cv::Mat(64, 64, CV_8UC3, cv::Scalar::all(255));
  s.presentation = stimulus::Presentation::Of(s.protocol, s.images, s.display);
  procedure::PrepareParticipant(&s, participant, seed);
  return s;
}

// Records what the loop asks it to show, on a simulated clock like the headless presenter's.
class FakePresenter : public Presenter {
 public:
  explicit FakePresenter(const procedure::PreparedSession& prepared) : prepared_(prepared) {}
  bool RealTime() const override { return false; }
  double FrameS() const override { return 0.25; }
  double Now() const override { return clock_s_; }
  bool Closed() const override { return false; }
  void Wait(double seconds) override { clock_s_ += seconds; }
  bool StartTrial() override {
    clock_s_ = 0;
    return true;
  }
  void SetTitle(const std::string& title) override { titles.push_back(title); }
  void Prepare(const TrialScene&) override {}
  void Compose(const TrialScene& scene, double t_s, double) override {
    shown_ = stimulus::ObjectsAt(prepared_.protocol, *prepared_.scene, scene, t_s);
    composed_levels.push_back(scene.level);
  }
  const std::array<std::optional<scene::BlurredObject>, 2>& Shown() const override { return shown_; }
  void ShowStimulus(const StimulusFrame& frame) override {
    if (frame.index == 0) trials_shown.push_back(frame.trial->index);
  }
  void ShowText(const std::string& title, const std::string& body, const std::string&) override {
    screens.push_back(title + ": " + body);
  }
  void DrawScreen() override {}
  void ShowTextFor(const std::string& title, double seconds) override {
    feedback.push_back(title);
    Wait(seconds);
  }
  void ShowFixationFor(double seconds) override { Wait(seconds); }
  void ShowBlankFor(double seconds) override { Wait(seconds); }
  void ShowLast(const std::string& title, const std::string&) override { screens.push_back(title); }

  std::vector<std::string> titles, screens, feedback;
  std::vector<int> trials_shown;       // each trial's index, at its first frame
  std::vector<double> composed_levels;  // the procedure level of every composed frame

 protected:
  double DoFlip(double wake_s) override {
    const double flip = clock_s_;
    clock_s_ = std::max(clock_s_, std::min(clock_s_ + FrameS(), wake_s));
    return flip;
  }

 private:
  const procedure::PreparedSession& prepared_;
  std::array<std::optional<scene::BlurredObject>, 2> shown_;
  double clock_s_ = 0;
};

// Answers each trial 0.3 s after onset: correctly (the test side of a procedure's trial, else the side showing the
// larger radius) or wrongly, as `correct` says in turn (all correct once it runs out); Return on every text screen.
class AnsweringResponder : public Responder {
 public:
  explicit AnsweringResponder(std::vector<bool> correct = {}) : correct_(correct.begin(), correct.end()) {}
  std::vector<InputEvent> Poll(double now_s) override {
    std::vector<InputEvent> due;
    while (!planned_.empty() && planned_.front().time_s <= now_s + 1e-9) {
      due.push_back(planned_.front());
      planned_.pop_front();
    }
    return due;
  }
  double NextPressS() const override {
    return planned_.empty() ? std::numeric_limits<double>::infinity() : planned_.front().time_s;
  }
  void ScreenShown(double now_s) override { planned_.push_back({"Return", now_s + 0.6}); }
  void StimulusShown(const protocol::Trial& trial, const TrialScene& scene, double onset_s) override {
    const bool right_side = trial.cell >= 0
                                ? trial.test_side == "right"
                                : scene.side(protocol::Side::kRight).r_px > scene.side(protocol::Side::kLeft).r_px;
    bool correct = true;
    if (!correct_.empty()) correct = correct_.front(), correct_.pop_front();
    planned_.push_back({right_side == correct ? "Right" : "Left", onset_s + 0.3});
    ++answered;
  }
  void Forget() override { planned_.clear(); }
  int answered = 0;

 private:
  std::deque<bool> correct_;
  std::deque<InputEvent> planned_;
};

// Starts (or resumes) the participant's session in `recording` and runs it.
RunResult RunSessionOf(Recording& recording, const procedure::PreparedSession& prepared, Presenter& presenter,
                       Responder& responder, int stop_after = -1, bool resume = false) {
  const LoopOptions options{"runner-test.sqlite", stop_after, {}};
  SessionInfo info;
  info.simulated = true;
  info.window = false;
  const SessionStart start = recording.StartOrResumeSession(prepared.protocol.name, "P1", prepared.protocol_text,
                                                            prepared.seed, info, resume);
  if (start.trial_count == 0)
    recording.SaveTrialList(start.session_id, prepared);
  else
    recording.CheckTrialList(start.session_id, prepared);
  return RunTrials(options, prepared, presenter, responder, recording, start);
}

double Level(const RecordedAnswer& answer) { return ParseJson(answer.shown_json, "shown")["level"].get<double>(); }

TEST(Runner, EveryPlannedTrialGetsExactlyOneResponseInOrder) {
  const procedure::PreparedSession prepared = Prepare(GridProtocol({{"factors", {{"edge", {2, 4, 6, 8}}}}, {"repetitions", 2}}));
  ASSERT_EQ(prepared.trials.size(), 8u);
  Recording recording = Recording::Open(":memory:");
  FakePresenter presenter(prepared);
  AnsweringResponder responder;
  const RunResult result = RunSessionOf(recording, prepared, presenter, responder);
  EXPECT_TRUE(result.completed);
  EXPECT_EQ(result.trial_count, 8);
  EXPECT_EQ(result.answered_now, 8);
  EXPECT_EQ(presenter.trials_shown, (std::vector<int>{0, 1, 2, 3, 4, 5, 6, 7}));
  EXPECT_EQ(responder.answered, 8);
  const auto answers = recording.AnsweredTrials(result.session_id);
  ASSERT_EQ(answers.size(), 8u);
  // The left card is blurred by 2 px, the right one not at all: a correct answer is always "left".
  for (const auto& [index, answer] : answers) EXPECT_EQ(answer.choice, "left") << "trial " << index;
  EXPECT_EQ(recording.FirstUnansweredTrial(result.session_id), 8);
}

TEST(Runner, ResumedSessionContinuesAtTheFirstUnansweredTrialWithTheSameOrder) {
  const std::filesystem::path db = std::filesystem::temp_directory_path() / ("blurcue-runner-test-resume-" + std::to_string(::getpid()) + ".sqlite");
  std::filesystem::remove(db);
  const Json json = GridProtocol({{"factors", {{"edge", {2, 3, 4, 5, 6, 7}}}}});
  const procedure::PreparedSession prepared = Prepare(json);
  int64_t session = 0;
  {
    Recording recording = Recording::Open(db);
    FakePresenter presenter(prepared);
    AnsweringResponder responder({true, false, true});
    const RunResult first = RunSessionOf(recording, prepared, presenter, responder, 3);
    EXPECT_FALSE(first.completed);
    EXPECT_EQ(first.answered_now, 3);
    EXPECT_EQ(presenter.trials_shown, (std::vector<int>{0, 1, 2}));
    session = first.session_id;
  }
  // Another sitting: the same participant's list, prepared again, continues where the record stops.
  const procedure::PreparedSession again = Prepare(json);
  Recording recording = Recording::Open(db);
  FakePresenter presenter(again);
  AnsweringResponder responder;
  const RunResult rest = RunSessionOf(recording, again, presenter, responder, -1, true);
  EXPECT_EQ(rest.session_id, session);
  EXPECT_EQ(rest.answered_before, 3);
  EXPECT_EQ(rest.answered_now, 3);
  EXPECT_TRUE(rest.completed);
  EXPECT_EQ(presenter.trials_shown, (std::vector<int>{3, 4, 5}));
  EXPECT_EQ(presenter.screens.front(), "Welcome back: Which one is more blurred?");
  const auto answers = recording.AnsweredTrials(session);
  ASSERT_EQ(answers.size(), 6u);
  EXPECT_EQ(answers.at(0).choice, "left");
  EXPECT_EQ(answers.at(1).choice, "right");  // the wrong answer of the first sitting is kept
  for (int i = 2; i < 6; ++i) EXPECT_EQ(answers.at(i).choice, "left") << i;
  std::filesystem::remove(db);
}

// The staircase of StaircaseLevelsFollowTheAnswersByItsSteps.
Json StaircaseProtocol() {
  const Json blocks = {{{"name", "staircase"},
                        {"factors", {{"edge", {5}}}},
                        {"procedure",
                         {{"type", "staircase"}, {"variable", "relative_difference"}, {"reference", "fitted"},
                          {"trials", 6}, {"start", 1.0}, {"min", 0.02}, {"max", 3}, {"up", 1}, {"down", 2},
                          {"steps", {0.4, 0.2}}, {"stop", {{"reversals", 4}}}}}}};
  Json json = GridProtocol({{"blocks", blocks}});
  json.erase("sides");
  return json;
}

// A 1-up/2-down staircase from 1.0 with steps 0.4 then 0.2: correct, correct (down 0.4 to 0.6), wrong (a reversal:
// up by the next step, 0.2, to 0.8), correct, correct (down 0.2 to 0.6).
TEST(Runner, StaircaseLevelsFollowTheAnswersByItsSteps) {
  const Json json = StaircaseProtocol();
  const procedure::PreparedSession prepared = Prepare(json);
  ASSERT_EQ(prepared.trials.size(), 6u);
  Recording recording = Recording::Open(":memory:");
  FakePresenter presenter(prepared);
  AnsweringResponder responder({true, true, false, true, true, true});
  const RunResult result = RunSessionOf(recording, prepared, presenter, responder);
  ASSERT_TRUE(result.completed);
  const auto answers = recording.AnsweredTrials(result.session_id);
  const std::vector<double> expected = {1.0, 1.0, 0.6, 0.8, 0.8, 0.6};
  ASSERT_EQ(answers.size(), expected.size());
  for (size_t i = 0; i < expected.size(); ++i) EXPECT_NEAR(Level(answers.at(int64_t(i))), expected[i], 1e-9) << i;
  // What was composed is what was recorded: the level on the test side, frame by frame.
  ASSERT_FALSE(presenter.composed_levels.empty());
  EXPECT_NEAR(presenter.composed_levels.back(), 0.6, 1e-9);
}

// Stopped after correct, correct, wrong (the staircase at 0.8 after its first reversal), a resumed session replays
// those answers and shows its next trial at 0.8, then goes on as an uninterrupted one would.
TEST(Runner, ResumedStaircaseContinuesAtTheLevelItsRecordedAnswersGive) {
  const std::filesystem::path db = std::filesystem::temp_directory_path() / ("blurcue-runner-test-staircase-" + std::to_string(::getpid()) + ".sqlite");
  std::filesystem::remove(db);
  const procedure::PreparedSession prepared = Prepare(StaircaseProtocol());
  {
    Recording recording = Recording::Open(db);
    FakePresenter presenter(prepared);
    AnsweringResponder responder({true, true, false});
    ASSERT_EQ(RunSessionOf(recording, prepared, presenter, responder, 3).answered_now, 3);
  }
  Recording recording = Recording::Open(db);
  FakePresenter presenter(prepared);
  AnsweringResponder responder({true, true, true});
  const RunResult rest = RunSessionOf(recording, prepared, presenter, responder, -1, true);
  ASSERT_TRUE(rest.completed);
  ASSERT_FALSE(presenter.composed_levels.empty());
  EXPECT_NEAR(presenter.composed_levels.front(), 0.8, 1e-9);
  const auto answers = recording.AnsweredTrials(rest.session_id);
  const std::vector<double> expected = {1.0, 1.0, 0.6, 0.8, 0.8, 0.6};
  for (size_t i = 0; i < expected.size(); ++i) EXPECT_NEAR(Level(answers.at(int64_t(i))), expected[i], 1e-9) << i;
  std::filesystem::remove(db);
}

// A practice block of two trials, run until all of a run are correct (at most three runs): the first run is all
// correct, so the second and third are recorded as skipped, not shown.
TEST(Runner, PracticeUntilCriterionSkipsTheRunsAfterTheOneThatMetIt) {
  const Json blocks = {{{"name", "warm-up"},
                        {"practice", true},
                        {"factors", {{"edge", {3, 7}}}},
                        {"criterion", {{"correct", 1.0}, {"max_repeats", 3}}}},
                       {{"name", "main"}, {"factors", {{"edge", {2, 5}}}}}};
  const procedure::PreparedSession prepared = Prepare(GridProtocol({{"blocks", blocks}}));
  ASSERT_EQ(prepared.trials.size(), 8u);  // 3 runs of 2 practice trials, then 2 main ones
  Recording recording = Recording::Open(":memory:");
  FakePresenter presenter(prepared);
  AnsweringResponder responder;
  const RunResult result = RunSessionOf(recording, prepared, presenter, responder);
  EXPECT_TRUE(result.completed);
  EXPECT_EQ(result.answered_now, 4);
  EXPECT_EQ(result.skipped_now, 4);
  EXPECT_EQ(result.skipped_by_criterion_now, 4);
  EXPECT_EQ(presenter.trials_shown, (std::vector<int>{0, 1, 6, 7}));
  const auto answers = recording.AnsweredTrials(result.session_id);
  for (int i = 2; i < 6; ++i) EXPECT_EQ(answers.at(i).choice, store::kChoiceSkipped) << i;
}

TEST(Runner, ShowsTheInstructionsThenEachPartsScreenAsItsBlockBegins) {
  const Json blocks = {{{"name", "near"}, {"factors", {{"edge", {2, 3}}}}, {"instructions", "The near cards."}},
                       {{"name", "far"}, {"factors", {{"edge", {8, 9}}}}, {"instructions", "The far cards."}}};
  Json json = GridProtocol({{"blocks", blocks}, {"block_order", "fixed"}});
  const procedure::PreparedSession prepared = Prepare(json);
  Recording recording = Recording::Open(":memory:");
  FakePresenter presenter(prepared);
  AnsweringResponder responder;
  ASSERT_TRUE(RunSessionOf(recording, prepared, presenter, responder).completed);
  EXPECT_EQ(presenter.screens, (std::vector<std::string>{"Instructions: Which one is more blurred?",
                                                         "Part 1 of 2: The near cards.", "Part 2 of 2: The far cards.",
                                                         "Thank you"}));
}

// On the real clock as a window is (so a late flip is a dropped frame): every trial's third flip comes late, four
// frame periods after the one before (more than the runner's 1.5), and the window is closed at the third trial's
// fourth flip - after its late one, before it is answered.
class LateFlipPresenter : public FakePresenter {
 public:
  using FakePresenter::FakePresenter;
  bool RealTime() const override { return true; }
  double FrameS() const override { return 0.02; }
  bool Closed() const override { return closed_; }
  void ShowStimulus(const StimulusFrame& frame) override {
    FakePresenter::ShowStimulus(frame);
    index_ = frame.index;
  }
  int late_flips = 0;

 protected:
  double DoFlip(double wake_s) override {
    if (index_ == 2) {
      Wait(3 * FrameS());
      ++late_flips;
    }
    if (trials_shown.size() == 3 && index_ == 3) closed_ = true;
    index_ = -1;  // a text screen's flips are no trial's
    return FakePresenter::DoFlip(wake_s);
  }

 private:
  int index_ = -1;
  bool closed_ = false;
};

// What run says of dropped frames is what the record holds: the quit trial's late flip was seen but, unanswered, its
// frames are not recorded, so it is in no count (it was in run's, which said 3 where frames.csv has 2).
TEST(Runner, DroppedFramesAreTheRecordsCountNotTheQuitTrials) {
  const std::filesystem::path db = std::filesystem::temp_directory_path() /
                                   ("blurcue-runner-test-dropped-" + std::to_string(::getpid()) + ".sqlite");
  std::filesystem::remove(db);
  const procedure::PreparedSession prepared = Prepare(GridProtocol({{"factors", {{"edge", {2, 4, 6, 8}}}}}));
  RunResult result;
  LateFlipPresenter presenter(prepared);
  {
    Recording recording = Recording::Open(db);
    AnsweringResponder responder;
    result = RunSessionOf(recording, prepared, presenter, responder);
  }
  EXPECT_FALSE(result.completed);
  EXPECT_EQ(result.answered_now, 2);
  EXPECT_EQ(presenter.late_flips, 3);  // two answered trials' and the quit one's
  EXPECT_EQ(result.dropped_frames, 2);
  // The record, read apart from the runner: one dropped flip in each answered trial, at its third frame.
  store::Database record(db, store::OpenMode::kReadOnly);
  EXPECT_EQ(record.QueryInt64("SELECT count(*) FROM frames WHERE dropped = 1 AND frame_index = 2"), 2);
  EXPECT_EQ(record.QueryInt64("SELECT count(*) FROM frames WHERE dropped = 1"), 2);
  std::filesystem::remove(db);
}

}  // namespace
}  // namespace blurcue::session
