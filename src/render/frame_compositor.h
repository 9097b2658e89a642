#pragma once
// Composing whole stimulus frames on the GPU: the photo stays in a texture, each virtual object is drawn into a
// layer covering its pixels plus the kernel margin, blurred there, and blended over the frame in linear light.
// The thesis's way - blur a whole-frame buffer holding the object - is kept beside it for the benchmark.
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/camera.h"
#include "render/scene_render.h"

namespace blurcue::render {

struct BlurredObject {
  VirtualObject object;
  std::string method = "gaussian";  // "gaussian" or "disc"
  double r_px = 0;
};

class FrameCompositor {
 public:
  // Needs a current GL context. `background` is the 8-bit sRGB photo, the camera's size.
  FrameCompositor(const Camera& camera, const cv::Vec3d& rvec, const cv::Vec3d& tvec, const cv::Mat& background);
  ~FrameCompositor();
  FrameCompositor(const FrameCompositor&) = delete;
  FrameCompositor& operator=(const FrameCompositor&) = delete;

  // Object-region approach: per object, a layer of its bounds + kernel margin is drawn, blurred and blended.
  void Compose(const std::vector<BlurredObject>& objects);
  // The thesis's approach: each object drawn into a whole-frame buffer, the whole buffer blurred, then blended.
  void ComposeWholeFrame(const std::vector<BlurredObject>& objects);
  // Waits for the GPU (timing) and reads the frame as 8-bit BGR sRGB.
  cv::Mat Read();
  void Finish();
  // Copies the frame to the current default framebuffer (a window), scaled to fit `width` x `height`.
  void Present(int width_px, int height_px);
  SceneRenderer& renderer();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// An 8-bit sRGB image (a text screen, a CPU-made stimulus) uploaded once and shown in the current window as often
// as needed: a frame costs a blit, not an upload. Needs a current GL context.
// The scale at which a src_w x src_h frame is shown in a width_px x height_px window: fitted whole, letterboxed,
// its shown width floored to whole pixels (screen px per frame px). What BlitToWindow does, and what the record says.
double FitScale(int src_w, int src_h, int width_px, int height_px);

class WindowImage {
 public:
  explicit WindowImage(const cv::Mat& image);
  ~WindowImage();
  WindowImage(const WindowImage&) = delete;
  WindowImage& operator=(const WindowImage&) = delete;
  // Draws it into the window's default framebuffer, scaled to fit width_px x height_px, letterboxed on grey.
  void Present(int width_px, int height_px) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace blurcue::render
