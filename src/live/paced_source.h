#pragma once
// INPUT as `blurcue live` reads it, on threads of its own: a camera (a V4L2 device through OpenCV's videoio) as it
// delivers frames, or a video file or image sequence played as a camera would deliver it - frame k posted at
// start + k / fps by a pacer, decoded up to kDecodeAhead frames ahead by a decoder, so that a frame whose decoding
// is slow for a moment still arrives on time - into a FrameMailbox (which drops, never queues, a frame the loop had
// no time for).
#include <deque>
#include <atomic>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "core/error.h"
#include "core/media.h"
#include "live/mailbox.h"
#include "track/frames.h"

namespace blurcue::live {

// The V4L2 device INPUT names: "/dev/videoN" or a whole number N (both /dev/videoN); empty for a video or a pattern.
std::string CameraDevice(const std::string& input);

// Frames a video or sequence is decoded ahead of its pace (8 frames of 1148 x 764: 21 MB): a camera has each frame
// whole when it hands it over, and a file's decoding, which a camera does not do, must not make frames late.
constexpr int kDecodeAhead = 8;
// The most a preloaded input may hold decoded in memory (--preload), MB of 10^6 bytes: 760 frames of 1148 x 764 BGR
// (25 s at 30 fps).
constexpr double kMaxPreloadMb = 2000;

class PacedSource {
 public:
  // `fps`: the pace of a video (0: its own rate, 30 when it states none) or of an image sequence (0: 30); a camera
  // keeps its own (`fps` must be 0). `max_frames`: the input ends after that many frames (0: no limit).
  // Throws Error(kInput) naming the device when no camera is there or videoio cannot open it, and as
  // track::FrameSource for a video or a sequence; Error(kUsage) for `fps` given with a camera or out of range.
  PacedSource(const std::string& input, double fps, int max_frames);
  // A camera read through `reader`, opened already, named `device` in what it says: the frames as the reader hands
  // them over, its first failed read the camera stopping (a test plays a short video as the camera).
  PacedSource(const std::string& device, std::unique_ptr<media::VideoReader> reader, int max_frames);
  ~PacedSource();
  PacedSource(const PacedSource&) = delete;
  PacedSource& operator=(const PacedSource&) = delete;

  bool is_camera() const { return !device_.empty(); }
  // Frames per second it delivers at (0 for a camera: its own rate, measured by the log).
  double fps() const { return fps_; }
  // Frames the video's header promises (0 for a sequence or a camera).
  int expected_frames() const;

  // A video or a sequence decoded whole before the clock starts (--preload): the frames are then delivered at their
  // pace from memory, as a camera hands over frames it has decoded itself, and no decoding competes with the drawing.
  // Returns the seconds the decoding took. `frame_size`: the size every frame has (camera.json's; a frame of another
  // size is refused when shown): with the frames INPUT holds - a video's header, a sequence's files counted - it
  // gives the memory they need before a frame is decoded. Throws Error(kUsage) naming INPUT when that is more than
  // `max_mb` MB - at once; while decoding, for a video whose header gives no count - or for a camera; a damaged
  // frame ends the preload, and the frames before it are played, then the error (as without it). `interrupt`, when
  // given and non-zero (a signal's number: Ctrl-C), ends the decoding at the next frame: the frames decoded so far
  // are held, and the input ends there.
  double Preload(cv::Size frame_size, double max_mb = kMaxPreloadMb, const std::atomic<int>* interrupt = nullptr);
  // Preload's refusal before decoding, alone (for a caller to refuse before it says it decodes); Preload calls it.
  void CheckPreloadFits(cv::Size frame_size, double max_mb = kMaxPreloadMb) const;
  // Frames held decoded by Preload (0: none, decoded as they are played), and the MB they hold.
  int preloaded_frames() const { return preloaded_frames_; }
  double preloaded_mb() const { return preloaded_mb_; }

  // Starts the reader: every frame is posted to `mailbox`, stamped with its arrival; the input's end (a clean end,
  // max_frames, or an error) closes the mailbox with the reason. `start` is frame 0's due time.
  void Start(FrameMailbox* mailbox, Clock::time_point start);
  // Ends the reader (at its next frame; a camera's pending read is waited for) and joins it. Idempotent.
  void Stop();
  // The error that ended the input early (a damaged video, a camera that stopped), once the mailbox is closed.
  std::optional<Error> error() const;

 private:
  void DecodeVideo();
  // The frames a preload would decode, known before decoding: a video's header count, a sequence's files from 0 up to
  // the first missing one, at most max_frames_ (0: a video whose header does not say).
  int FramesToPreload() const;
  // Error(kUsage) naming INPUT: `frames` (or more than them when !known) of `frame_mb` MB do not fit in `max_mb`.
  Error TooMuchToPreload(int frames, bool known, double frame_mb, double max_mb) const;
  // Decodes frames into ahead_ until the input ends, `max_frames_`, `ahead_limit` frames are waiting (0: no limit) or
  // Stop; false when stopped. At its end sets decoded_end_, end_why_ and end_error_. `max_mb` > 0: throws Error(kUsage)
  // when the frames decoded would hold more.
  bool DecodeFrames(int ahead_limit, double max_mb);
  void PaceVideo(FrameMailbox* mailbox, Clock::time_point start);
  void ReadCamera(FrameMailbox* mailbox);
  bool WaitUntil(Clock::time_point due);  // false when stopped first

  std::string input_, device_;
  double fps_ = 0;
  int max_frames_ = 0;
  int preloaded_frames_ = 0;
  double preloaded_mb_ = 0;
  const std::atomic<int>* interrupt_ = nullptr;  // Preload's; nullptr otherwise
  std::unique_ptr<track::FrameSource> file_;
  std::unique_ptr<media::VideoReader> camera_;
  std::thread thread_, decoder_;
  // Decoded frames waiting for their time (the decoder fills, the pacer empties), and how the file ended: `decoded_end_`
  // once the decoder is done, with `end_why_` ("" at a clean end is not used: the reason is always said) and
  // `end_error_` when it ended on an error.
  std::deque<LiveFrame> ahead_;
  std::vector<cv::Mat> spare_;  // buffers the pacer has posted and got back, for the decoder to reuse
  bool decoded_end_ = false;
  std::string end_why_;
  std::optional<Error> end_error_;
  std::condition_variable ahead_changed_;
  std::atomic<bool> stop_{false};
  mutable std::mutex mutex_;
  std::condition_variable wake_;
  std::optional<Error> error_;
};

}  // namespace blurcue::live
