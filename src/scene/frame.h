#pragma once
// A stimulus frame's layout, without GL: the objects it shows with their blur, where it shows the camera's photo
// (FrameView), how it fits a window (FitScale), and the depth-matching study's frame (DepthMatchingLayout).
#include <functional>
#include <string>

#include <opencv2/core.hpp>

#include "core/camera.h"
#include "scene/objects.h"

namespace blurcue::scene {

// An object with the blur it is drawn with: one radius, or a radius per camera depth.
struct BlurredObject {
  VirtualObject object;
  std::string method = "gaussian";  // "gaussian" or "disc"
  // The radius of its PSF without the motion, in the camera's (photo) px, as the measurement states it (2 x the std
  // of the line-spread function of defocus x lens floor); drawn at r_px x the view's scale in screen px.
  double r_px = 0;
  // The scene's lens floor inside r_px (std, photo px; 0: none): a pillbox defocus is drawn convolved with it.
  double floor_sigma_px = 0;
  // The motion blur: where the object moves in the image during the exposure (photo px, x right, y down; 0: none).
  cv::Vec2d motion_px{0, 0};
  // The per-pixel plan: the radius (photo px) at a camera depth (mm), each pixel blurred by its own depth
  // (BlurLayerVarying); empty: r_px everywhere.
  std::function<double(double)> r_of_depth_px;
  // Where the photo's lens distortion stretches its blur unequally (docs/distortion.md; last, so that
  // aggregate initialisers of the fields above keep their order): the map, of determinant 1, the
  // round PSF is drawn through (calib::ShapeAt; render::Psf::shape); identity: round. r_px is then the geometric
  // mean of the principal radii, and the radius across an edge of normal n is r_px |shape^T n|.
  cv::Matx22d shape{1, 0, 0, 1};
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

// The scale at which a src_w x src_h frame is shown in a width_px x height_px window: fitted whole, letterboxed,
// its shown width floored to whole pixels (screen px per frame px). What BlitToWindow does, and what the record says.
double FitScale(int src_w, int src_h, int width_px, int height_px);

// The std of the Gaussian equivalent to a Butterworth low-pass at `cutoff` cycles per width, in widths: the Gaussian
// that also halves contrast at the cut-off (H(cutoff) = 1/2 for every order; exp(-2 pi^2 s^2 f^2) = 1/2 there), so
// s = sqrt(ln 2 / 2) / (pi cutoff) ~ 0.187 / cutoff; its blurcue radius is r = 2 s. The Butterworth's line-spread
// function has no usable second moment (a 2nd-order one's is zero: H = 1 - (f/fc)^4 + ...), so r = 2 std cannot
// define it; other equivalences land within 7 % of this one (equal area under the transfer: 0.180 / cutoff; the
// same 10-90 % edge rise: 0.175 / cutoff, checked against ButterworthBlurCpu in render_test).
double ButterworthEquivalentSigma(double cutoff_cycles_per_width);

// Where render's PictureOnGrey and PictureOnField put a picture: the one definition they and DepthMatchingLayout
// share.
// A picture's width when scaled to height_px (its aspect kept, rounded, at least 1 px).
int ScaledWidthPx(cv::Size picture, int height_px);
// Where PictureOnField puts a layer of `layer` size: centred on the field (it may overhang).
cv::Rect LayerOnField(cv::Size field, cv::Size layer);
// PictureOnGrey's transparent margin around a picture of `scaled` size: room for its blur to spread.
int GreyMarginPx(cv::Size scaled);

// The depth-matching study's frame (thesis 3.2) of width_px showing a picture of `picture` size, in frame px: the
// frame (width x 3/4 width); its upper half, grey, with the virtual picture's outline (before the blur spreads it)
// centred in it at 0.6 of its height (PictureOnGrey's place, with its rounding); its lower half, the real photo
// scaled to cover it and cropped at its centre.
struct DepthMatchingLayout {
  cv::Size frame;
  cv::Rect upper, picture, lower;  // `picture` empty for an empty picture size
  static DepthMatchingLayout Of(int width_px, cv::Size picture);
  // The scale (frame px per photo px) at which the lower half shows a photo of `photo` size, and that photo there
  // (8-bit BGR of lower's size).
  double LowerScale(cv::Size photo) const;
  cv::Mat LowerHalf(const cv::Mat& photo) const;
};

}  // namespace blurcue::scene
