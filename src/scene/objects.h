#pragma once
// Virtual content placed in a calibrated scene's board frame (mm): what an object is, where it stands, and where it
// lands in a camera's image - without GL (render draws it; stimulus plans with it).
#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "core/board.h"
#include "core/camera.h"

namespace blurcue::scene {

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

// A card or a ball in the board frame (mm), with its texture and its colour adjustments.
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
VirtualObject BallOnBoard(const Board& board, int section, double y_mm, double radius_mm, double from_y_mm);

// A card's axes in the board frame, each scaled to its extent: along its width (u), towards its texture's top (v),
// and its unit normal (n).
struct CardAxes {
  cv::Vec3d u, v, n;
};
// The axes of card `o` from its size, height, standing and rotation (its centre not included).
CardAxes AxesOf(const VirtualObject& o);

// A card's four corners in the board frame (mm): top-left, top-right, bottom-right, bottom-left of its texture - the
// one definition of its pose that drawing, footprints and outlines use.
std::vector<cv::Point3d> CardCorners(const VirtualObject& card);

// Where the object lands in the photo, and how far it spans in depth.
struct Footprint {
  // The image pixels it may cover (not clipped): its corners' box (card), its outline's box (ball); under distortion
  // the box of both its exact outline and the one LocalImageMap draws.
  cv::Rect bounds;
  // The camera z (mm) of its visible surface, nearest and farthest (a ball's: its cap facing the camera, whose rim
  // lies nearer than its centre unless it sits well off the axis), and of its centre.
  double z_min_mm = 0, z_max_mm = 0, z_center_mm = 0;
};

// Where `object` lands in `camera`'s image (board frame -> camera by rvec/tvec), without GL.
Footprint FootprintOf(const Camera& camera, const cv::Vec3d& rvec, const cv::Vec3d& tvec, const VirtualObject& object);
// How an object is drawn through the camera's lens distortion (camera.json's dist_coeffs): by the distortion's local
// affine map at its centre, photo px = A ideal px + t (A the Jacobian there, t putting the centre where the lens puts
// it), applied to its whole pinhole image, so that its shape and its blur (render::Psf::shape) are stretched by the
// same map. Exact at the centre; a card of 100 px at a k1 = -0.3 corner bends by ~1.5 px at its corners, which the
// affine map leaves straight. The identity (A = I, t = 0) without distortion.
cv::Matx23d LocalImageMap(const Camera& camera, const cv::Vec3d& rvec, const cv::Vec3d& tvec, const VirtualObject& object);

// The object's silhouette in `camera`'s image as a polygon (image px, centres at integers): a card's four corners,
// a ball's outline circle (the sphere's rim as seen from the camera's centre) at `points` points. No GL.
std::vector<cv::Point2d> OutlineOf(const Camera& camera, const cv::Vec3d& rvec, const cv::Vec3d& tvec,
                                   const VirtualObject& object, int points = 64);

}  // namespace blurcue::scene
