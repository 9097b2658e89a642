#pragma once
// Composing whole stimulus frames on the GPU: the photo stays in a texture, each virtual object is drawn into a
// layer covering its pixels plus the kernel margin, blurred there, and blended over the frame in linear light.
// The thesis's way - blur a whole-frame buffer holding the object - is kept beside it for the benchmark.
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/camera.h"
#include "render/scene_render.h"
#include "scene/frame.h"

namespace blurcue::render {

class FrameCompositor {
 public:
  // Needs a current GL context. `background` is the 8-bit sRGB photo, the camera's size; `view` where frames show
  // it (default: the photo as it is). The photo is resampled once, here.
  FrameCompositor(const Camera& camera, const cv::Vec3d& rvec, const cv::Vec3d& tvec, const cv::Mat& background,
                  std::optional<scene::FrameView> view = std::nullopt);
  ~FrameCompositor();
  FrameCompositor(const FrameCompositor&) = delete;
  FrameCompositor& operator=(const FrameCompositor&) = delete;

  // Object-region approach: per object, a layer of its bounds + kernel margin is drawn, blurred and blended - the
  // frame's layers side by side in one atlas, each stage for all of them at once (llvmpipe pays per pass).
  void Compose(const std::vector<scene::BlurredObject>& objects);
  // The thesis's approach: each object drawn into a whole-frame buffer, the whole buffer blurred, then blended.
  void ComposeWholeFrame(const std::vector<scene::BlurredObject>& objects);
  // Waits for the GPU (timing) and reads the frame as 8-bit BGR sRGB.
  cv::Mat Read();
  void Finish();
  // The next frame of a video: `background` (8-bit sRGB, the camera's size, or already resampled to the view's photo
  // size: ScaledPhoto) uploaded into the photo's texture and the board at rvec/tvec, in the targets made once (a
  // video allocates no GL object per frame).
  // `compose_once` (a live view, which shows each photo once): the next Compose is the only one on this photo, so a
  // photo that fills the frame is uploaded straight into the frame, without the base frame a second Compose restores
  // the photo from (a whole-frame copy saved a frame: 6-7 ms on llvmpipe); Compose again or Place before the next
  // SetFrame throws Error(kInternal).
  void SetFrame(const cv::Vec3d& rvec, const cv::Vec3d& tvec, const cv::Mat& background, bool compose_once = false);
  // A photo of the camera's size resampled as this compositor shows it (linear light, area filter): what SetFrame
  // takes without resampling again.
  cv::Mat ScaledPhoto(const cv::Mat& background) const;
  // Moves the photo in the frame (another crop of the same scaled photo): x_px, y_px of the view.
  void Place(int x_px, int y_px);
  const scene::FrameView& view() const;
  // Copies the frame to the current default framebuffer (a window), scaled to fit `width` x `height` (one to one
  // when the view is the window's size, as a session's is).
  void Present(int width_px, int height_px);
  SceneRenderer& renderer();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// An 8-bit sRGB image (a text screen, a CPU-made stimulus) uploaded once and shown in the current window as often
// as needed: a frame costs a blit, not an upload. Needs a current GL context.
class WindowImage {
 public:
  explicit WindowImage(const cv::Mat& image);
  ~WindowImage();
  WindowImage(const WindowImage&) = delete;
  WindowImage& operator=(const WindowImage&) = delete;
  // Draws it into the window's default framebuffer, scaled to fit width_px x height_px, letterboxed on grey.
  void Present(int width_px, int height_px) const;
  // Shows `image` (the same size and type) from now on: an upload into the texture it has, no new one.
  void Update(const cv::Mat& image);
  // Draws it 1:1 over what the window already shows, its top-left corner at (x_px, y_px) (y down from the top) of a
  // window height_px high.
  void PresentAt(int x_px, int y_px, int height_px) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// The current window's back buffer (what the next swap shows) as 8-bit BGR, image rows top first.
cv::Mat ReadWindow(int width_px, int height_px);

}  // namespace blurcue::render
