#pragma once
// Where a session's frames go and whose clock its times are on. The trial loop (SessionLoop) sees only this: a
// window on the real clock, headless on a simulated one that moves a frame at a time, either one capturing each
// trial's first frame, or a test's fake that records what it was asked to show.
#include <array>
#include <chrono>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <utility>

#include "protocol/trials.h"
#include "scene/frame.h"
#include "stimulus/stimulus.h"
#include "stimulus/video_take.h"

namespace blurcue::session {

// One frame of a trial as the loop asks for it.
struct StimulusFrame {
  const protocol::Trial* trial = nullptr;
  const stimulus::TrialScene* scene = nullptr;  // what the trial's first frame shows (an intervals trial's first)
  int index = 0;       // the frame's number in the trial, from 0
  bool shown = false;  // the stimulus, else the grey field (between intervals, after a timed stimulus)
  std::string_view prompt;  // the response prompt shown in its band under it (the block's); empty: no band
  double cutoff = 0;   // the adjustment level shown (picture)
};

class Presenter {
 public:
  virtual ~Presenter() = default;

  // The real clock (a window): frames can be dropped, and a wait is a wait. Else a simulated clock.
  virtual bool RealTime() const = 0;
  // Seconds per frame: the display's refresh, or the headless frame rate.
  virtual double FrameS() const = 0;
  virtual double Now() const = 0;
  // The participant closed the window.
  virtual bool Closed() const = 0;
  // Lets `seconds` pass on the clock.
  virtual void Wait(double seconds) = 0;
  // A trial begins; returns whether the clock started again from 0 (times scheduled before are then void).
  virtual bool StartTrial() = 0;
  // Names what is on screen (a window's title; the experimenter's view).
  virtual void SetTitle(const std::string& title) = 0;

  // What a trial's frames need, done before its first frame (StimulusRenderer::Prepare).
  virtual void Prepare(const stimulus::TrialScene& scene) = 0;
  // Composes the stimulus t_s after onset at the adjustment `level` (StimulusRenderer::Compose).
  virtual void Compose(const stimulus::TrialScene& scene, double t_s, double level) = 0;
  // What the last composed frame showed of a pair (radii in photo px); empty sides for pictures and wiped balls.
  virtual const std::array<std::optional<scene::BlurredObject>, 2>& Shown() const = 0;
  // A study on video: the take's frame the last composed frame showed (StimulusRenderer::ShownTake); empty otherwise.
  virtual std::optional<stimulus::TakeFrameShown> ShownTake() const { return std::nullopt; }
  // Puts a trial's frame on the screen for the next flip.
  virtual void ShowStimulus(const StimulusFrame& frame) = 0;

  // A text screen (title, body wrapped, footer) from now on, until another; DrawScreen puts it up for each flip.
  virtual void ShowText(const std::string& title, const std::string& body, const std::string& footer) = 0;
  virtual void DrawScreen() = 0;
  // A screen for a fixed time: a text screen (feedback), the fixation mark, the grey field (one flip, then a wait).
  virtual void ShowTextFor(const std::string& title, double seconds) = 0;
  virtual void ShowFixationFor(double seconds) = 0;
  virtual void ShowBlankFor(double seconds) = 0;
  // The session's last screen ("Thank you"), shown briefly where someone is looking.
  virtual void ShowLast(const std::string& title, const std::string& body) = 0;

  // Ends a frame; returns its flip time (when it reached the screen). A simulated clock moves on to the next frame
  // or to `wake_s` (the responder's next press), whichever comes first.
  double Flip(double wake_s = std::numeric_limits<double>::infinity());
  // Called after a flip at most every few seconds of real time (the record's lock heartbeat); null: none.
  virtual void OnBeat(std::function<void()> beat) { beat_ = std::move(beat); }

 protected:
  virtual double DoFlip(double wake_s) = 0;

 private:
  std::function<void()> beat_;
  std::chrono::steady_clock::time_point last_beat_ = std::chrono::steady_clock::now();
};

}  // namespace blurcue::session
