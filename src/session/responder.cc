#include "session/responder.h"

#include <algorithm>

#include "procedure/trial_logic.h"

namespace blurcue::session {

using protocol::Task;
using render::InputEvent;

std::vector<InputEvent> KeyResponder::Poll(double /*now_s*/) { return context_.TakeEvents(); }

ObserverResponder::ObserverResponder(const procedure::ObserverParams& params, uint64_t seed, const protocol::Protocol& protocol,
                                     const stimulus::Presentation& presentation, const KeyMap& keys,
                                     Responder* window)
    : params_(params), seed_(seed), protocol_(protocol), presentation_(presentation), keys_(keys), window_(window) {}

std::vector<InputEvent> ObserverResponder::Poll(double now_s) {
  std::vector<InputEvent> events = window_ ? window_->Poll(now_s) : std::vector<InputEvent>{};
  while (!scripted_.empty() && scripted_.front().time_s <= now_s + 1e-9) {
    events.push_back(scripted_.front());
    scripted_.pop_front();
  }
  return events;
}

double ObserverResponder::NextPressS() const {
  return scripted_.empty() ? std::numeric_limits<double>::infinity() : scripted_.front().time_s;
}

// A text screen: Return after a moment.
void ObserverResponder::ScreenShown(double now_s) { Script("Return", now_s + 0.6); }

// The observer's key presses for a trial whose stimulus appeared at `onset_s` (ObserverPresses, as a plan).
void ObserverResponder::StimulusShown(const protocol::Trial& trial, const stimulus::TrialScene& scene,
                                      double onset_s) {
  const std::vector<procedure::KeyPress> presses = procedure::ObserverPresses(params_, seed_, protocol_, trial, scene, presentation_);
  if (protocol::TraitsOf(trial.task).answer != protocol::TaskAnswer::kLevel) {
    // A moving stimulus is watched to its end before the answer (task 1 is one answer per run); intervals too.
    for (const procedure::KeyPress& press : presses)
      Script(keys_.Key(press.action, trial.task),
             onset_s + procedure::StimulusEndS(protocol::TimingOf(protocol_, trial), scene) + press.after_ms / 1000);
    return;
  }
  double t = onset_s;
  for (const procedure::KeyPress& press : presses) {
    t += press.after_ms / 1000;
    Script(keys_.Key(press.action, trial.task), t);
  }
}

void ObserverResponder::Script(const std::string& key, double time_s) {
  auto at = std::upper_bound(scripted_.begin(), scripted_.end(), time_s,
                             [](double t, const InputEvent& e) { return t < e.time_s; });
  scripted_.insert(at, {key, time_s});
}

}  // namespace blurcue::session
