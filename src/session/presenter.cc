#include "session/presenter.h"

namespace blurcue::session {

double Presenter::Flip(double wake_s) {
  if (beat_) {
    // A participant may sit on a screen for minutes: the lock must still show a live writer.
    const auto now = std::chrono::steady_clock::now();
    if (now - last_beat_ > std::chrono::seconds(5)) {
      last_beat_ = now;
      beat_();
    }
  }
  return DoFlip(wake_s);
}

}  // namespace blurcue::session
