#include "session/trial_loop.h"


#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/interrupt.h"
#include "session/keys.h"
#include "procedure/trial_logic.h"

namespace blurcue::session {
namespace {

using protocol::Task;
using ActionKind = procedure::Action::Kind;
using render::InputEvent;
using stimulus::IntervalScene;
using stimulus::IntervalShowsRight;
using stimulus::TrialScene;

enum class Outcome { kAnswered, kQuit };

class Runner {
 public:
  Runner(const LoopOptions& options, const procedure::PreparedSession& prepared, Presenter& presenter, Responder& responder)
      : options_(options), prepared_(prepared), protocol_(prepared.protocol), presenter_(presenter),
        responder_(responder), trials_(prepared.trials), scenes_(prepared.scenes),
        keys_{protocol_.responses, protocol_.layout == protocol::Layout::kOddOneOut} {}

  // Shows a text screen until one of `keys` is pressed and returns it ("" when the window is closed).
  std::string ShowUntil(const std::string& title, const std::string& body, const std::string& footer,
                        const std::vector<std::string>& keys) {
    presenter_.SetTitle(Title(title));
    presenter_.ShowText(title, body, footer);
    for (;;) {
      presenter_.DrawScreen();
      presenter_.Flip(responder_.NextPressS());
      if (presenter_.Closed() || Interrupted()) return "";
      for (const InputEvent& e : responder_.Poll(presenter_.Now()))
        if (std::find(keys.begin(), keys.end(), e.key) != keys.end()) return e.key;
    }
  }

  // A text screen until Return, Space or a click (a simulated observer presses Return after a moment). Escape
  // on it pauses like anywhere else. Returns false when the participant quits.
  bool ShowScreen(const std::string& title, const std::string& body, const std::string& footer) {
    responder_.ScreenShown(presenter_.Now());
    for (;;) {
      const std::string key = ShowUntil(title, body, footer, {"Return", "Space", "MouseLeft", "Escape"});
      if (key.empty()) return false;
      if (key != "Escape") return true;
      if (!Pause()) return false;
    }
  }

  // Escape: asks whether to quit. Q quits (every answer so far is already saved), Return goes on.
  bool Pause() {
    const std::string key = ShowUntil("Paused",
                                      "Every answer so far is saved. Press Q to quit (the session can be continued "
                                      "later with --resume), or Return to go on.",
                                      "Q: quit    Return: go on", {"Q", "Return", "Space"});
    return !key.empty() && key != "Q";
  }

  // The window's title names what is on screen (the experimenter's view; tests wait for it).
  std::string Title(const std::string& what) const { return "blurcue - " + protocol_.name + " - " + what; }
  std::string TrialTitle(const protocol::Trial& trial) const {
    return Title("trial " + std::to_string(trial.index + 1) + " of " + std::to_string(trials_.size()));
  }

  // Shows one trial until it is answered; fills the response and the frames.
  Outcome RunTrial(const protocol::Trial& trial, const TrialScene& scene, Response* response,
                   std::vector<FrameRecord>* frames) {
    // Times planned on a clock that started again are void.
    if (presenter_.StartTrial()) responder_.Forget();
    const protocol::Timing& timing = protocol::TimingOf(protocol_, trial);  // its block's
    const std::string& prompt_text = protocol::PromptOf(protocol_, trial);
    // Whatever the trial's frames need from disk or a resampling, now, not in its first frame.
    presenter_.Prepare(scene.intervals > 0 ? IntervalScene(scene, IntervalShowsRight(trial, scene, 0)) : scene);
    // Inter-trial interval: the grey field.
    if (timing.inter_trial_ms > 0) presenter_.ShowBlankFor(timing.inter_trial_ms / 1000);
    // A fixation mark before the stimulus, where the participant should look.
    if (timing.fixation_ms > 0) presenter_.ShowFixationFor(timing.fixation_ms / 1000);
    responder_.Forget();
    // Keys pressed before the stimulus (during the interval) answer nothing: drop them. Escape still pauses.
    for (const InputEvent& e : responder_.Poll(presenter_.Now()))
      if (e.key == "Escape" && !Pause()) return Outcome::kQuit;
    double onset = -1;    // the first frame's flip: response times and motion run from it
    double paused_s = 0;  // time spent on the pause screen: neither motion nor response time
    int level = trial.start_index;
    const int levels = static_cast<int>(trial.adjust_levels.size());
    Json steps = Json::array();
    const double stimulus_s = timing.stimulus_ms / 1000;
    double last_flip = -1;
    int composed_level = -2;  // none yet (-1 is the level of a trial without levels)
    // Intervals (2IFC, odd one out): each interval's object for interval_ms, grey for isi_ms between them, then grey
    // until the answer.
    const int n = scene.intervals;
    const double interval_s = timing.interval_ms / 1000, isi_s = timing.isi_ms / 1000;
    std::vector<TrialScene> intervals;
    for (int k = 0; k < n; ++k) intervals.push_back(IntervalScene(scene, IntervalShowsRight(trial, scene, k)));
    // With responses.after_motion keys count (and the prompt shows) only once the motion or the intervals are over.
    const double answer_from_s = protocol_.responses.after_motion ? procedure::StimulusEndS(timing, scene) : 0;
    // Where keys wait for the motion's end, the window's title says when they count (" - answer"): a person sees it
    // and a test waits for it rather than for a guessed time.
    bool answer_titled = answer_from_s <= 0;
    int composed_interval = -1;
    for (int frame = 0;; ++frame) {
      const double t = onset < 0 ? 0 : presenter_.Now() - onset - paused_s;
      // The interval on screen (-1 between and after them).
      const int k = n == 0 || t >= n * interval_s + (n - 1) * isi_s ? -1 : int(t / (interval_s + isi_s));
      const int on = k >= 0 && t - k * (interval_s + isi_s) < interval_s ? k : -1;
      const bool shown = n > 0 ? on >= 0 : stimulus_s <= 0 || t < stimulus_s;
      if (n > 0) {
        // An interval's object is still (composed once), but on video, where the take plays on under it.
        if (shown && (composed_interval != on || scene.video))
          presenter_.Compose(intervals[size_t(on)], scene.video ? t : 0, 0);
        composed_interval = on;
      } else if (shown && (composed_level != level || scene.MotionS() > 0 || scene.video)) {
        // A still stimulus is composed once (and again when the adjusted level changes); a moving one every frame.
        presenter_.Compose(scene, t, levels > 0 ? trial.adjust_levels[size_t(level)] : 0);
        composed_level = level;
      }
      // The prompt shows while an answer is taken.
      const bool prompt = prepared_.presentation.prompt_band_px > 0 && !prompt_text.empty() && t >= answer_from_s;
      presenter_.ShowStimulus({&trial, n > 0 ? &intervals[0] : &scene, frame, shown,
                               prompt ? std::string_view(prompt_text) : std::string_view(),
                               levels > 0 ? trial.adjust_levels[size_t(level)] : 0});
      const double flip = presenter_.Flip(responder_.NextPressS());
      if (onset < 0) {
        onset = flip;
        presenter_.SetTitle(TrialTitle(trial));
        responder_.StimulusShown(trial, scene, onset);
      }
      if (!answer_titled && flip - onset - paused_s >= answer_from_s) {
        presenter_.SetTitle(TrialTitle(trial) + " - answer");
        answer_titled = true;
      }
      const bool dropped = presenter_.RealTime() && last_flip >= 0 && flip - last_flip > 1.5 * presenter_.FrameS();
      FrameRecord shown_frame;
      shown_frame.frame_index = frame;
      shown_frame.flip_time_s = flip - onset;
      shown_frame.dropped = dropped;
      if (shown) {
        // What this frame showed, as Compose drew it (a still stimulus is composed once and shown unchanged).
        const auto& objects = presenter_.Shown();
        for (size_t i = 0; i < 2; ++i) {
          if (!objects[i]) continue;
          const scene::BlurredObject& o = *objects[i];
          // An interval shows one side's object in the left slot.
          const bool right = i == 1 || (n > 0 && IntervalShowsRight(trial, scene, on));
          FrameSide& side = shown_frame.sides[protocol::Index(right ? protocol::Side::kRight : protocol::Side::kLeft)];
          side.r_px = o.r_px;
          side.floor_sigma_px = o.floor_sigma_px;
          side.motion_x_px = o.motion_px[0];
          side.motion_y_px = o.motion_px[1];
          if (!shown_frame.y_mm) shown_frame.y_mm = o.object.center_board_mm[1];
        }
        if (const auto take = presenter_.ShownTake()) {
          shown_frame.take_frame = take->take_frame;
          shown_frame.take_status = take->status;
        }
      }
      frames->push_back(shown_frame);
      last_flip = flip;
      if (presenter_.Closed() || Interrupted()) return Outcome::kQuit;
      // A deadline: no answer this long after onset is recorded as none, without a response time.
      if (timing.deadline_ms > 0 && protocol::TraitsOf(trial.task).deadline &&
          (presenter_.Now() - onset - paused_s) * 1000 >= timing.deadline_ms) {
        response->choice = Choice::Of(Choice::Kind::kNone);
        response->rt_ms = std::numeric_limits<double>::quiet_NaN();
        return Outcome::kAnswered;
      }
      for (const InputEvent& e : responder_.Poll(presenter_.Now())) {
        if (e.time_s < onset) continue;  // pressed before the stimulus was on screen
        const procedure::Action action = keys_.ActionOf(e.key, trial.task);
        const double t_ms = (e.time_s - onset - paused_s) * 1000;
        if (action.kind != ActionKind::kPause && t_ms < answer_from_s * 1000) continue;  // before the motion ended
        if (action.kind == ActionKind::kPause) {
          const double paused_at = presenter_.Now();
          if (!Pause()) return Outcome::kQuit;
          paused_s += presenter_.Now() - paused_at;
          presenter_.SetTitle(TrialTitle(trial) + (answer_from_s > 0 && answer_titled ? " - answer" : ""));
          last_flip = -1;  // the gap is the pause, not a dropped frame
        } else if (action.kind == ActionKind::kAnswer) {
          response->choice = action.choice;
          response->rt_ms = t_ms;
          return Outcome::kAnswered;
        } else if ((action.kind == ActionKind::kPrevious || action.kind == ActionKind::kNext) && levels > 0) {
          level = procedure::StepLevel(level, action.kind, levels);
          steps.push_back({{"level", trial.adjust_levels[size_t(level)]}, {"t_ms", std::round(t_ms * 10) / 10}});
        } else if (action.kind == ActionKind::kAccept && levels > 0) {
          response->choice = Choice::Level(trial.adjust_levels[size_t(level)]);
          response->rt_ms = t_ms;
          response->adjustment_json = steps.dump();
          return Outcome::kAnswered;
        }
      }
    }
  }

  RunResult Run(Recording& record, const SessionStart& start) {
    RunResult result;
    result.session_id = start.session_id;
    result.seed = prepared_.seed;
    result.trial_count = static_cast<int64_t>(trials_.size());
    result.answered_before = start.first_unanswered_trial;
    presenter_.OnBeat([&] { record.Heartbeat(start.session_id); });
    const auto wall_start = std::chrono::steady_clock::now();
    auto progress = [&](int64_t done) {
      if (!options_.progress) return;
      const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
      const int64_t now = done - result.answered_before;
      const double left = now > 0 ? elapsed / double(now) * double(result.trial_count - done) : 0;
      options_.progress({done, result.trial_count, elapsed, left});
    };

    const std::string welcome = start.resumed && start.first_unanswered_trial > 0 ? "Welcome back" : "Instructions";
    if (!ShowScreen(welcome, protocol_.instructions, "Press Return to start")) return result;
    // What the answers so far decided (procedures' levels and stop rules, practice runs, breaks): rebuilt by
    // replaying the record's answers through the same decisions a live session takes, so a resumed session
    // continues exactly where it was. Each replayed decision must be the one the record says was taken.
    procedure::SessionLogic logic(prepared_);
    // Breaks come every N answered main trials, counted over the whole session (a resumed one included); trials
    // skipped by a stop rule or a met criterion are no answers.
    int64_t main_answered = 0;
    if (start.first_unanswered_trial > 0) {
      const auto answered = record.AnsweredTrials(start.session_id);
      auto cannot = [&](int64_t i, const std::string& why) {
        return InputError(options_.db.string(), "session " + std::to_string(start.session_id) + " trial " +
                                                    std::to_string(i) + ": " + why + "; it cannot be resumed");
      };
      for (int64_t i = 0; i < start.first_unanswered_trial; ++i) {
        const protocol::Trial& t = trials_[size_t(i)];
        const auto it = answered.find(i);
        if (it == answered.end()) throw cannot(i, "the record has no answer for it but has answers after it");
        const std::optional<Choice> recorded = keys_.Parse(it->second.choice, t);
        const bool recorded_skip = recorded && recorded->kind == Choice::Kind::kSkipped;
        const std::optional<procedure::Skip> why = logic.SkipReason(t);
        if (recorded_skip && !why)
          throw cannot(i, "the record skips it, but the answers before it show it (its procedure had not stopped, "
                          "its practice criterion was not met)");
        if (!recorded_skip && why)
          throw cannot(i, "the record shows it, but the answers before it skip it (" + why->why + ")");
        if (recorded_skip) continue;
        if (!recorded || !keys_.CanRecord(*recorded, t))
          throw cannot(i, "the record's answer '" + it->second.choice + "' is none this trial can have");
        main_answered += !t.practice;
        double level = 0;
        const TrialScene scene = logic.SceneOf(t, &level);
        if (t.cell >= 0) {
          const Json shown = ParseJson(it->second.shown_json, options_.db.string() + " session " +
                                                                  std::to_string(start.session_id) + " trial " +
                                                                  std::to_string(i));
          if (!shown.is_object() || !shown.contains("level") || !shown["level"].is_number() ||
              std::abs(shown["level"].get<double>() - level) > 1e-9 * std::max(1.0, std::abs(level)))
            throw cannot(i, "the record's procedure level " +
                                (shown.is_object() && shown.contains("level") ? shown["level"].dump()
                                                                              : std::string("(none)")) +
                                " is not the " + std::to_string(level) + " its answers give");
        }
        logic.Answer(t, scene, level, *recorded);
      }
    }
    std::string shown_block;
    bool shown_practice = false;  // the trial before was practice (the next main one says the practice is over)
    for (int64_t i = start.first_unanswered_trial; i < result.trial_count && !Interrupted(); ++i) {
      if (options_.stop_after >= 0 && result.answered_now >= options_.stop_after) break;
      const protocol::Trial& trial = trials_[size_t(i)];
      // Instructions when the part changes: practice, then each block.
      // A practice block is a part of its own; practice drawn from a main block is the part "practice".
      const protocol::Block* block = protocol::BlockOf(protocol_, trial);
      const bool practice_block = block && block->practice;
      const std::string part = trial.practice && !practice_block ? std::string("practice") : trial.block;
      if (part != shown_block) {
        std::string text;
        if (part == "practice" && !practice_block) {
          text = protocol_.practice.instructions;
        } else {
          if (block) text = block->instructions;
          if (text.empty() && shown_practice && !trial.practice) text = "The practice is over; the study starts now.";
        }
        // The block's title or "Part n of N", never its name (which may give the condition away).
        if (!text.empty() && !ShowScreen(protocol::BlockTitle(protocol_, trials_, size_t(i)), text,
                                         "Press Return to go on"))
          return result;
        shown_block = part;
      }
      shown_practice = trial.practice;
      // Not shown, recorded as skipped: a procedure ended by its stop rule, a practice run after the run that met
      // its block's criterion.
      if (const std::optional<procedure::Skip> why = logic.SkipReason(trial)) {
        Response skipped;
        skipped.choice = Choice::Of(Choice::Kind::kSkipped);
        skipped.rt_ms = std::numeric_limits<double>::quiet_NaN();
        skipped.shown_json = SkippedVariables(*why);
        record.RecordResponse(start.session_id, i, skipped);
        ++result.skipped_now;
        result.skipped_by_criterion_now += trial.practice && why->criterion;
        progress(i + 1);
        continue;
      }
      // A procedure's trial shows the level its answers so far give, on its test side.
      double level = 0;
      const TrialScene scene = logic.SceneOf(trial, &level);
      Response response;
      std::vector<FrameRecord> frames;
      if (RunTrial(trial, scene, &response, &frames) == Outcome::kQuit) break;
      // Scored, and taken by the procedure and the practice run (their state is only in memory; a resume replays
      // the record): a staircase's reversals before the answer and QUEST+'s posterior after it are recorded with it.
      const procedure::Scored scored = logic.Answer(trial, scene, level, response.choice);
      const std::optional<bool> right = scored.correct;
      const bool correct = right.value_or(false);
      response.correct = right;
      if (trial.cell >= 0) {
        response.shown_json = ShownVariables(trial, scene, prepared_.presentation, scored);
        response.level = level;
        for (size_t side = 0; side < 2; ++side) response.r_px[side] = scene.sides[side].r_px;
      }
      record.RecordResponse(start.session_id, i, response, frames);  // committed before anything else happens
      // Feedback where an answer is right or wrong: procedure trials, odd one out, practice run to a criterion.
      if (const double feedback_ms = protocol::TimingOf(protocol_, trial).feedback_ms; right && feedback_ms > 0)
        presenter_.ShowTextFor(response.choice.kind == Choice::Kind::kNone ? "Too slow" : correct ? "Correct" : "Wrong",
                               feedback_ms / 1000);
      ++result.answered_now;
      progress(i + 1);
      if (!trial.practice) ++main_answered;
      if (protocol_.break_every_trials > 0 && !trial.practice && main_answered % protocol_.break_every_trials == 0 &&
          i + 1 < result.trial_count &&
          !ShowScreen("Break", protocol_.break_text.empty() ? "Take a short break." : protocol_.break_text,
                      "Press Return to go on"))
        break;
    }
    result.completed = record.FirstUnansweredTrial(start.session_id) == result.trial_count;
    presenter_.OnBeat(nullptr);  // the session's lock is released below or by the Record
    if (result.completed) {
      record.CompleteSession(start.session_id);
      presenter_.ShowLast("Thank you", "The session is complete.");
    }
    return result;
  }


 private:
  const LoopOptions& options_;
  const procedure::PreparedSession& prepared_;
  const protocol::Protocol& protocol_;
  Presenter& presenter_;
  Responder& responder_;
  const std::vector<protocol::Trial>& trials_;
  const std::vector<TrialScene>& scenes_;
  KeyMap keys_;
};

}  // namespace

RunResult RunTrials(const LoopOptions& options, const procedure::PreparedSession& prepared, Presenter& presenter,
                    Responder& responder, Recording& recording, const SessionStart& start) {
  Runner runner(options, prepared, presenter, responder);
  // Ctrl-C or a kill while trials run stops the loop between trials (or on a text screen): what was answered is
  // committed already, and the session is left to --resume, as a quit with Escape leaves it. Before and after the
  // loop (preparing the trials, decoding a take) a signal ends the process as it always did.
  const InterruptScope interrupt;
  RunResult result = runner.Run(recording, start);
  result.interrupted = InterruptSignal();
  // However the run ended (a quit on a text screen too), the frames counted are the record's.
  result.dropped_frames = recording.DroppedFrames(start.session_id);
  return result;
}

}  // namespace blurcue::session
