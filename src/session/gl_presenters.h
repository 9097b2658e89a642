#pragma once
// The presenters over a GL context and the stimulus renderer: a window on the real clock, headless on a simulated
// one, and the capture of each trial's first frame around either.
#include <array>
#include <chrono>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>

#include <opencv2/core.hpp>

#include "render/frame_compositor.h"
#include "render/gl_context.h"
#include "procedure/prepare.h"
#include "session/presenter.h"
#include "session/stimulus_renderer.h"

namespace blurcue::session {

// What the window and headless presenters share: the renderer composes, the context names and closes.
class GlPresenter : public Presenter {
 public:
  GlPresenter(render::GlContext& context, StimulusRenderer& renderer) : context_(context), renderer_(renderer) {}
  bool Closed() const override { return context_.ShouldClose(); }
  void SetTitle(const std::string& title) override { context_.SetTitle(title); }
  void Prepare(const stimulus::TrialScene& scene) override { renderer_.Prepare(scene); }
  void Compose(const stimulus::TrialScene& scene, double t_s, double level) override {
    renderer_.Compose(scene, t_s, level);
  }
  const std::array<std::optional<scene::BlurredObject>, 2>& Shown() const override { return renderer_.Shown(); }
  std::optional<stimulus::TakeFrameShown> ShownTake() const override { return renderer_.ShownTake(); }
  // The calibration the last composed frame's objects were drawn with (a video's frame's; else the protocol's).
  const calib::SceneCalib* ShownScene() const { return renderer_.ShownScene(); }
  // Where the last composed frame showed the photo.
  scene::FrameView View() const { return renderer_.View(); }
  // The frame as the screen shows it now (8-bit BGR), with `prompt` in its band when not empty.
  virtual cv::Mat ReadFrame(std::string_view prompt) = 0;

 protected:
  render::GlContext& context_;
  StimulusRenderer& renderer_;
};

// A window on the real clock: every frame is drawn and swapped, held to the refresh rate when the swap does not wait
// for it (no vsync, e.g. under Xvfb).
class WindowPresenter : public GlPresenter {
 public:
  // `prompt_band_px` high at the bottom: the band each frame's prompt is shown in (Presentation::prompt_band_px).
  WindowPresenter(render::GlContext& context, StimulusRenderer& renderer, cv::Size screen, int prompt_band_px);
  bool RealTime() const override { return true; }
  double FrameS() const override { return frame_s_; }
  double Now() const override { return context_.Now(); }
  void Wait(double seconds) override;
  bool StartTrial() override { return false; }
  void ShowStimulus(const StimulusFrame& frame) override;
  void ShowText(const std::string& title, const std::string& body, const std::string& footer) override;
  void DrawScreen() override;
  void ShowTextFor(const std::string& title, double seconds) override;
  void ShowFixationFor(double seconds) override;
  void ShowBlankFor(double seconds) override;
  void ShowLast(const std::string& title, const std::string& body) override;
  cv::Mat ReadFrame(std::string_view prompt) override;

 protected:
  double DoFlip(double wake_s) override;

 private:
  void ShowFor(const cv::Mat& image, double seconds);
  // The grey field between trials and after a timed stimulus (made once), and the prompt's band.
  const render::WindowImage& Blank();
  const render::WindowImage& Prompt(std::string_view text);

  cv::Size screen_;
  int prompt_band_px_;
  std::string prompt_;  // what prompt_image_ says
  double frame_s_;
  double last_flip_s_ = 0;
  std::optional<render::WindowImage> screen_image_;  // the text screen up now: uploaded once, drawn every frame
  std::unique_ptr<render::WindowImage> blank_, prompt_image_;
};

// Headless on a simulated clock that moves a frame at a time, or to the responder's next press when that comes
// first, so a simulated observer's response times are exact and a session of minutes runs in seconds. Each trial's
// clock starts at 0: its times (response times, flips) are then the same sums whatever came before it, so a resumed
// session's are bit-identical to an uninterrupted one's.
class HeadlessPresenter : public GlPresenter {
 public:
  HeadlessPresenter(render::GlContext& context, StimulusRenderer& renderer, double fps, int prompt_band_px);
  bool RealTime() const override { return false; }
  double FrameS() const override { return frame_s_; }
  double Now() const override { return clock_s_; }
  void Wait(double seconds) override { clock_s_ += seconds; }
  bool StartTrial() override;
  void ShowStimulus(const StimulusFrame&) override {}
  void ShowText(const std::string&, const std::string&, const std::string&) override {}
  void DrawScreen() override {}
  void ShowTextFor(const std::string&, double seconds) override { Wait(seconds); }
  void ShowFixationFor(double seconds) override { Wait(seconds); }
  void ShowBlankFor(double seconds) override { Wait(seconds); }
  void ShowLast(const std::string&, const std::string&) override {}
  cv::Mat ReadFrame(std::string_view prompt) override;

 protected:
  double DoFlip(double wake_s) override;

 private:
  double frame_s_;
  int prompt_band_px_;
  double clock_s_ = 0;
};

// --capture: around a window or headless presenter, each trial's first frame as the screen shows it (trial-NNNN.png)
// and what it shows in screen terms (trial-NNNN.json, DescribeFrame), written before the frame is flipped.
class CapturingPresenter : public Presenter {
 public:
  CapturingPresenter(GlPresenter& inner, const procedure::PreparedSession& prepared, std::filesystem::path dir,
                     std::string participant)
      : inner_(inner), prepared_(prepared), protocol_(prepared.protocol), dir_(std::move(dir)),
        participant_(std::move(participant)) {}
  bool RealTime() const override { return inner_.RealTime(); }
  double FrameS() const override { return inner_.FrameS(); }
  double Now() const override { return inner_.Now(); }
  bool Closed() const override { return inner_.Closed(); }
  void Wait(double seconds) override { inner_.Wait(seconds); }
  bool StartTrial() override { return inner_.StartTrial(); }
  void SetTitle(const std::string& title) override { inner_.SetTitle(title); }
  void Prepare(const stimulus::TrialScene& scene) override { inner_.Prepare(scene); }
  void Compose(const stimulus::TrialScene& scene, double t_s, double level) override {
    inner_.Compose(scene, t_s, level);
  }
  const std::array<std::optional<scene::BlurredObject>, 2>& Shown() const override { return inner_.Shown(); }
  std::optional<stimulus::TakeFrameShown> ShownTake() const override { return inner_.ShownTake(); }
  void ShowStimulus(const StimulusFrame& frame) override;
  void ShowText(const std::string& title, const std::string& body, const std::string& footer) override {
    inner_.ShowText(title, body, footer);
  }
  void DrawScreen() override { inner_.DrawScreen(); }
  void ShowTextFor(const std::string& title, double seconds) override { inner_.ShowTextFor(title, seconds); }
  void ShowFixationFor(double seconds) override { inner_.ShowFixationFor(seconds); }
  void ShowBlankFor(double seconds) override { inner_.ShowBlankFor(seconds); }
  void ShowLast(const std::string& title, const std::string& body) override { inner_.ShowLast(title, body); }
  // The heartbeat goes with the inner presenter's flips, its own screens' included.
  void OnBeat(std::function<void()> beat) override { inner_.OnBeat(std::move(beat)); }

 protected:
  // The inner presenter's flip (and its heartbeat).
  double DoFlip(double wake_s) override;

 private:
  void Capture(const protocol::Trial& trial, const stimulus::TrialScene& scene, std::string_view prompt,
               double cutoff);

  GlPresenter& inner_;
  const procedure::PreparedSession& prepared_;
  const protocol::Protocol& protocol_;
  std::filesystem::path dir_;
  std::string participant_;
};

}  // namespace blurcue::session
