#pragma once
// Virtual objects in a tracked take (the folder `blurcue track` writes: track.csv and one calib-NNNN.json per frame
// with a pose): each frame's objects placed at that frame's pose, blurred for their depth by the frame's blur model
// and streaked by their image motion between frames over the exposure. GL-free: what `blurcue ar` draws in every
// frame, and what a study on video will (issue 27).
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "calib/scene_blur.h"
#include "core/json_io.h"
#include "scene/frame.h"
#include "scene/objects.h"
#include "track/tracker.h"

namespace blurcue::stimulus {

// One frame of a tracked take: its row of track.csv and, unless it is lost, its calibration.
struct TrackedFrame {
  int index = 0;
  double time_s = 0;
  track::FrameStatus status = track::FrameStatus::kLost;
  std::optional<calib::SceneCalib> calib;  // empty when lost
  std::vector<double> signature;           // the frame's track::FrameSignature as tracked (empty when lost)
};

struct TrackedTake {
  std::vector<TrackedFrame> frames;  // frames[i].index == i
  // The camera of its calibrations (every frame's is the same camera); Error(kInput) when no frame has a pose.
  const Camera& camera() const;
  const Board& board() const;
  // The frame rate its times state (from the first two frames; 0 with one frame).
  double FramesPerSecond() const;
};

// A camera exposes each frame of a take within the frame's own interval: "" when exposure_ms fits a take at `fps`
// frames per second (or the rate is unknown, fps <= 0), else the words for a message ("longer than a frame of the
// take (33.33 ms at 30 fps)").
std::string ExposureBeyondFrame(double exposure_ms, double fps);

// Reads DIR/track.csv and the calib-NNNN.json of every frame it says has a pose. Errors (kInput) name the file and the
// line or field and the value: a missing file, a column missing, frames out of order, an unknown status; a
// calibration that is not the one track wrote for that row (its frame, time or status differ, its camera is not the
// take's, or it has no frame signature) and one left for a frame track.csv says is lost.
TrackedTake LoadTrackedTake(const std::filesystem::path& dir);

// Checks that `image`, frame `index` of `video`, is the frame `track_dir` tracked: the camera's size and, for a frame
// with a pose, its signature (track::FrameSignature). Error(kInput) naming the video and the frame otherwise.
void CheckTakeFrame(const TrackedTake& take, int index, const cv::Mat& image, const std::string& video,
                    const std::string& track_dir);

// An object an experimenter places on the board (board frame, mm; texture set), named for the record.
struct PlacedObject {
  std::string name;  // "ball1", "card2", or the name the objects file gives
  scene::VirtualObject object;
};

// A ball of `radius_mm` resting on the board with its centre over (x_mm, y_mm); a card of width x height mm standing
// upright on the board, its bottom edge's middle at (x_mm, y_mm), facing the camera (-y) turned by rotation_deg.
scene::VirtualObject BallAt(double x_mm, double y_mm, double radius_mm);
scene::VirtualObject StandingCardAt(double x_mm, double y_mm, double width_mm, double height_mm, double rotation_deg);

// The most objects one AR run places: each is drawn in every frame and has a CSV row per frame. A longer list is
// refused before any texture is decoded.
constexpr size_t kMaxPlacedObjects = 64;

// Objects from a JSON file: {"objects": [{"kind": "ball", "x_mm": 87.5, "y_mm": 125, "radius_mm": 10,
// "texture": "soccer"}, {"kind": "card", "x_mm": 60, "y_mm": 150, "width_mm": 40, "height_mm": 30,
// "rotation_deg": 0, "texture": "wood", "name": "sign"}]}. Every key is checked (an unknown one is an error with a
// did-you-mean); errors (kInput) name the file, the JSON pointer and the value.
std::vector<PlacedObject> LoadPlacedObjects(const std::filesystem::path& path);
std::vector<PlacedObject> PlacedObjectsFromJson(const Json& json, const std::string& where);

// How a take's objects are blurred: the blur source (core's vocabulary) at each object's centre, the defocus's shape,
// and the exposure over which its image motion streaks it (0: no motion blur).
struct TakeBlur {
  BlurSource source = BlurSource::kFitted;
  double fixed_r_px = 0;      // for BlurSource::kFixed
  std::string method = "disc";  // "disc" (a thin lens's pillbox) or "gaussian"
  double exposure_ms = 0;
};

// What was drawn of one object in one frame (a row of the per-frame CSV).
struct DrawnObject {
  std::string name;
  cv::Point2d screen_px;  // its centre's projection (image px, x right, y down, pixel centres at integers)
  double depth_mm = 0;    // its centre's camera z
  double r_px = 0;        // defocus x floor: 2 x the std of the PSF's line-spread function without the motion
  double floor_sigma_px = 0;
  cv::Vec2d motion_px{0, 0};  // the streak: its image velocity x the exposure
};

// One frame's objects, ready to draw (objects[i] is drawn[i]); both empty for a lost frame.
struct TrackedFramePlan {
  std::vector<scene::BlurredObject> objects;
  std::vector<DrawnObject> drawn;
};

// The streak of a board point in frame `index` (image px, x right, y down): its image velocity there - the change of
// its projection between the nearest frames with a pose on either side (central where both are, one-sided at a gap
// or an end, none when neither is) over their time apart - times the exposure. 0 for a lost frame or no exposure.
cv::Vec2d StreakPx(const TrackedTake& take, int index, const cv::Vec3d& board_mm, double exposure_ms);

// The objects of frame `index` (its place in take.frames) at its pose, each streaked by StreakPx of its centre.
// Error(kDomain) naming the object and the frame (take.frames[index].index: a live view plans from a two-frame window
// of a take) when its blur cannot be evaluated there or exceeds the largest blur.
TrackedFramePlan PlanTrackedFrame(const TrackedTake& take, int index, const std::vector<PlacedObject>& objects,
                                  const TakeBlur& blur);

// Whether any posed frame of the take shows `object` in its photo (its footprint meets the image; a frame with the
// object behind the camera does not). An object in none would leave a video without it.
bool SeenInAnyFrame(const TrackedTake& take, const scene::VirtualObject& object);

// The per-frame CSV of what was drawn: its columns (name, meaning), its header line and a frame's lines (one per
// object; one line with empty object fields for a frame drawn without objects, `status` saying why).
struct DrawnColumn {
  const char* name;
  const char* meaning;
};
extern const std::vector<DrawnColumn> kDrawnColumns;
std::string DrawnCsvHeader();
std::string DrawnCsvRows(int frame, double time_s, const std::string& status, const std::vector<DrawnObject>& drawn);

}  // namespace blurcue::stimulus
