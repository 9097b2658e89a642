#pragma once
// A study on video (a protocol's scene {"video": ..., "track": ...}): the tracked take, its frames decoded once per
// session, and which frame a trial shows when. A trial plays the take from its first frame with a pose at the take's
// own frame rate; a lost frame, and every moment past the take's end, holds the last frame with a pose (its photo and
// its objects). GL-free: session's StimulusRenderer draws what this says, the runner records it.
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "calib/scene_blur.h"
#include "protocol/protocol.h"
#include "stimulus/stimulus.h"
#include "stimulus/tracked_take.h"

namespace blurcue::stimulus {

// The take's frame on screen at a moment of a trial.
struct TakeFrameShown {
  int take_frame = 0;   // the take's frame at this moment (its index in track.csv; the last one past the end)
  int posed = 0;        // the frame whose photo and pose are shown: take_frame, or for a held one the last with a pose
  std::string status;   // found | tracked (shown at its own pose) | held (lost, or past the take's end)
};

class VideoTake {
 public:
  // Reads the track folder (LoadTrackedTake) and decodes every frame of the take up to its last with a pose, checking
  // each against the track's camera. Errors (kInput) name the protocol file and /scene/track or /scene/video.
  explicit VideoTake(const protocol::Protocol& protocol);

  const TrackedTake& take() const { return take_; }
  int first_posed() const { return first_posed_; }
  // Frame `index`'s image (8-bit BGR) and, for a frame with a pose, its calibration.
  const cv::Mat& Photo(int index) const { return photos_[size_t(index)]; }
  const calib::SceneCalib& Calib(int index) const { return *take_.frames[size_t(index)].calib; }
  // The frames per second the take plays at (track.csv's times; 30 for a one-frame take).
  double fps() const { return fps_; }
  // The take's frame t_s after a trial's onset: first_posed() + floor(t_s x fps), held as the class says.
  TakeFrameShown FrameAt(double t_s) const;
  // Throws Error(kInput) naming /scene/track when the frames a trial can show, decoded and resampled for the screen
  // (`screen_photo`: the photo's size there, 8-bit RGBA), would hold more than 4 GiB.
  void CheckMemory(const protocol::Protocol& protocol, cv::Size screen_photo) const;
  // Every frame a trial can show (the frames with a pose from first_posed() on).
  std::vector<int> PosedFrames() const;

 private:
  TrackedTake take_;
  std::vector<cv::Mat> photos_;
  int first_posed_ = 0, last_posed_ = 0;
  double fps_ = 30;
};

// What identifies a take in the record (procedure/prepare.cc adds it to the recorded protocol text as "recorded_take"):
// its frame count, frame rate and a hash of every frame's status and signature (track::FrameSignature, as track
// wrote them). Another take - or the same protocol text at a station that filmed its own - is then another protocol
// text: refused under the same version, told apart by protocol_hash in a merged record and described apart in the
// report. Re-tracking the same take gives the same identity (track's timings are not in it).
Json TakeIdentity(const VideoTake& take);

// What a pair trial shows in the take's frame `shown`, t_s after onset: ObjectsAt at that frame's pose (each side's
// source evaluated with the frame's calibration: its lens model, its measured edges), each object's streak being its
// own motion's plus the camera's (StreakPx of its centre over the trial's exposure). Throws as ObjectsAt.
std::array<std::optional<scene::BlurredObject>, 2> VideoObjectsAt(const protocol::Protocol& protocol,
                                                                   const VideoTake& take, const TakeFrameShown& shown,
                                                                   const TrialScene& trial, double t_s);

// A trial on video as the take plays under it: DescribeTrial and PlanOnScreen at every frame with a pose the trial
// shows, the record's radii, floors, streaks and scene blur (each side's r_px, floor_sigma_px and motion_px,
// r_scene_px) averaged over the time each frame is on screen while the stimulus is (TakeWindowS), a per-pixel plan
// where any frame asks for one.
// What the trial shows first (place, size at onset) is the first frame's. A frame whose objects cannot be drawn or
// lie outside its photo is an error (kInput) naming the protocol file, the trial and the take's frame. The trial's
// radii are thus the ones its participant sees on the whole, as a rolling ball's are averaged over its run.
TrialScene DescribeVideoTrial(const protocol::Protocol& protocol, const VideoTake& take, const protocol::Trial& trial,
                              const Presentation& presentation);

// PlanOnScreen for a trial on video whose radii a procedure's level has changed (ApplyLevel): planned on every frame
// with a pose the trial shows, as DescribeVideoTrial plans it (the per-pixel plan where any frame asks for it, the
// widest depth span); what it shows first is the first frame's.
void PlanVideoOnScreen(const protocol::Protocol& protocol, const VideoTake& take, const protocol::Trial& trial,
                       const Presentation& presentation, TrialScene* scene);

// The seconds of a trial over which its radii are averaged: the stimulus's time (timing.stimulus_ms, or all the
// intervals), or for one shown until the answer the take's time as it plays once (from its first frame with a pose
// to the end of its last frame), or a rolling ball's run if longer, at most the deadline.
double TakeWindowS(const protocol::Protocol& protocol, const VideoTake& take, const protocol::Trial& trial,
                   const TrialScene& scene);

// Checks that every frame a trial can show can draw its objects (a measured source needs the frame's measurement at
// the object's edge; every radius and streak within range): Error(kInput) naming the protocol file, the trial and the
// take's frame.
void CheckVideoTrial(const protocol::Protocol& protocol, const VideoTake& take, const protocol::Trial& trial,
                     const TrialScene& scene);

}  // namespace blurcue::stimulus
