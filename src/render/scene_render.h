#pragma once
// Virtual content placed in a calibrated scene's board frame (mm), drawn with GL into a layer that covers only the
// object's pixels plus the blur kernel's margin (model no more than a scene needs), blurred, and composited over
// the photo in linear light.
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include "core/board.h"
#include "core/camera.h"

namespace blurcue::render {

// An object's surface texture: an 8-bit sRGB image (BGR/BGRA) with an identity of its own. The renderer keeps one GL
// texture per identity, made the first time it is drawn; an image's address is no identity (freed pixels come back
// as another image's), an id is never handed out twice in a process. Make one per image, once, and copy it freely
// (the pixels are shared); a new SurfaceTexture of the same pixels is a new texture to the renderer.
class SurfaceTexture {
 public:
  SurfaceTexture() = default;
  explicit SurfaceTexture(cv::Mat image);
  const cv::Mat& image() const { return image_; }
  uint64_t id() const { return id_; }
  bool empty() const { return image_.empty(); }

 private:
  cv::Mat image_;
  uint64_t id_ = 0;
};

struct VirtualObject {
  enum class Kind { kCard, kBall };
  Kind kind = Kind::kBall;
  // Card: centre of the card; ball: centre of the sphere.
  cv::Vec3d center_board_mm{0, 0, 10};
  double size_mm = 10;  // card: its width; ball: radius
  // Card: its height along its texture's rows (0: square); upright on the table facing the camera (its face towards
  // -y, its texture's top up) or lying flat (texture's top towards +y); turned about the vertical axis by
  // rotation_deg (counter-clockwise seen from above).
  double card_height_mm = 0;
  bool standing = false;
  double rotation_deg = 0;
  SurfaceTexture texture;  // equirectangular for a ball, the card's face for a card
  double brightness = 1.0, contrast = 1.0;
  cv::Vec3d white_balance{1, 1, 1};  // gains of red, green, blue in linear light (after brightness and contrast)
  double spin_deg = 0;  // rotation of a ball about the board's x axis (rolling along y)
};

// Poses on the calibrated board (board frame, mm): the one definition every command places objects with (run,
// preview, render, animate, bench). A 2 x 2-square card lying on the table beside the board, left or right of it, its
// centre on edge `edge`'s line (test 1); a ball of `radius_mm` resting on section `section` (1-based, centred
// across it) at y_mm along the board, turned as if rolled there from from_y_mm without slipping (tests 2 and 3).
// Texture, brightness and contrast are left to the caller.
// `size_mm` > 0: a card of that width (its centre as far beside the board); 0: two squares wide.
VirtualObject CardBesideBoard(const Board& board, int edge, bool left, double size_mm = 0);

// A card's four corners in the board frame (mm): top-left, top-right, bottom-right, bottom-left of its texture - the
// one definition of its pose that drawing, footprints and outlines use.
std::vector<cv::Point3d> CardCorners(const VirtualObject& card);
VirtualObject BallOnBoard(const Board& board, int section, double y_mm, double radius_mm, double from_y_mm);

// Where the object lands in the photo, and how far it spans in depth.
struct Footprint {
  cv::Rect bounds;  // the image pixels it may cover (not clipped): its corners' box (card), its outline's box (ball)
  double z_min_mm = 0, z_max_mm = 0, z_center_mm = 0;
};

// An object drawn alone: premultiplied linear RGBA (CV_32FC4, BGRA order like OpenCV) over `roi` of the photo.
struct Layer {
  cv::Rect roi;
  cv::Mat bgra;
  cv::Mat depth_mm;  // CV_32F camera z of the object's surface per pixel, 0 where it does not cover
};

// Where `object` lands in `camera`'s image (board frame -> camera by rvec/tvec), without GL.
Footprint FootprintOf(const Camera& camera, const cv::Vec3d& rvec, const cv::Vec3d& tvec, const VirtualObject& object);
// The object's silhouette in `camera`'s image as a polygon (image px, centres at integers): a card's four corners,
// a ball's outline circle (the sphere's rim as seen from the camera's centre) at `points` points. No GL.
std::vector<cv::Point2d> OutlineOf(const Camera& camera, const cv::Vec3d& rvec, const cv::Vec3d& tvec,
                                   const VirtualObject& object, int points = 64);

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

  Footprint Measure(const VirtualObject& object) const;
  // Draws from now on as `camera` sees (the same pose): a view of the photo scaled and placed (Camera::Viewed).
  void SetCamera(const Camera& camera);
  // Draws the object into a layer covering its bounds grown by margin_px, clipped to the image.
  Layer Draw(const VirtualObject& object, int margin_px);
  // The same, left on the GPU for frame composition, in targets the renderer made once and grows (a frame loop
  // allocates nothing); the per-pixel depth only when `depth_map` (the depth-varying blur needs it; a frame of
  // single-radius objects does not pay for it).
  GpuLayer DrawToTexture(const VirtualObject& object, int margin_px, bool depth_map = false);
  // Where a layer of the object with that margin lies in the image (its bounds grown, clipped; empty: off-screen).
  cv::Rect LayerRoi(const VirtualObject& object, int margin_px) const;
  // Draws the object's layer over image rectangle `roi` into `color` (and its depth into `depth` when given) with its
  // top-left image pixel at texel `at`: many layers side by side in one target, drawn in one go. The targets must
  // already hold at + roi's size (GrowingTarget::Reserve first): growing one would lose the layers it holds.
  void DrawLayerAt(const VirtualObject& object, const cv::Rect& roi, GrowingTarget& color, GrowingTarget* depth,
                   cv::Point at);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Blurs a layer in place with one radius: "gaussian" (s = r/2) or "disc", on the GL path when `gl` is given
// (CPU reference otherwise). The layer's margin must cover the kernel.
class GlBlur;
void BlurLayer(Layer& layer, const std::string& method, double r_px, GlBlur* gl);

// Depth-varying blur: each pixel of the object gets r_of_depth(its camera z); pixels the blur spreads into take
// the r of the nearest covered pixel. The layer is blurred at radius levels 0.5 px apart and each pixel mixes its
// two nearest levels so the variance (r^2 / 4) is exact. Margin must cover r at the largest depth.
void BlurLayerVarying(Layer& layer, const std::string& method, const std::function<double(double)>& r_of_depth,
                      GlBlur* gl);

// The margin (px) a blur of radius r needs around an object: the kernel's half-width.
int KernelMarginPx(const std::string& method, double r_px);

// `background` linear BGR (CV_32FC3); the layer composited over it ("over", premultiplied), in place.
void CompositeOver(cv::Mat& background_linear, const Layer& layer);

}  // namespace blurcue::render
