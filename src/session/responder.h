#pragma once
// Where a session's answers come from: a person's keys (and mouse) at the window, or the simulated observer, who
// presses the same keys at planned times on the presenter's clock (in a window, a person's keys still count: Escape
// pauses). The trial loop sees only this.
#include <cstdint>
#include <deque>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "protocol/protocol.h"
#include "protocol/trials.h"
#include "render/gl_context.h"
#include "session/keys.h"
#include "procedure/observer.h"
#include "stimulus/stimulus.h"

namespace blurcue::session {

class Responder {
 public:
  virtual ~Responder() = default;
  // The keys pressed since the last call, and those planned for up to `now_s` (the presenter's clock), in order.
  virtual std::vector<render::InputEvent> Poll(double now_s) = 0;
  // When the next planned press is due (infinity: none; a person's keys are not known ahead).
  virtual double NextPressS() const { return std::numeric_limits<double>::infinity(); }
  // A text screen that waits for Return went up at `now_s`.
  virtual void ScreenShown(double /*now_s*/) {}
  // `trial`'s stimulus (`scene`) reached the screen at `onset_s`.
  virtual void StimulusShown(const protocol::Trial& /*trial*/, const stimulus::TrialScene& /*scene*/,
                             double /*onset_s*/) {}
  // Forgets the presses planned so far (the clock started again; keys before a stimulus answer nothing).
  virtual void Forget() {}
};

// A person at the window: the keys and clicks its context reports.
class KeyResponder : public Responder {
 public:
  explicit KeyResponder(render::GlContext& context) : context_(context) {}
  std::vector<render::InputEvent> Poll(double now_s) override;

 private:
  render::GlContext& context_;
};

// The simulated observer (ObserverPresses): Return on a text screen after 0.6 s, a trial's answer after its stimulus
// has run its course, an adjustment's steps from onset - as the keys `keys` maps its actions to. `window`: a person's
// keys at the window count too (null headless).
class ObserverResponder : public Responder {
 public:
  ObserverResponder(const procedure::ObserverParams& params, uint64_t seed, const protocol::Protocol& protocol,
                    const stimulus::Presentation& presentation, const KeyMap& keys, Responder* window);
  std::vector<render::InputEvent> Poll(double now_s) override;
  double NextPressS() const override;
  void ScreenShown(double now_s) override;
  void StimulusShown(const protocol::Trial& trial, const stimulus::TrialScene& scene, double onset_s) override;
  void Forget() override { scripted_.clear(); }

 private:
  // A key the observer will press at `time_s`; kept in time order.
  void Script(const std::string& key, double time_s);

  procedure::ObserverParams params_;
  uint64_t seed_;
  const protocol::Protocol& protocol_;
  const stimulus::Presentation& presentation_;
  KeyMap keys_;
  Responder* window_;
  std::deque<render::InputEvent> scripted_;
};

}  // namespace blurcue::session
