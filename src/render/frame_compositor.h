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

namespace blurcue::render {

struct BlurredObject {
  VirtualObject object;
  std::string method = "gaussian";  // "gaussian" or "disc"
  double r_px = 0;                  // in the camera's (photo) px; drawn at r_px x the view's scale in screen px
  // The per-pixel plan: the radius (photo px) at a camera depth (mm), each pixel blurred by its own depth
  // (BlurLayerVarying); empty: r_px everywhere.
  std::function<double(double)> r_of_depth_px;
};

// Where a composed frame (the window, in screen px) shows the camera's photo: resampled in linear light with an area
// filter to photo_width x photo_height px and placed with its top-left corner at (x_px, y_px), grey around it
// (letterboxed) or cut by the frame's edges (cropped). The objects are drawn, and blurred, at screen resolution.
struct FrameView {
  int width_px = 0, height_px = 0;              // the frame
  int photo_width_px = 0, photo_height_px = 0;  // the photo in it
  int x_px = 0, y_px = 0;                       // the photo's top-left corner in it

  // The photo as it is: one screen px per photo px, nothing around it.
  static FrameView Identity(int photo_width_px, int photo_height_px);
  // Screen px per photo px across (down differs by less than one px over the photo's height).
  double Scale(const Camera& photo_camera) const { return double(photo_width_px) / photo_camera.image_width_px; }
  // The camera that sees the frame (Camera::Viewed).
  Camera CameraOf(const Camera& photo_camera) const;
  bool operator==(const FrameView&) const = default;
};

class FrameCompositor {
 public:
  // Needs a current GL context. `background` is the 8-bit sRGB photo, the camera's size; `view` where frames show
  // it (default: the photo as it is). The photo is resampled once, here.
  FrameCompositor(const Camera& camera, const cv::Vec3d& rvec, const cv::Vec3d& tvec, const cv::Mat& background,
                  std::optional<FrameView> view = std::nullopt);
  ~FrameCompositor();
  FrameCompositor(const FrameCompositor&) = delete;
  FrameCompositor& operator=(const FrameCompositor&) = delete;

  // Object-region approach: per object, a layer of its bounds + kernel margin is drawn, blurred and blended - the
  // frame's layers side by side in one atlas, each stage for all of them at once (llvmpipe pays per pass).
  void Compose(const std::vector<BlurredObject>& objects);
  // The thesis's approach: each object drawn into a whole-frame buffer, the whole buffer blurred, then blended.
  void ComposeWholeFrame(const std::vector<BlurredObject>& objects);
  // Waits for the GPU (timing) and reads the frame as 8-bit BGR sRGB.
  cv::Mat Read();
  void Finish();
  // Moves the photo in the frame (another crop of the same scaled photo): x_px, y_px of the view.
  void Place(int x_px, int y_px);
  const FrameView& view() const;
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
