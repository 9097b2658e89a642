#include "session/runner.h"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <deque>
#include <functional>
#include <map>
#include <optional>
#include <limits>
#include <thread>

#include <opencv2/core.hpp>

#include "core/atomic_file.h"
#include "core/error.h"
#include "core/image.h"
#include "core/typed.h"
#include "protocol/design.h"
#include "protocol/protocol.h"
#include "protocol/trials.h"
#include "render/frame_compositor.h"
#include "render/gl_context.h"
#include "session/adaptive.h"
#include "session/answer.h"
#include "session/observer.h"
#include "session/prepare.h"
#include "session/record_meta.h"
#include "session/screens.h"
#include "session/stimulus.h"
#include "session/trial_logic.h"
#include "store/record.h"

namespace blurcue::session {
namespace {

using protocol::Task;
using render::InputEvent;

// Where frames are shown and keys come from. A window runs on the real clock; headless runs on a simulated one
// that moves a frame at a time, or to the next scripted key press when that comes first, so a simulated observer's
// response times are exact and a session of minutes runs in seconds.
class Station {
 public:
  Station(render::GlContext& context, bool window, double sim_fps)
      : context_(context), window_(window), frame_s_(window ? 1.0 / (context.RefreshHz() > 0 ? context.RefreshHz()
                                                                                             : 60.0)
                                                            : 1.0 / sim_fps) {}

  bool window() const { return window_; }
  double frame_s() const { return frame_s_; }
  double Now() const { return window_ ? context_.Now() : clock_s_; }

  // Called after a flip at most every few seconds of real time (the record's lock heartbeat).
  void OnBeat(std::function<void()> beat) { beat_ = std::move(beat); }

  // Ends a frame and returns its flip time (when it reached the screen). Headless: the frame shows now, and the
  // clock moves on to the next frame or the next scripted key, whichever comes first.
  double Flip() {
    if (beat_) {
      // A participant may sit on a screen for minutes: the lock must still show a live writer.
      const auto now = std::chrono::steady_clock::now();
      if (now - last_beat_ > std::chrono::seconds(5)) {
        last_beat_ = now;
        beat_();
      }
    }
    if (!window_) {
      const double flip = clock_s_;
      const double next = clock_s_ + frame_s_;
      clock_s_ = scripted_.empty() ? next : std::max(clock_s_, std::min(next, scripted_.front().time_s));
      return flip;
    }
    context_.SwapBuffers();
    // Without vsync (e.g. under Xvfb) a swap returns at once: hold the refresh rate so a window shows what a
    // participant's monitor would.
    const double now = context_.Now();
    if (last_flip_s_ > 0 && now - last_flip_s_ < frame_s_)
      std::this_thread::sleep_for(std::chrono::duration<double>(frame_s_ - (now - last_flip_s_)));
    last_flip_s_ = context_.Now();
    return last_flip_s_;
  }

  // Keys pressed since the last call: the window's, and the scripted ones that are due.
  std::vector<InputEvent> Poll() {
    std::vector<InputEvent> events = context_.TakeEvents();
    while (!scripted_.empty() && scripted_.front().time_s <= Now() + 1e-9) {
      events.push_back(scripted_.front());
      scripted_.pop_front();
    }
    return events;
  }

  // A key the simulated observer will press at `time_s` (on this station's clock); kept in time order.
  void Script(const std::string& key, double time_s) {
    auto at = std::upper_bound(scripted_.begin(), scripted_.end(), time_s,
                               [](double t, const InputEvent& e) { return t < e.time_s; });
    scripted_.insert(at, {key, time_s});
  }
  void ClearScript() { scripted_.clear(); }
  // Headless, a trial's simulated clock starts at 0: its times (response times, flips) are then the same sums
  // whatever came before it, so a resumed session's are bit-identical to an uninterrupted one's. Carried over from
  // the session's start, the same durations added to a larger clock and taken off its onset again rounded
  // differently (a resumed session's clock had not run through the trials before it, nor the same screens).
  void StartTrial() {
    if (window_) return;
    clock_s_ = 0;
    scripted_.clear();
  }
  bool Closed() const { return context_.ShouldClose(); }
  void Wait(double seconds) {
    if (window_)
      std::this_thread::sleep_for(std::chrono::duration<double>(seconds));
    else
      clock_s_ += seconds;
  }

 private:
  render::GlContext& context_;
  bool window_;
  double frame_s_;
  double clock_s_ = 0, last_flip_s_ = 0;
  std::deque<InputEvent> scripted_;
  std::function<void()> beat_;
  std::chrono::steady_clock::time_point last_beat_ = std::chrono::steady_clock::now();
};

// Keys -> actions, as the protocol maps them: left / right / cant_tell, an odd-one-out interval or a rating point
// ("1".."n"), yes / no, or the adjustment's steps (the mouse steps and accepts too).
struct KeyMap {
  const protocol::Responses& r;
  bool odd_one_out;
  // The keys whose position names the answer ("1".."n"): a rating's points, an odd-one-out trial's intervals.
  const std::vector<std::string>* Numbered(Task task) const {
    return task == Task::kRating ? &r.rating : task == Task::kForcedChoice && odd_one_out ? &r.alternatives : nullptr;
  }
  std::string Action(const std::string& key, Task task) const {
    if (key == "Escape") return "pause";
    if (const auto* keys = Numbered(task)) {
      const auto it = std::find(keys->begin(), keys->end(), key);
      if (it != keys->end()) return std::to_string(it - keys->begin() + 1);
      if (task == Task::kForcedChoice && !r.cant_tell.empty() && key == r.cant_tell) return "cant_tell";
      return "";
    }
    if (task == Task::kForcedChoice) {
      if (key == r.left) return "left";
      if (key == r.right) return "right";
      if (key == r.cant_tell) return "cant_tell";
    } else if (task == Task::kYesNo) {
      if (key == r.yes) return "yes";
      if (key == r.no) return "no";
    } else if (task == Task::kAdjustment) {
      if (key == r.previous || key == "WheelDown") return "previous";
      if (key == r.next || key == "WheelUp") return "next";
      if (key == r.accept || key == "MouseLeft") return "accept";
    }
    return "";
  }
  std::string Key(const std::string& action, Task task) const {
    if (const auto* keys = Numbered(task); keys && !action.empty() && std::isdigit(unsigned(action[0])))
      return (*keys)[size_t(std::stoi(action) - 1)];
    if (action == "left") return r.left;
    if (action == "right") return r.right;
    if (action == "cant_tell") return r.cant_tell;
    if (action == "yes") return r.yes;
    if (action == "no") return r.no;
    if (action == "previous") return r.previous;
    if (action == "next") return r.next;
    return r.accept;
  }
  // Whether `choice` is an answer a session can record for `trial`: one of its task's actions as these keys give
  // them, an adjustment's level (as the record writes it), or no answer (a deadline passed).
  bool CanRecord(const std::string& choice, const protocol::Trial& trial) const {
    if (choice == store::kChoiceNone) return true;
    if (trial.task == Task::kAdjustment)
      return std::any_of(trial.adjust_levels.begin(), trial.adjust_levels.end(),
                         [&](double level) { return protocol::LevelText(level) == choice; });
    const bool cant_tell = trial.task == Task::kForcedChoice && !r.cant_tell.empty() && choice == "cant_tell";
    if (const auto* keys = Numbered(trial.task)) {
      for (size_t i = 0; i < keys->size(); ++i)
        if (choice == std::to_string(i + 1)) return true;
      return cant_tell;
    }
    if (trial.task == Task::kForcedChoice) return choice == "left" || choice == "right" || cant_tell;
    if (trial.task == Task::kYesNo) return choice == "yes" || choice == "no";
    return false;
  }
  // An action that answers a trial (not a step of an adjustment, not the pause).
  static bool Answers(const std::string& action) {
    return action == "left" || action == "right" || action == "cant_tell" || action == "yes" || action == "no" ||
           (!action.empty() && std::isdigit(unsigned(action[0])));
  }
};

std::string Clock(double seconds) {
  const int s = std::max(0, int(std::lround(seconds)));
  char text[32];
  std::snprintf(text, sizeof text, "%d:%02d", s / 60, s % 60);
  return text;
}

enum class Outcome { kAnswered, kQuit };

class Runner {
 public:
  Runner(const RunOptions& options, const PreparedSession& prepared, render::GlContext& context,
         StimulusRenderer& renderer, std::optional<ObserverParams> observer)
      : options_(options), prepared_(prepared), protocol_(prepared.protocol), context_(context), renderer_(renderer),
        trials_(prepared.trials), scenes_(prepared.scenes), observer_(observer), seed_(prepared.seed),
        keys_{protocol_.responses, protocol_.layout == "odd_one_out"}, station_(context, !observer || options.window, options.sim_fps),
        screen_size_(protocol_.display.width_px, protocol_.display.height_px) {}

  // --capture: the trial's first frame as the swap shows it (read back from the window, or the frame composed
  // headless: the same pixels) and what it shows in screen terms (DescribeFrame), before the frame is flipped.
  void Capture(const protocol::Trial& trial, const TrialScene& scene, bool prompt, double cutoff) {
    cv::Mat image =
        station_.window() ? render::ReadWindow(context_.width_px(), context_.height_px()) : renderer_.Read();
    // Headless the prompt is not drawn into a window: put its band where the window shows it.
    const int band = prepared_.presentation.prompt_band_px;
    if (prompt && !station_.window() && band > 0 && band <= image.rows)
      PromptBand(image.cols, band, protocol_.responses.prompt).copyTo(image.rowRange(image.rows - band, image.rows));
    char name[32];
    std::snprintf(name, sizeof name, "trial-%04d", trial.index + 1);
    Json frame = DescribeFrame(prepared_.scene ? &*prepared_.scene : nullptr, scene, prepared_.presentation,
                               renderer_.View(), renderer_.Shown(), cutoff);
    frame["protocol"] = protocol_.name;
    frame["participant"] = options_.participant;
    frame["trial_index"] = trial.index;
    frame["block"] = trial.block;
    frame["practice"] = trial.practice;
    frame["prompt"] = prompt ? Json(protocol_.responses.prompt) : Json();
    if (scene.content == "picture")
      frame["real_picture"]["photo"] = protocol_.content.real_photos.empty()
                                           ? protocol_.scene.ShownPhoto().string()
                                           : protocol::RealPhotoFor(protocol_.content, scene.distance_m).string();
    // Intervals show one object at a time at the left object's place: which side's object the first interval shows
    // (its "side" below is the slot it is drawn in).
    if (scene.intervals > 0) frame["first_interval_shows"] = IntervalShowsRight(trial, scene, 0) ? "right" : "left";
    if (prompt) frame["prompt_rect_px"] = {0, image.rows - band, image.cols, band};
    WriteImage(options_.capture_dir / (std::string(name) + ".png"), image);
    WriteFileAtomically(options_.capture_dir / (std::string(name) + ".json"), frame.dump(1) + "\n");
  }

  // Shows `image` until one of `keys` is pressed and returns it ("" when the window is closed).
  std::string ShowUntil(const std::string& title, const cv::Mat& image, const std::vector<std::string>& keys) {
    context_.SetTitle(Title(title));
    std::optional<render::WindowImage> shown;  // uploaded once, blitted every frame
    if (station_.window()) shown.emplace(image);
    for (;;) {
      if (shown) shown->Present(context_.width_px(), context_.height_px());
      station_.Flip();
      if (station_.Closed()) return "";
      for (const InputEvent& e : station_.Poll())
        if (std::find(keys.begin(), keys.end(), e.key) != keys.end()) return e.key;
    }
  }

  // A text screen until Return, Space or a click (a simulated observer presses Return after a moment). Escape
  // on it pauses like anywhere else. Returns false when the participant quits.
  bool ShowScreen(const std::string& title, const std::string& body, const std::string& footer) {
    const cv::Mat image = TextScreen(screen_size_, title, body, footer);
    if (observer_) station_.Script("Return", station_.Now() + 0.6);
    for (;;) {
      const std::string key = ShowUntil(title, image, {"Return", "Space", "MouseLeft", "Escape"});
      if (key.empty()) return false;
      if (key != "Escape") return true;
      if (!Pause()) return false;
    }
  }

  // A screen shown for a fixed time (feedback, fixation): in a window its frames, headless the simulated clock's time.
  void ShowFor(const cv::Mat& image, double seconds) {
    if (station_.window()) {
      const render::WindowImage shown(image);
      const double until = station_.Now() + seconds;
      while (station_.Now() < until && !station_.Closed()) {
        shown.Present(context_.width_px(), context_.height_px());
        station_.Flip();
      }
    } else {
      station_.Wait(seconds);
    }
  }

  // Escape: asks whether to quit. Q quits (every answer so far is already saved), Return goes on.
  bool Pause() {
    const cv::Mat image = TextScreen(screen_size_, "Paused",
                                     "Every answer so far is saved. Press Q to quit (the session can be continued "
                                     "later with --resume), or Return to go on.",
                                     "Q: quit    Return: go on");
    const std::string key = ShowUntil("Paused", image, {"Q", "Return", "Space"});
    return !key.empty() && key != "Q";
  }

  // The window's title names what is on screen (the experimenter's view; tests wait for it).
  std::string Title(const std::string& what) const { return "blurcue - " + protocol_.name + " - " + what; }
  std::string TrialTitle(const protocol::Trial& trial) const {
    return Title("trial " + std::to_string(trial.index + 1) + " of " + std::to_string(trials_.size()));
  }

  // The simulated observer's key presses for a trial whose stimulus appeared at `onset` (ObserverPresses, as a plan).
  void ScriptObserver(const protocol::Trial& trial, const TrialScene& scene, double onset) {
    const std::vector<KeyPress> presses = ObserverPresses(*observer_, seed_, protocol_, trial, scene, prepared_.presentation);
    if (trial.task != Task::kAdjustment) {
      // A moving stimulus is watched to its end before the answer (task 1 is one answer per run); intervals too.
      for (const KeyPress& press : presses)
        station_.Script(keys_.Key(press.action, trial.task), onset + StimulusEndS(protocol_, scene) + press.after_ms / 1000);
      return;
    }
    double t = onset;
    for (const KeyPress& press : presses) {
      t += press.after_ms / 1000;
      station_.Script(keys_.Key(press.action, trial.task), t);
    }
  }

  // Shows one trial until it is answered; fills the response and the frames.
  Outcome RunTrial(const protocol::Trial& trial, const TrialScene& scene, store::Response* response,
                   std::vector<store::FrameRecord>* frames) {
    station_.StartTrial();
    // Whatever the trial's frames need from disk or a resampling, now, not in its first frame.
    renderer_.Prepare(scene.intervals > 0 ? IntervalScene(scene, IntervalShowsRight(trial, scene, 0)) : scene);
    // Inter-trial interval: the grey field.
    if (protocol_.timing.inter_trial_ms > 0) {
      if (station_.window()) {
        Blank().Present(context_.width_px(), context_.height_px());
        station_.Flip();
      }
      station_.Wait(protocol_.timing.inter_trial_ms / 1000);
    }
    // A fixation mark before the stimulus, where the participant should look.
    if (protocol_.timing.fixation_ms > 0) ShowFor(FixationScreen(screen_size_), protocol_.timing.fixation_ms / 1000);
    station_.ClearScript();
    // Keys pressed before the stimulus (during the interval) answer nothing: drop them. Escape still pauses.
    for (const InputEvent& e : station_.Poll())
      if (e.key == "Escape" && !Pause()) return Outcome::kQuit;
    double onset = -1;    // the first frame's flip: response times and motion run from it
    double paused_s = 0;  // time spent on the pause screen: neither motion nor response time
    int level = trial.start_index;
    const int levels = static_cast<int>(trial.adjust_levels.size());
    Json steps = Json::array();
    const double stimulus_s = protocol_.timing.stimulus_ms / 1000;
    double last_flip = -1;
    int composed_level = -2;  // none yet (-1 is the level of a trial without levels)
    // Intervals (2IFC, odd one out): each interval's object for interval_ms, grey for isi_ms between them, then grey
    // until the answer.
    const int n = scene.intervals;
    const double interval_s = protocol_.timing.interval_ms / 1000, isi_s = protocol_.timing.isi_ms / 1000;
    std::vector<TrialScene> intervals;
    for (int k = 0; k < n; ++k) intervals.push_back(IntervalScene(scene, IntervalShowsRight(trial, scene, k)));
    // With responses.after_motion keys count (and the prompt shows) only once the motion or the intervals are over.
    const double answer_from_s = protocol_.responses.after_motion ? StimulusEndS(protocol_, scene) : 0;
    int composed_interval = -1;
    for (int frame = 0;; ++frame) {
      const double t = onset < 0 ? 0 : station_.Now() - onset - paused_s;
      // The interval on screen (-1 between and after them).
      const int k = n == 0 || t >= n * interval_s + (n - 1) * isi_s ? -1 : int(t / (interval_s + isi_s));
      const int on = k >= 0 && t - k * (interval_s + isi_s) < interval_s ? k : -1;
      const bool shown = n > 0 ? on >= 0 : stimulus_s <= 0 || t < stimulus_s;
      if (n > 0) {
        if (shown && composed_interval != on) renderer_.Compose(intervals[size_t(on)], 0, 0);
        composed_interval = on;
      } else if (shown && (composed_level != level || scene.MotionS() > 0)) {
        // A still stimulus is composed once (and again when the adjusted level changes); a moving one every frame.
        renderer_.Compose(scene, t, levels > 0 ? trial.adjust_levels[size_t(level)] : 0);
        composed_level = level;
      }
      // The prompt shows while an answer is taken.
      const bool prompt = prepared_.presentation.prompt_band_px > 0 && t >= answer_from_s;
      if (station_.window()) {
        if (shown)
          renderer_.Present(context_.width_px(), context_.height_px());
        else
          Blank().Present(context_.width_px(), context_.height_px());
        if (prompt) Prompt().PresentAt(0, context_.height_px() - prepared_.presentation.prompt_band_px, context_.height_px());
      }
      if (frame == 0 && !options_.capture_dir.empty())
        Capture(trial, n > 0 ? intervals[0] : scene, prompt, levels > 0 ? trial.adjust_levels[size_t(level)] : 0);
      const double flip = station_.Flip();
      if (onset < 0) {
        onset = flip;
        context_.SetTitle(TrialTitle(trial));
        if (observer_) ScriptObserver(trial, scene, onset);
      }
      const bool dropped = station_.window() && last_flip >= 0 && flip - last_flip > 1.5 * station_.frame_s();
      store::FrameRecord shown_frame{frame, flip - onset, dropped, {}, {}, {}};
      if (shown) {
        // What this frame showed, as Compose drew it (a still stimulus is composed once and shown unchanged).
        const auto& objects = renderer_.Shown();
        if (objects[0])
          (n > 0 && IntervalShowsRight(trial, scene, on) ? shown_frame.r_right_px : shown_frame.r_left_px) =
              objects[0]->r_px;
        if (objects[1]) shown_frame.r_right_px = objects[1]->r_px;
        for (const auto& o : objects)
          if (o && !shown_frame.y_mm) shown_frame.y_mm = o->object.center_board_mm[1];
      }
      frames->push_back(shown_frame);
      dropped_frames_ += dropped;
      last_flip = flip;
      if (station_.Closed()) return Outcome::kQuit;
      // A deadline: no answer this long after onset is recorded as "none", without a response time.
      if (protocol_.timing.deadline_ms > 0 && trial.task != Task::kAdjustment &&
          (station_.Now() - onset - paused_s) * 1000 >= protocol_.timing.deadline_ms) {
        response->choice = store::kChoiceNone;
        response->rt_ms = std::numeric_limits<double>::quiet_NaN();
        return Outcome::kAnswered;
      }
      for (const InputEvent& e : station_.Poll()) {
        if (e.time_s < onset) continue;  // pressed before the stimulus was on screen
        const std::string action = keys_.Action(e.key, trial.task);
        const double t_ms = (e.time_s - onset - paused_s) * 1000;
        if (action != "pause" && t_ms < answer_from_s * 1000) continue;  // before the motion ended
        if (action == "pause") {
          const double paused_at = station_.Now();
          if (!Pause()) return Outcome::kQuit;
          paused_s += station_.Now() - paused_at;
          context_.SetTitle(TrialTitle(trial));
          last_flip = -1;  // the gap is the pause, not a dropped frame
        } else if (KeyMap::Answers(action)) {
          response->choice = action;
          response->rt_ms = t_ms;
          return Outcome::kAnswered;
        } else if ((action == "previous" || action == "next") && levels > 0) {
          level = StepLevel(level, action, levels);
          steps.push_back({{"level", trial.adjust_levels[size_t(level)]}, {"t_ms", std::round(t_ms * 10) / 10}});
        } else if (action == "accept" && levels > 0) {
          response->choice = protocol::LevelText(trial.adjust_levels[size_t(level)]);
          response->rt_ms = t_ms;
          response->adjustment_json = steps.dump();
          return Outcome::kAnswered;
        }
      }
    }
  }

  RunResult Run(store::Record& record, const store::SessionStart& start) {
    RunResult result;
    result.session_id = start.session_id;
    result.seed = seed_;
    result.trial_count = static_cast<int64_t>(trials_.size());
    result.answered_before = start.first_unanswered_trial;
    station_.OnBeat([&] { record.Heartbeat(start.session_id); });
    const auto wall_start = std::chrono::steady_clock::now();
    const bool tty = isatty(2);
    auto progress = [&](int64_t done) {
      // A terminal gets one line rewritten after every answer; a log gets about ten lines.
      if (!tty && done % std::max<int64_t>(1, result.trial_count / 10) != 0 && done != result.trial_count)
        return;
      const double elapsed =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
      const int64_t now = done - result.answered_before;
      const double left = now > 0 ? elapsed / double(now) * double(result.trial_count - done) : 0;
      std::fprintf(stderr, "%strial %lld of %lld  elapsed %s  remaining ~%s%s", tty ? "\r" : "",
                   static_cast<long long>(done), static_cast<long long>(result.trial_count), Clock(elapsed).c_str(),
                   Clock(left).c_str(), tty ? "   " : "\n");
    };

    const std::string welcome = start.resumed && start.first_unanswered_trial > 0 ? "Welcome back" : "Instructions";
    if (!ShowScreen(welcome, protocol_.instructions, "Press Return to start")) return result;
    // What the answers so far decided (procedures' levels and stop rules, practice runs, breaks): rebuilt by
    // replaying the record's answers through the same decisions a live session takes, so a resumed session
    // continues exactly where it was. Each replayed decision must be the one the record says was taken.
    SessionLogic logic(prepared_);
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
        const bool recorded_skip = it->second.choice == store::kChoiceSkipped;
        const Json why = logic.SkipReason(t);
        if (recorded_skip && why.is_null())
          throw cannot(i, "the record skips it, but the answers before it show it (its procedure had not stopped, "
                          "its practice criterion was not met)");
        if (!recorded_skip && !why.is_null())
          throw cannot(i, "the record shows it, but the answers before it skip it (" +
                              why["skipped"].get<std::string>() + ")");
        if (recorded_skip) continue;
        if (!keys_.CanRecord(it->second.choice, t))
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
        logic.Answer(t, scene, level, it->second.choice);
      }
    }
    std::string shown_block;
    bool shown_practice = false;  // the trial before was practice (the next main one says the practice is over)
    for (int64_t i = start.first_unanswered_trial; i < result.trial_count; ++i) {
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
        if (!text.empty() && !ShowScreen(trial.practice ? "Practice" : "Part: " + trial.block, text,
                                         "Press Return to go on"))
          return result;
        shown_block = part;
      }
      shown_practice = trial.practice;
      // Not shown, recorded as skipped: a procedure ended by its stop rule, a practice run after the run that met
      // its block's criterion.
      if (const Json why = logic.SkipReason(trial); !why.is_null()) {
        store::Response skipped;
        skipped.choice = store::kChoiceSkipped;
        skipped.rt_ms = std::numeric_limits<double>::quiet_NaN();
        skipped.shown_json = why.dump();
        record.RecordResponse(start.session_id, i, skipped);
        ++result.skipped_now;
        result.skipped_by_criterion_now += trial.practice && why.value("skipped", "").rfind("criterion", 0) == 0;
        progress(i + 1);
        continue;
      }
      // A procedure's trial shows the level its answers so far give, on its test side.
      double level = 0;
      const TrialScene scene = logic.SceneOf(trial, &level);
      store::Response response;
      std::vector<store::FrameRecord> frames;
      if (RunTrial(trial, scene, &response, &frames) == Outcome::kQuit) break;
      // Scored, and taken by the procedure and the practice run (their state is only in memory; a resume replays
      // the record): a staircase's reversals before the answer and QUEST+'s posterior after it are recorded with it.
      const Scored scored = logic.Answer(trial, scene, level, response.choice);
      const std::optional<bool> right = scored.correct;
      const bool correct = right.value_or(false);
      response.correct = right;
      if (trial.cell >= 0) {
        Json shown = TrialVariables(trial, scene, prepared_.presentation);
        shown["correct"] = correct ? 1 : 0;
        if (scored.reversals_before) shown["reversals"] = *scored.reversals_before;
        if (scored.posterior) {
          shown["posterior_threshold"] = scored.posterior->first;
          shown["posterior_slope"] = scored.posterior->second;
        }
        response.shown_json = shown.dump();
        response.level = level;
        response.r_left_px = scene.r_left_px;
        response.r_right_px = scene.r_right_px;
      }
      record.RecordResponse(start.session_id, i, response, frames);  // committed before anything else happens
      // Feedback where an answer is right or wrong: procedure trials, odd one out, practice run to a criterion.
      if (right && protocol_.timing.feedback_ms > 0)
        ShowFor(TextScreen(screen_size_, response.choice == store::kChoiceNone ? "Too slow" : correct ? "Correct" : "Wrong", "",
                           ""),
                protocol_.timing.feedback_ms / 1000);
      ++result.answered_now;
      progress(i + 1);
      if (!trial.practice) ++main_answered;
      if (protocol_.break_every_trials > 0 && !trial.practice && main_answered % protocol_.break_every_trials == 0 &&
          i + 1 < result.trial_count &&
          !ShowScreen("Break", protocol_.break_text.empty() ? "Take a short break." : protocol_.break_text,
                      "Press Return to go on"))
        break;
    }
    if (tty) std::fprintf(stderr, "\n");
    result.completed = record.FirstUnansweredTrial(start.session_id) == result.trial_count;
    station_.OnBeat(nullptr);  // the session's lock is released below or by the Record
    if (result.completed) {
      record.FinishSession(start.session_id, store::SessionStatus::kCompleted);
      if (station_.window()) {
        render::WindowImage(TextScreen(screen_size_, "Thank you", "The session is complete.", ""))
            .Present(context_.width_px(), context_.height_px());
        station_.Flip();
        station_.Wait(0.5);
      }
    }
    result.dropped_frames = dropped_frames_;
    return result;
  }

 private:
  // The grey field between trials and after a timed stimulus (window only).
  const render::WindowImage& Blank() {
    if (!blank_) blank_ = std::make_unique<render::WindowImage>(TextScreen(screen_size_, "", "", ""));
    return *blank_;
  }

  // The response prompt's band (window only), made once.
  const render::WindowImage& Prompt() {
    if (!prompt_)
      prompt_ = std::make_unique<render::WindowImage>(
          PromptBand(context_.width_px(), prepared_.presentation.prompt_band_px, protocol_.responses.prompt));
    return *prompt_;
  }

  const RunOptions& options_;
  const PreparedSession& prepared_;
  const protocol::Protocol& protocol_;
  render::GlContext& context_;
  StimulusRenderer& renderer_;
  const std::vector<protocol::Trial>& trials_;
  const std::vector<TrialScene>& scenes_;
  std::optional<ObserverParams> observer_;
  uint64_t seed_;
  KeyMap keys_;
  Station station_;
  cv::Size screen_size_;
  std::unique_ptr<render::WindowImage> blank_, prompt_;
  int64_t dropped_frames_ = 0;
};

}  // namespace

// The participant information a session records: --info values checked against the protocol's fields, the
// required ones that are missing asked for in the terminal (stdin a terminal) or refused; a resumed session's
// recorded information, which --info may repeat but not change.
Json CollectInfo(const protocol::Protocol& p, const RunOptions& options, const store::GroupsSoFar& so_far) {
  auto field_of = [&](const std::string& key) -> const protocol::InfoField* {
    for (const auto& f : p.participant_info)
      if (f.key == key) return &f;
    return nullptr;
  };
  auto value_of = [](const protocol::InfoField& f, const std::string& text) {
    // Checked by CheckInfoValue before: a decimal number in the field's range.
    return f.type == "integer" ? Json(int64_t(*ParseDecimal(text)))
           : f.type == "number" ? Json(*ParseDecimal(text))
                                : Json(text);
  };
  auto describe = [](const protocol::InfoField& f) {
    if (f.type == "choice") {
      std::string list;
      for (const auto& c : f.choices) list += (list.empty() ? "" : " / ") + c;
      return list;
    }
    char range[64];
    std::snprintf(range, sizeof range, "%g-%g", f.min, f.max);
    return f.type == "text" ? std::string("text") : std::string(range);
  };
  std::string asked;
  for (const auto& f : p.participant_info) asked += (asked.empty() ? "" : ", ") + f.key;
  Json info = Json::object();
  for (const auto& [key, text] : options.info) {
    const protocol::InfoField* f = field_of(key);
    if (!f)
      throw Error(ErrorKind::kUsage, "--info " + Echo(key, false) + ": " + options.protocol_file.string() +
                                         (asked.empty() ? " asks for no participant information"
                                                        : " asks for " + asked + " (participant_info), not " +
                                                              Echo(key, false)));
    if (const std::string why = protocol::CheckInfoValue(*f, text); !why.empty())
      throw Error(ErrorKind::kUsage, "--info " + key + "=" + Echo(text, false) + ": " + why);
    info[key] = value_of(*f, text);
  }
  if (options.resume && so_far.unfinished) {
    const Json recorded = ParseJson(so_far.unfinished_info, options.db.string());
    for (const auto& [key, value] : info.items())
      if (!recorded.contains(key) || recorded[key] != value)
        throw InputError(options.db.string(), "--info " + key + ": the unfinished session recorded " +
                                                  (recorded.contains(key) ? recorded[key].dump() : "nothing") +
                                                  ", got " + value.dump() + "; a session keeps what it recorded");
    return recorded;
  }
  for (const auto& f : p.participant_info) {
    if (info.contains(f.key) || !f.required) continue;
    if (!isatty(0))
      throw Error(ErrorKind::kUsage, "--info: " + options.protocol_file.string() + " asks for " + f.key + " (" +
                                         describe(f) + "); give --info " + f.key + "=VALUE");
    for (int tries = 0;; ++tries) {
      std::fprintf(stderr, "%s (%s): ", f.prompt.empty() ? f.key.c_str() : f.prompt.c_str(), describe(f).c_str());
      std::string line;
      int c;
      while ((c = std::getchar()) != EOF && c != '\n') line += char(c);
      if (c == EOF && line.empty()) throw Error(ErrorKind::kUsage, "--info: no answer for " + f.key);
      const std::string why = protocol::CheckInfoValue(f, line);
      if (why.empty()) {
        info[f.key] = value_of(f, line);
        break;
      }
      std::fprintf(stderr, "  %s %s\n", f.key.c_str(), why.c_str());
      if (tries >= 4) throw Error(ErrorKind::kUsage, "--info " + f.key + ": " + why);
    }
  }
  return info;
}

RunResult RunSession(const RunOptions& options) {
  protocol::CheckParticipantId(options.participant);
  std::optional<ObserverParams> observer;
  if (!options.observer.empty()) observer = ParseObserver(options.observer);
  if (options.sim_fps <= 0) throw Error(ErrorKind::kUsage, "--sim-fps must be > 0");

  // --resume continues what a record holds: a missing record holds nothing (and is not created).
  if (options.resume && !std::filesystem::exists(options.db))
    throw InputError(options.db.string(), "--resume: no such record, so there is no session to continue; leave out "
                                          "--resume to start one");
  // Groups and participant information: what the record already says (a resumed session keeps its group and its
  // information), then the group a new session gets and the information it is given.
  const protocol::Protocol head = protocol::LoadProtocol(options.protocol_file);
  store::GroupsSoFar so_far;
  if (head.groups || !head.participant_info.empty())
    so_far = store::PeekGroups(options.db, head.name, options.participant);
  const std::string group = !head.groups       ? ""
                            : so_far.unfinished ? so_far.unfinished_group
                                                : protocol::AssignGroup(head, options.participant, so_far.sessions);
  const Json info = CollectInfo(head, options, so_far);
  // A new session's number decides its default seed (the record decides the number again when it starts the
  // session); a resumed one runs with the seed it recorded.
  const store::SessionsSoFar sessions = store::PeekSessions(options.db, head.name, options.participant);
  const int64_t session_number = options.resume && sessions.unfinished ? sessions.unfinished_number : sessions.next_number;
  const uint64_t session_seed = options.seed                                  ? *options.seed
                                : options.resume && sessions.unfinished ? sessions.unfinished_seed
                                : DefaultSessionSeed(head.name, options.participant, session_number);
  // Everything checked before the first trial is what `blurcue validate` checks: the same function.
  const PreparedSession prepared =
      PrepareSession(options.protocol_file, options.participant, session_seed, options.display_profile, group);
  const protocol::Protocol& protocol = prepared.protocol;
  if (observer) CheckObserverCanAnswer(*observer, protocol);
  // A new session's balanced group is decided again in the transaction that starts it: a station starting at the
  // same moment may take the group peeked above. So each group it may get is prepared (and checked) now.
  const bool balanced = protocol.groups && protocol.groups->assign == "balanced" && !options.resume;
  std::map<std::string, PreparedSession> other_groups;
  if (balanced)
    for (const std::string& name : protocol.groups->names)
      if (name != prepared.group) {
        PreparedSession other = prepared;
        PrepareParticipant(&other, options.participant, session_seed, name);
        other_groups.emplace(name, std::move(other));
      }
  const std::string& protocol_text = prepared.protocol_text;
  const uint64_t seed = prepared.seed;
  const std::optional<calib::SceneCalib>& scene = prepared.scene;
  // The trial list as saved: one record per trial, with its planned radii.
  auto trial_records = [&](const PreparedSession& s) {
    std::vector<store::TrialRecord> records;
    for (const protocol::Trial& trial : s.trials) {
      store::TrialRecord r;
      r.index = trial.index;
      r.block = protocol::BlockIndex(protocol, trial);
      const TrialScene& planned = s.scenes[size_t(trial.index)];
      r.factors_json = TrialVariables(trial, planned, s.presentation).dump();
      r.left_json = trial.left.dump();
      r.right_json = trial.right.dump();
      r.block_name = trial.block;
      r.task = protocol::ToString(trial.task);
      r.practice = trial.practice;
      r.swapped = trial.swapped;
      r.cell = protocol::CellLevels(protocol, trial);
      if (planned.content != "picture" && trial.task != protocol::Task::kAdjustment) {
        r.r_left_px = planned.r_left_px;
        if (!planned.left_only) r.r_right_px = planned.r_right_px;
        r.r_scene_px = planned.r_scene_px;
      }
      records.push_back(std::move(r));
    }
    return records;
  };

  std::unique_ptr<render::GlContext> context;
  const bool window = !observer || options.window;
  if (window) {
    render::WindowOptions w;
    w.width_px = protocol.display.width_px;
    w.height_px = protocol.display.height_px;
    w.fullscreen = protocol.display.fullscreen;
    w.monitor = protocol.display.monitor;
    w.title = "blurcue - " + protocol.name;  // then Runner::Title names what is on screen
    try {
      context = render::GlContext::CreateWindow(w);
    } catch (const Error& e) {
      // Only run knows the way round a missing display: a simulated observer needs no window.
      if (e.kind() != ErrorKind::kUsage || observer) throw;
      throw Error(ErrorKind::kUsage, std::string(e.what()) + "; to try the protocol without a participant, run it "
                                                              "with --observer sim");
    }
  } else {
    context = render::GlContext::CreateOffscreen();
  }
  // The record states what the window shows: a window of another size than the protocol's display (a window
  // manager's choice, a full screen of another mode) would show every radius at another scale.
  if (window && (context->width_px() != protocol.display.width_px || context->height_px() != protocol.display.height_px))
    throw InputError(options.protocol_file.string() + ": /display",
                     "the window opened at " + std::to_string(context->width_px()) + " x " +
                         std::to_string(context->height_px()) + " px, the protocol's display says " +
                         std::to_string(protocol.display.width_px) + " x " + std::to_string(protocol.display.height_px) +
                         " px; set width_px/height_px to the screen's (full screen: the monitor's mode)");
  StimulusRenderer renderer(protocol, scene, prepared.images, prepared.presentation);
  // The capture folder is made before the session starts: a path that cannot hold captures stops here.
  if (!options.capture_dir.empty()) {
    std::error_code ec;
    std::filesystem::create_directories(options.capture_dir, ec);
    if (ec || !std::filesystem::is_directory(options.capture_dir))
      throw InputError(options.capture_dir.string(), "--capture: cannot make a folder here (" +
                                                         (ec ? ec.message() : std::string("not a folder")) + ")");
  }

  store::Record record = store::Record::Open(options.db);
  store::SessionMeta meta;
  char display[256];
  std::snprintf(display, sizeof display, "%s %dx%d%s; %s%s", window ? "window" : "headless",
                window ? context->width_px() : protocol.display.width_px,
                window ? context->height_px() : protocol.display.height_px,
                window && context->RefreshHz() > 0 ? ("@" + std::to_string(int(context->RefreshHz()))).c_str() : "",
                context->Describe().c_str(), observer ? ("; observer " + ToString(*observer)).c_str() : "");
  meta.display = display;
  meta.display_profile = display::ToJson(prepared.display).dump();
  meta.group = prepared.group;
  if (balanced)
    meta.assign_group = [&](const std::map<std::string, int64_t>& sessions) {
      return protocol::AssignGroup(protocol, options.participant, sessions);
    };
  meta.participant_info = info.dump();
  meta.simulated = observer.has_value();
  meta.observer_params = observer ? ToString(*observer) : "";
  meta.window = window;
  meta.protocol_version = protocol.version;
  meta.design = DesignRecord(protocol);
  meta.seed_given = options.seed.has_value();
  if (!options.seed && !options.resume) meta.seed_for_number = session_number;
  if (!options.again && !options.resume) {
    // Running a participant through a study they finished is usually a typo in the id: say so.
    const std::vector<int64_t> done = record.CompletedSessions(protocol.name, options.participant);
    if (!done.empty())
      throw InputError(options.db.string(), "participant " + options.participant + " already completed " +
                                                protocol.name + " (session " + std::to_string(done.front()) +
                                                "); check the id, or add --again for another session");
  }
  const store::SessionStart start = record.StartOrResumeSession(protocol.name, options.participant, protocol_text,
                                                                seed, meta, options.resume);
  // The group the record gave (another than the one peeked when a station started at the same moment).
  const auto given = other_groups.find(start.group);
  const PreparedSession& chosen = given == other_groups.end() ? prepared : given->second;
  // A new session saves its list; a resumed one must show the same trials in the same order.
  if (start.trial_count == 0)
    record.SaveTrialList(start.session_id, trial_records(chosen));
  else
    record.CheckTrialList(start.session_id, trial_records(chosen));
  Runner runner(options, chosen, *context, renderer, observer);
  RunResult result = runner.Run(record, start);
  result.session_number = start.session_number;
  return result;
}

}  // namespace blurcue::session
