#include "live/mailbox.h"

#include <utility>

namespace blurcue::live {

bool FrameMailbox::Post(LiveFrame& frame) {
  bool replaced = false;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (closed_) return false;
    replaced = full_;
    if (replaced) ++dropped_;
    // Swapped, not copied: the slot's old image (a dropped frame's, or one the taker handed back) becomes the
    // reader's buffer for its next frame, so a frame of the same size is decoded into memory it already has.
    std::swap(slot_, frame);
    full_ = true;
  }
  ready_.notify_one();
  return replaced;
}

void FrameMailbox::Close(const std::string& why, bool failed) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (closed_) return;
    closed_ = true;
    failed_ = failed;
    why_ = why;
  }
  ready_.notify_all();
}

FrameMailbox::Got FrameMailbox::Take(LiveFrame& frame, std::chrono::milliseconds timeout) {
  std::unique_lock<std::mutex> lock(mutex_);
  if (!ready_.wait_for(lock, timeout, [this] { return full_ || closed_; })) return Got::kTimeout;
  if (!full_) return Got::kClosed;
  std::swap(slot_, frame);
  full_ = false;
  return Got::kFrame;
}

int FrameMailbox::dropped() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return dropped_;
}

std::string FrameMailbox::why_closed() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return why_;
}

bool FrameMailbox::failed() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return failed_;
}

}  // namespace blurcue::live
