#pragma once
// The frames that show a trial (stimulus::TrialScene, as stimulus describes it), composed on the GPU: the session's one
// user of render's compositor.
#include <array>
#include <memory>
#include <optional>
#include <utility>
#include <vector>

#include <opencv2/core.hpp>

#include "calib/scene_blur.h"
#include "protocol/protocol.h"
#include "render/blur.h"
#include "render/frame_compositor.h"
#include "scene/frame.h"
#include "stimulus/stimulus.h"
#include "stimulus/video_take.h"

namespace blurcue::session {

class StimulusRenderer {
 public:
  // Needs a current GL context. `scene` is the protocol's calibration (LoadProtocolScene), `images` its images
  // (LoadStimulusImages), both copied; frames are composed as `presentation` says (the window's size).
  StimulusRenderer(const protocol::Protocol& protocol, const std::optional<calib::SceneCalib>& scene,
                   const stimulus::StimulusImages& images, const stimulus::Presentation& presentation);
  ~StimulusRenderer();
  StimulusRenderer(const StimulusRenderer&) = delete;
  StimulusRenderer& operator=(const StimulusRenderer&) = delete;

  // Size of the frames it makes (the photo's, or the depth-matching frame's).
  cv::Size FrameSize() const;
  // What a trial's frames need besides their own drawing, done before its first frame so that the frame loop reads
  // no file and resamples no photo: the photo placed where the trial shows it (pairs), the real photo at the trial's
  // distance read and scaled (picture). Cheap when nothing changed; Compose at t_s = 0 calls it too.
  void Prepare(const stimulus::TrialScene& trial);
  // Composes the frame t_s after onset; `level` is the adjustment level shown (picture only).
  void Compose(const stimulus::TrialScene& trial, double t_s, double level);
  // What the last composed frame showed of a pair (ObjectsAt, as drawn; radii in photo px): empty sides for
  // pictures and wiped balls.
  const std::array<std::optional<scene::BlurredObject>, 2>& Shown() const { return shown_; }
  // A study on video: the take's frame the last composed frame showed, and its calibration (the pose and blur its
  // objects were drawn with); empty / null for a photo.
  const std::optional<stimulus::TakeFrameShown>& ShownTake() const { return take_shown_; }
  const calib::SceneCalib* ShownScene() const;
  // Where the last composed frame showed the photo (pairs; the identity of the frame for a picture).
  scene::FrameView View() const;
  // Shows the last composed frame in the current window, fitted to width x height.
  void Present(int width_px, int height_px);
  // Waits until the last composed frame is drawn (for timing).
  void Finish();
  // The last composed frame, 8-bit sRGB BGR.
  cv::Mat Read();

 private:
  const protocol::Protocol& protocol_;
  std::optional<calib::SceneCalib> scene_;
  stimulus::Presentation presentation_;
  cv::Mat photo_;
  scene::SurfaceTexture texture_;  // the objects' texture: one GL texture for the session
  std::vector<scene::BlurredObject> objects_;  // the frame's objects for the compositor, kept between frames
  std::unique_ptr<render::FrameCompositor> compositor_;
  // Picture: the upper half at a cut-off, made once (the Butterworth runs on the CPU) and kept; every level of
  // the protocol is made up front.
  const cv::Mat& UpperHalf(double level);
  cv::Mat picture_;
  std::vector<std::pair<double, cv::Mat>> upper_cache_;  // cut-off -> upper half
  cv::Mat picture_frame_;
  std::unique_ptr<render::WindowImage> picture_shown_;  // picture_frame_ on the GPU, updated in place
  bool picture_stale_ = true;                          // picture_frame_ changed since it was last uploaded
  double lower_distance_m_ = -1;  // the distance whose real photo lower_ shows (one at a time: 27 would hold ~50 MB)
  cv::Mat lower_;                 // the frame's lower half, scaled once per trial
  std::array<std::optional<scene::BlurredObject>, 2> shown_;
  // Video: the take, its frames with a pose resampled once for the screen (by take frame; empty for the others), the
  // frame the compositor holds, and the frame last shown.
  std::shared_ptr<const stimulus::VideoTake> take_;
  std::vector<cv::Mat> take_photos_;
  int take_posed_ = -1;
  std::optional<stimulus::TakeFrameShown> take_shown_;
  const stimulus::TrialScene* composed_trial_ = nullptr;  // what the last composed frame showed (a video's hold)
};

}  // namespace blurcue::session
