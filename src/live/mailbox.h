#pragma once
// The hand-over between a frame reader and the loop that shows frames, as a camera's driver makes it: one slot. A
// frame posted while the slot still holds one that was never taken replaces it, and that one is counted dropped:
// frames are never queued, so the loop always works on the newest frame and latency cannot pile up.
#include <chrono>
#include <condition_variable>
#include <mutex>
#include <string>

#include <opencv2/core.hpp>

namespace blurcue::live {

using Clock = std::chrono::steady_clock;

// A delivered frame: its number on the input (a camera's count, a video's index), its time on the input's clock, and
// when it arrived (was posted).
struct LiveFrame {
  cv::Mat image;  // 8-bit BGR
  int index = 0;
  double time_s = 0;
  Clock::time_point arrival;
};

class FrameMailbox {
 public:
  // Puts `frame` in the slot; `frame` gets the slot's old buffers back (a reader reuses them: no allocation a frame).
  // True when it replaced a frame that was never taken (counted dropped). Ignored once closed.
  bool Post(LiveFrame& frame);
  // No more frames will come: `why` says why in words ("the video ended after 60 frames"); `failed` for an error
  // (a damaged frame, a camera that stopped). A frame still in the slot can be taken.
  void Close(const std::string& why, bool failed);

  enum class Got { kFrame, kTimeout, kClosed };
  // Waits up to `timeout` for a frame: kFrame with it swapped into `frame` (whose buffers go back to the slot),
  // kTimeout, or kClosed once closed and empty.
  Got Take(LiveFrame& frame, std::chrono::milliseconds timeout);

  int dropped() const;           // frames replaced before they were taken, so far
  std::string why_closed() const;
  bool failed() const;

 private:
  mutable std::mutex mutex_;
  std::condition_variable ready_;
  LiveFrame slot_;
  bool full_ = false, closed_ = false, failed_ = false;
  int dropped_ = 0;
  std::string why_;
};

}  // namespace blurcue::live
