#pragma once
// Virtual content placed in a calibrated scene's board frame (mm; scene/objects.h), drawn with GL into a layer that
// covers only the object's pixels plus the blur kernel's margin (model no more than a scene needs), blurred, and
// composited over the photo in linear light.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/camera.h"
#include "render/psf.h"
#include "scene/frame.h"
#include "scene/objects.h"

namespace blurcue::render {

// An object drawn alone: premultiplied linear RGBA (CV_32FC4, BGRA order like OpenCV) over `roi` of the photo.
struct Layer {
  cv::Rect roi;
  cv::Mat bgra;
  cv::Mat depth_mm;  // CV_32F camera z of the object's surface per pixel, 0 where it does not cover
};

class GrowingTarget;
// The same on the GPU: linear premultiplied RGBA in the bottom-left roi.width x roi.height of one of the renderer's
// pooled targets (GL row = image row); `color` null when off-screen. Valid until the renderer's next DrawToTexture.
struct GpuLayer {
  cv::Rect roi;
  GrowingTarget* color = nullptr;
  GrowingTarget* depth = nullptr;  // camera z (mm) x coverage in red, the coverage in alpha; null unless asked for
};

class SceneRenderer {
 public:
  // Needs a current GL context. rvec/tvec: board frame -> camera (mm).
  SceneRenderer(const Camera& camera, const cv::Vec3d& rvec, const cv::Vec3d& tvec);
  ~SceneRenderer();
  SceneRenderer(const SceneRenderer&) = delete;
  SceneRenderer& operator=(const SceneRenderer&) = delete;

  // Where `object` lands in the image (scene::FootprintOf with the renderer's camera and pose).
  scene::Footprint Measure(const scene::VirtualObject& object) const;
  // Draws from now on as `camera` sees (the same pose): a view of the photo scaled and placed (Camera::Viewed).
  void SetCamera(const Camera& camera);
  // Draws from now on with the board at another pose (a tracked take's next frame): nothing is allocated.
  void SetPose(const cv::Vec3d& rvec, const cv::Vec3d& tvec);
  // Draws the object into a layer covering its bounds grown by margin_px, clipped to the image.
  Layer Draw(const scene::VirtualObject& object, int margin_px);
  // The same, left on the GPU for frame composition, in targets the renderer made once and grows (a frame loop
  // allocates nothing); the per-pixel depth only when `depth_map` (the depth-varying blur needs it; a frame of
  // single-radius objects does not pay for it).
  GpuLayer DrawToTexture(const scene::VirtualObject& object, int margin_px, bool depth_map = false);
  // Where a layer of the object with that margin lies in the image (its bounds grown, clipped; empty: off-screen).
  cv::Rect LayerRoi(const scene::VirtualObject& object, int margin_px) const;
  // Draws the object's layer over image rectangle `roi` into `color` (and its depth into `depth` when given) with its
  // top-left image pixel at texel `at`: many layers side by side in one target, drawn in one go. The targets must
  // already hold at + roi's size (GrowingTarget::Reserve first): growing one would lose the layers it holds.
  void DrawLayerAt(const scene::VirtualObject& object, const cv::Rect& roi, GrowingTarget& color,
                   GrowingTarget* depth, cv::Point at);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Blurs a layer in place with one radius: "gaussian" (s = r/2) or "disc", on the GL path when `gl` is given
// (CPU reference otherwise). The layer's margin must cover the kernel.
class GlBlur;
void BlurLayer(Layer& layer, const std::string& method, double r_px, GlBlur* gl);
// The same with a whole PSF (defocus x floor x streak, render/psf.h): the general kernel through filter2D on the CPU,
// one pass of blur_kernel.frag on the GL path.
void BlurLayer(Layer& layer, const Psf& psf, GlBlur* gl);

// Depth-varying blur: each pixel of the object gets r_of_depth(its camera z); pixels the blur spreads into take
// the r of the nearest covered pixel. The layer is blurred at radius levels 0.5 px apart and each pixel mixes its
// two nearest levels so the variance (r^2 / 4) is exact. Margin must cover r at the largest depth.
void BlurLayerVarying(Layer& layer, const std::string& method, const std::function<double(double)>& r_of_depth,
                      GlBlur* gl);
// The same with `psf`'s shape, floor and streak at every level (its r_px unused): the floor and the streak do not
// change with depth, so the levels' variances still mix exactly.
void BlurLayerVarying(Layer& layer, const Psf& psf, const std::function<double(double)>& r_of_depth, GlBlur* gl);

// The margin (px) a blur of radius r needs around an object: the kernel's half-width.
int KernelMarginPx(const std::string& method, double r_px);
// The margin a whole PSF needs (PsfHalfWidth).
int KernelMarginPx(const Psf& psf);

// The PSF `object` is drawn with at `scale` screen px per photo px.
Psf PsfOf(const scene::BlurredObject& object, double scale);

// `background` linear BGR (CV_32FC3); the layer composited over it ("over", premultiplied), in place.
void CompositeOver(cv::Mat& background_linear, const Layer& layer);

}  // namespace blurcue::render
