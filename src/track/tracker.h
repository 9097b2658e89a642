#pragma once
// Board tracking through a take (DESIGN.md "Motion"): the pose carried from frame to frame, a full detection as the
// flagged fallback, every usable section measured by calibrate's own measurement, and one lens model for the take.
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "calib/calibrate.h"
#include "core/board.h"
#include "core/camera.h"

namespace blurcue::track {

// How a frame's board was found: carried from the previous frames, a full detection (the first frame, or tracking
// lost), or not at all.
enum class FrameStatus { kFound, kTracked, kLost };
const char* Name(FrameStatus status);

struct TrackOptions {
  calib::CalibrateOptions calibrate;     // the measurement's options (known_pose is set per frame)
  double max_track_error_px = 0.5;       // a tracked pose's RMS reprojection error above this: tracking is lost
  bool always_detect = false;            // full detection on every frame (the bench's baseline)
  bool measure_blur = true;              // false: the pose only (a lens model fixed elsewhere: blurcue live)
  // With measure_blur: 0 measures every section of every frame; N > 0 a rotating subset of N a frame (the next N in
  // the order section 1 of edges 1 .. E, section 2 of edges 1 .. E, ..., wrapping round, on each frame with a pose),
  // so every section is measured once in every ceil(sections / N) frames (blurcue live --measure-sections).
  int sections_per_frame = 0;
};

struct FrameResult {
  int index = 0;
  double time_s = 0;
  FrameStatus status = FrameStatus::kLost;
  std::string note;                      // why a frame is lost, or why tracking fell back to detection
  std::optional<calib::CalibResult> calib;  // empty when lost, or when the blur is not measured
  std::optional<calib::BoardPose> pose;     // the frame's pose; empty when lost
  double pose_ms = 0;                    // tracking or detection, and the pose
  double measure_ms = 0;                 // linear light, every section's blur, the frame's estimate
  double frame_ms = 0;                   // all of the frame's work (decoding excluded)
  int sections_measured = 0;             // sections whose blur was measured in this frame (usable or not)
  std::vector<double> signature;         // FrameSignature of the frame (TrackTake fills it)
};

// Carries the board from frame to frame: the corners predicted from the last two frames (constant velocity),
// refined where they are, the pose solved; a full detection when there is no history or the refined corners do
// not fit a pose within max_track_error_px.
class Tracker {
 public:
  Tracker(Camera camera, Board board, TrackOptions options);
  // `photo`: 8-bit BGR or grey, the camera's size (Error(kInput) otherwise).
  FrameResult Process(const cv::Mat& photo, int index, double time_s);

 private:
  std::optional<calib::BoardPose> Track(const cv::Mat& grey8, const cv::Mat& small, double time_s,
                                        std::string* note) const;

  Camera camera_;
  Board board_;
  TrackOptions options_;
  std::vector<cv::Point2f> last_, before_last_;  // corners of the last two frames with a pose (empty: none)
  double last_time_s_ = 0, before_last_time_s_ = 0;  // and their times
  cv::Mat last_small_;  // the last frame with a pose, a quarter size, float: its shift to the next one
  calib::PhotoPlanes planes_;  // the frame's grey and linear planes; their buffers serve the whole take
  int next_section_ = 0;       // the first section of the next frame's subset (sections_per_frame > 0)
};

// The take's one lens model (fixed focus and aperture): the thin-lens fit to every usable section of every frame
// with a calibration, then made each frame's model (calib::ApplyModel). Throws Error(kNotFound) when fewer than
// three sections are usable in the whole take.
optics::FittedModel FitTakeModel(std::vector<FrameResult>& frames, const optics::FitOptions& options = {});

}  // namespace blurcue::track
