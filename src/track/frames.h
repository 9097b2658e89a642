#pragma once
// The frames of a take: a video file (whatever OpenCV's videoio reads) or an image sequence named by a printf
// pattern (frames/frame-%04d.png, numbered from 0).
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/media.h"

namespace blurcue::track {

// The frame rates a take is read at, frames per second: at the slowest a day holds 864 frames, at the fastest frames
// are 1 ms apart (what a tracked take's reader, stimulus/tracked_take.cc, accepts); a rate outside would write times
// that are refused when read back, or 63-digit ones.
constexpr double kMinFps = 0.01, kMaxFps = 1000;

class FrameSource {
 public:
  // `fps` gives the frames' times for an image sequence (a video's own rate is used when it states one).
  // Throws Error(kUsage) for a pattern with other than one integer conversion or `fps` outside [kMinFps, kMaxFps],
  // Error(kInput) for a video that cannot be opened or a sequence whose first frame is missing.
  FrameSource(const std::string& input, double fps);

  // The next frame (8-bit BGR) with its index and time; false at the clean end of the take. Throws Error(kInput)
  // naming the input and the frame for a damaged or truncated video, a missing frame inside a sequence, or an
  // unreadable, damaged or truncated image (ReadImage checks each file whole).
  bool Next(cv::Mat* frame, int* index, double* time_s);

  bool is_video() const { return !pattern_; }
  double fps() const { return fps_; }
  // Frames the video's header promises (0 when it does not say, or for a sequence).
  int expected_frames() const { return expected_; }

 private:
  std::string input_;
  std::optional<std::string> pattern_;
  media::VideoReader video_;
  double fps_ = 30;
  int expected_ = 0;
  int next_ = 0;
};

// A frame's signature: the means of its grey level (0-255, channels averaged) over an 8 x 8 grid of cells. `track`
// writes it in each calib-NNNN.json ("frame_signature") so that whoever plays the take later (a study on video,
// `ar`) can tell the video is the one that was tracked: another take, or frames in another order, differ by tens of
// levels in some cell; the same take decoded by another build of a codec, by a level or less.
std::vector<double> FrameSignature(const cv::Mat& bgr);
// The largest difference of two signatures' cells (grey levels); infinity when their sizes differ.
double SignatureDistance(const std::vector<double>& a, const std::vector<double>& b);
// Signatures further apart than this are of different frames.
constexpr double kMaxSignatureDistance = 4;

// True when `input` is a printf pattern (holds a '%'), i.e. an image sequence.
bool IsFramePattern(const std::string& input);
// The files a take is read from: the video, or the frames of a sequence that exist (numbered from 0, up to the first
// gap the reader would end at). For a command to check its outputs against (core/output_guard.h) before reading.
std::vector<std::filesystem::path> TakeInputFiles(const std::string& input);
// The pattern's file for frame `index`; Error(kUsage) unless the pattern has exactly one %d-style conversion.
std::filesystem::path PatternFile(const std::string& pattern, int index);

}  // namespace blurcue::track
