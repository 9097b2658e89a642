#include "session/gl_presenters.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <thread>

#include "core/atomic_file.h"
#include "core/image.h"
#include "session/screens.h"
#include "stimulus/stimulus.h"

namespace blurcue::session {

WindowPresenter::WindowPresenter(render::GlContext& context, StimulusRenderer& renderer, cv::Size screen,
                                 int prompt_band_px)
    : GlPresenter(context, renderer), screen_(screen), prompt_band_px_(prompt_band_px),
      frame_s_(1.0 / (context.RefreshHz() > 0 ? context.RefreshHz() : 60.0)) {}

void WindowPresenter::Wait(double seconds) { std::this_thread::sleep_for(std::chrono::duration<double>(seconds)); }

double WindowPresenter::DoFlip(double /*wake_s*/) {
  context_.SwapBuffers();
  // Without vsync (e.g. under Xvfb) a swap returns at once: hold the refresh rate so a window shows what a
  // participant's monitor would.
  const double now = context_.Now();
  if (last_flip_s_ > 0 && now - last_flip_s_ < frame_s_)
    std::this_thread::sleep_for(std::chrono::duration<double>(frame_s_ - (now - last_flip_s_)));
  last_flip_s_ = context_.Now();
  return last_flip_s_;
}

void WindowPresenter::ShowStimulus(const StimulusFrame& frame) {
  const int w = context_.width_px(), h = context_.height_px();
  if (frame.shown)
    renderer_.Present(w, h);
  else
    Blank().Present(w, h);
  if (!frame.prompt.empty()) Prompt(frame.prompt).PresentAt(0, h - prompt_band_px_, h);
}

void WindowPresenter::ShowText(const std::string& title, const std::string& body, const std::string& footer) {
  screen_image_.emplace(TextScreen(screen_, title, body, footer));
}

void WindowPresenter::DrawScreen() {
  if (screen_image_) screen_image_->Present(context_.width_px(), context_.height_px());
}

void WindowPresenter::ShowFor(const cv::Mat& image, double seconds) {
  const render::WindowImage shown(image);
  const double until = Now() + seconds;
  while (Now() < until && !Closed()) {
    shown.Present(context_.width_px(), context_.height_px());
    Flip();
  }
}

void WindowPresenter::ShowTextFor(const std::string& title, double seconds) {
  ShowFor(TextScreen(screen_, title, "", ""), seconds);
}

void WindowPresenter::ShowFixationFor(double seconds) { ShowFor(FixationScreen(screen_), seconds); }

void WindowPresenter::ShowBlankFor(double seconds) {
  Blank().Present(context_.width_px(), context_.height_px());
  Flip();
  Wait(seconds);
}

void WindowPresenter::ShowLast(const std::string& title, const std::string& body) {
  render::WindowImage(TextScreen(screen_, title, body, "")).Present(context_.width_px(), context_.height_px());
  Flip();
  Wait(0.5);
}

cv::Mat WindowPresenter::ReadFrame(std::string_view /*prompt*/) {
  return render::ReadWindow(context_.width_px(), context_.height_px());
}

const render::WindowImage& WindowPresenter::Blank() {
  if (!blank_) blank_ = std::make_unique<render::WindowImage>(TextScreen(screen_, "", "", ""));
  return *blank_;
}

// Made again only when a block's prompt differs from the last one shown.
const render::WindowImage& WindowPresenter::Prompt(std::string_view text) {
  if (!prompt_image_ || prompt_ != text) {
    prompt_ = std::string(text);
    prompt_image_ = std::make_unique<render::WindowImage>(PromptBand(context_.width_px(), prompt_band_px_, prompt_));
  }
  return *prompt_image_;
}

HeadlessPresenter::HeadlessPresenter(render::GlContext& context, StimulusRenderer& renderer, double fps,
                                     int prompt_band_px)
    : GlPresenter(context, renderer), frame_s_(1.0 / fps), prompt_band_px_(prompt_band_px) {}

bool HeadlessPresenter::StartTrial() {
  // Carried over from the session's start, the same durations added to a larger clock and taken off its onset again
  // would round differently (a resumed session's clock had not run through the trials before it, nor the same
  // screens).
  clock_s_ = 0;
  return true;
}

double HeadlessPresenter::DoFlip(double wake_s) {
  // The frame shows now, and the clock moves on to the next frame or the next planned key, whichever comes first.
  const double flip = clock_s_;
  const double next = clock_s_ + frame_s_;
  clock_s_ = std::max(clock_s_, std::min(next, wake_s));
  return flip;
}

cv::Mat HeadlessPresenter::ReadFrame(std::string_view prompt) {
  cv::Mat image = renderer_.Read();
  // Headless the prompt is not drawn into a window: put its band where the window shows it.
  const int band = prompt_band_px_;
  if (!prompt.empty() && band > 0 && band <= image.rows)
    PromptBand(image.cols, band, std::string(prompt)).copyTo(image.rowRange(image.rows - band, image.rows));
  return image;
}

void CapturingPresenter::ShowStimulus(const StimulusFrame& frame) {
  inner_.ShowStimulus(frame);
  if (frame.index == 0) Capture(*frame.trial, *frame.scene, frame.prompt, frame.cutoff);
}

double CapturingPresenter::DoFlip(double wake_s) { return inner_.Flip(wake_s); }


// The trial's first frame as the swap shows it (read back from the window, or the frame composed headless: the same
// pixels) and what it shows in screen terms.
void CapturingPresenter::Capture(const protocol::Trial& trial, const stimulus::TrialScene& scene,
                                 std::string_view prompt, double cutoff) {
  const cv::Mat image = inner_.ReadFrame(prompt);
  const int band = prepared_.presentation.prompt_band_px;
  char name[32];
  std::snprintf(name, sizeof name, "trial-%04d", trial.index + 1);
  Json frame = stimulus::DescribeFrame(inner_.ShownScene(), scene, prepared_.presentation, inner_.View(),
                                       inner_.Shown(), cutoff);
  if (const auto take = inner_.ShownTake()) {
    frame["take_frame"] = take->take_frame;
    frame["take_status"] = take->status;
  }
  frame["protocol"] = protocol_.name;
  frame["participant"] = participant_;
  frame["trial_index"] = trial.index;
  frame["block"] = trial.block;
  frame["practice"] = trial.practice;
  frame["prompt"] = !prompt.empty() ? Json(std::string(prompt)) : Json();
  if (scene.content == protocol::ContentType::kPicture)
    frame["real_picture"]["photo"] = protocol_.content.real_photos.empty()
                                         ? protocol_.scene.ShownPhoto().string()
                                         : protocol::RealPhotoFor(protocol_.content, scene.distance_m).string();
  // Intervals show one object at a time at the left object's place: which side's object the first interval shows
  // (its "side" below is the slot it is drawn in).
  if (scene.intervals > 0)
    frame["first_interval_shows"] =
        ToString(stimulus::IntervalShowsRight(trial, scene, 0) ? protocol::Side::kRight : protocol::Side::kLeft);
  if (!prompt.empty()) frame["prompt_rect_px"] = {0, image.rows - band, image.cols, band};
  WriteImage(dir_ / (std::string(name) + ".png"), image);
  WriteFileAtomically(dir_ / (std::string(name) + ".json"), frame.dump(1) + "\n");
}

}  // namespace blurcue::session
