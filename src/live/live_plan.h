#pragma once
// What `blurcue live` draws in a frame, GL-free: the frame's pose from the tracker (the pose only: the lens model is
// fixed by a prior `track` or `calibrate`), and the objects planned as `blurcue ar` plans them
// (stimulus::PlanTrackedFrame: the same defocus and floor at each object's depth), streaked by their image motion
// since the last frame with a pose - the causal form of ar's streak, which looks at the next frame too.
#include <filesystem>
#include <future>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include "calib/calibrate.h"
#include "calib/scene_blur.h"
#include "stimulus/tracked_take.h"
#include "track/tracker.h"

namespace blurcue::live {

// The lens a live view draws with: calib.json's (`blurcue calibrate`), or a tracked take's (its first frame with a
// pose: one lens model for the whole take). Its sections are left out (they belong to that photo's pose). The
// camera must be `camera`'s (size, intrinsics, distortion), else Error(kInput) naming the file and what differs.
calib::SceneCalib LensFromCalib(const std::filesystem::path& calib_json, const Camera& camera);
calib::SceneCalib LensFromTrack(const std::filesystem::path& track_dir, const Camera& camera);

// The blur sources a live view can draw: those that need no section measured in the frame (fitted, estimated, none,
// a fixed radius). Error(kUsage) naming `option` for measured and measured_section.
void RequireLiveSource(BlurSource source, const std::string& option);

// The lens model a live view fits as it goes (--measure-sections): the latest reading of every board section
// measured so far - each a depth and a blur, true whatever the pose was, since the focus is fixed - and the thin lens
// fitted to them (optics::FitThinLens, as `track` fits a take's one model to every frame's sections). The fit runs on
// a thread of its own, so a frame never waits for it: 77 readings, the floor chosen by leave-one-out, take
// milliseconds that a frame's latency need not carry; a frame draws with the newest model finished before it.
class LiveLens {
 public:
  explicit LiveLens(Camera camera) : camera_(std::move(camera)) {}
  // Keeps the usable sections of `frame` (a subset measured: calib::CalibrateOptions::only_sections) as their
  // sections' latest readings, a section measured unusable forgetting its earlier one. When the readings changed
  // since the last fit started, lie on 3 edges at least (as calibrate asks of a photo) and no fit is running or
  // waiting to be taken, starts fitting the model to all of them; true when it did.
  bool Update(const calib::CalibResult& frame);
  // The model of the fit finished since the last call, into `model`; false when none finished (or it found too few
  // depths). Never waits.
  bool TakeModel(optics::FittedModel* model);
  // Waits for a fit started to finish (TakeModel then has it).
  void Wait();
  int sections() const { return sections_; }  // readings of the last model taken (0: none yet)

 private:
  Camera camera_;
  std::map<std::pair<int, int>, optics::BlurSample> latest_;  // by (edge, section)
  bool changed_ = false;  // readings changed since the last fit started
  std::future<std::optional<optics::FittedModel>> fit_;
  int sections_ = 0;
};

class LivePlanner {
 public:
  LivePlanner(calib::SceneCalib lens, std::vector<stimulus::PlacedObject> objects, stimulus::TakeBlur blur);
  // Frame `index` at `time_s` (the input's clock) with its pose (empty: lost, nothing drawn). Error(kDomain) as
  // PlanTrackedFrame, naming the object and the frame.
  stimulus::TrackedFramePlan Plan(int index, double time_s, track::FrameStatus status,
                                  const std::optional<calib::BoardPose>& pose);
  const calib::SceneCalib& lens() const { return *window_.frames[1].calib; }
  // Draws the next frames with `model` (a LiveLens's) in place of the lens model it was made with.
  void SetModel(const optics::FittedModel& model);
  const std::vector<stimulus::PlacedObject>& objects() const { return objects_; }

 private:
  // frames[0]: the last frame with a pose (its calib empty before the first); frames[1]: the frame being planned.
  // Two calibrations made once and updated in place: a frame allocates no calibration.
  stimulus::TrackedTake window_;
  std::vector<stimulus::PlacedObject> objects_;
  stimulus::TakeBlur blur_;
};

}  // namespace blurcue::live
