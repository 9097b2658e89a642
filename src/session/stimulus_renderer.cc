#include "session/stimulus_renderer.h"

#include <algorithm>

#include <opencv2/imgproc.hpp>

#include "core/image.h"

#include "render/psf.h"
#include "render/scene_render.h"

namespace blurcue::session {

using stimulus::LoadProtocolScene;
using stimulus::Presentation;
using stimulus::StimulusImages;
using stimulus::TrialScene;

StimulusRenderer::StimulusRenderer(const protocol::Protocol& protocol, const std::optional<calib::SceneCalib>& scene,
                                   const StimulusImages& images, const Presentation& presentation)
    : protocol_(protocol), scene_(scene), presentation_(presentation) {
  photo_ = images.photo;
  if (protocol.content.type == protocol::ContentType::kPicture) {
    picture_ = images.picture;
    // Every adjustment level's low-passed picture up front (~0.1 s each on the CPU): stepping through the levels
    // in a trial then never stalls a frame on a Butterworth filter.
    for (const auto& block : protocol.blocks)
      if (block.adjust)
        for (double level : block.adjust->levels) UpperHalf(level);
    return;
  }
  if (!scene_) scene_ = LoadProtocolScene(protocol);
  texture_ = scene::SurfaceTexture(images.texture);
  compositor_ = std::make_unique<render::FrameCompositor>(scene_->camera, scene_->rvec, scene_->tvec, photo_,
                                                          presentation.view);
  if (images.take) {
    // Every frame a trial can show, resampled for the screen now: a frame of the take then costs an upload.
    take_ = images.take;
    take_photos_.resize(take_->take().frames.size());
    for (const int i : take_->PosedFrames()) take_photos_[size_t(i)] = compositor_->ScaledPhoto(take_->Photo(i));
    take_posed_ = take_->first_posed();  // the compositor was made with its photo and pose (LoadProtocolScene's)
  }
}

const calib::SceneCalib* StimulusRenderer::ShownScene() const {
  if (take_shown_) return &take_->Calib(take_shown_->posed);
  return scene_ ? &*scene_ : nullptr;
}

StimulusRenderer::~StimulusRenderer() = default;

const cv::Mat& StimulusRenderer::UpperHalf(double level) {
  auto cached = std::find_if(upper_cache_.begin(), upper_cache_.end(),
                             [&](const auto& entry) { return entry.first == level; });
  if (cached != upper_cache_.end()) return cached->second;
  const scene::DepthMatchingLayout& l = presentation_.layout;
  upper_cache_.emplace_back(level, render::PictureOnGrey(picture_, l.upper.size(), l.picture.height, level));
  return upper_cache_.back().second;
}

cv::Size StimulusRenderer::FrameSize() const {
  if (compositor_) return {presentation_.window_width_px, presentation_.window_height_px};
  return presentation_.layout.frame;
}

scene::FrameView StimulusRenderer::View() const {
  return compositor_ ? compositor_->view() : presentation_.view;
}

void StimulusRenderer::Prepare(const TrialScene& trial) {
  if (!compositor_) {
    const double distance_m = protocol_.content.real_photos.empty() ? 0 : trial.distance_m;
    if (lower_.empty() || distance_m != lower_distance_m_) {
      const cv::Mat photo = protocol_.content.real_photos.empty()
                                ? photo_
                                : ReadImage(protocol::RealPhotoFor(protocol_.content, trial.distance_m), 1);
      lower_ = presentation_.layout.LowerHalf(photo);
      lower_distance_m_ = distance_m;
    }
    return;
  }
  const scene::FrameView v = presentation_.ViewFor(protocol_, *scene_, trial);
  compositor_->Place(v.x_px, v.y_px);  // redraws the base only when the place changed
}

void StimulusRenderer::Compose(const TrialScene& trial, double t_s, double level) {
  if (t_s <= 0) Prepare(trial);  // a trial's first frame: nothing to do when the runner prepared it
  if (!compositor_) {
    render::StackDepthMatchingFrame(UpperHalf(level), lower_, &picture_frame_);
    picture_stale_ = true;
    return;
  }
  if (take_) {
    // The take's frame at this moment, at its pose: its photo into the compositor when it changed.
    const stimulus::TakeFrameShown at = take_->FrameAt(t_s);
    // Held (a lost frame, past the take's end, or a screen faster than the take) with nothing else moving: the frame
    // composed last is this one.
    const bool same = t_s > 0 && take_shown_ && at.posed == take_shown_->posed && &trial == composed_trial_ &&
                      trial.MotionS() <= 0;
    take_shown_ = at;
    composed_trial_ = &trial;
    if (same) return;
    if (take_shown_->posed != take_posed_) {
      take_posed_ = take_shown_->posed;
      const calib::SceneCalib& c = take_->Calib(take_posed_);
      compositor_->SetFrame(c.rvec, c.tvec, take_photos_[size_t(take_posed_)]);
    }
    shown_ = VideoObjectsAt(protocol_, *take_, *take_shown_, trial, t_s);
  } else {
    shown_ = ObjectsAt(protocol_, *scene_, trial, t_s);
  }
  objects_.clear();  // kept between frames: its storage is reused
  for (auto& shown : shown_) {
    if (!shown) continue;
    // Under a streak a sub-pixel radius is drawn as wide as the streak's drawing is across (render::DrawnRadiusPx):
    // the record states what the frame shows. Drawn at screen resolution, the compositor's scale.
    // DrawnRadiusPx is max(r, the streak's own width across), which is under 1 screen px: only a smaller radius, or
    // the per-pixel plan's radius at each depth, can fall below it.
    if (shown->motion_px != cv::Vec2d(0, 0)) {
      const double scale = compositor_->view().Scale(scene_->camera);
      render::Psf psf = render::PsfOf(*shown, scale);
      if (psf.r_px < 1 || shown->r_of_depth_px) {
        psf.r_px = 0;
        const double least = render::DrawnRadiusPx(psf) / scale;
        shown->r_px = std::max(shown->r_px, least);
        if (shown->r_of_depth_px)
          shown->r_of_depth_px = [r = std::move(shown->r_of_depth_px), least](double z) {
            return std::max(r(z), least);
          };
      }
    }
    shown->object.texture = texture_;
    objects_.push_back(*shown);
  }
  compositor_->Compose(objects_);
}

void StimulusRenderer::Present(int width_px, int height_px) {
  if (compositor_) {
    compositor_->Present(width_px, height_px);
    return;
  }
  if (!picture_shown_) picture_shown_ = std::make_unique<render::WindowImage>(picture_frame_);
  else if (picture_stale_) picture_shown_->Update(picture_frame_);
  picture_stale_ = false;
  picture_shown_->Present(width_px, height_px);
}

void StimulusRenderer::Finish() {
  if (compositor_) compositor_->Finish();
}

cv::Mat StimulusRenderer::Read() {
  if (compositor_) return compositor_->Read();
  // The picture's frame where the window shows it, on the grey field.
  const scene::FrameView& v = presentation_.view;
  cv::Mat window(v.height_px, v.width_px, CV_8UC3, cv::Scalar::all(128));
  cv::Mat bgr = picture_frame_;
  if (bgr.channels() == 4) cv::cvtColor(bgr, bgr, cv::COLOR_BGRA2BGR);
  else if (bgr.channels() == 1) cv::cvtColor(bgr, bgr, cv::COLOR_GRAY2BGR);
  bgr.copyTo(window(cv::Rect(v.x_px, v.y_px, bgr.cols, bgr.rows)));
  return window;
}

}  // namespace blurcue::session
