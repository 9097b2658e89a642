#pragma once
// The point-spread function a virtual object is drawn with (DESIGN.md "Definitions", "Motion"): its depth's defocus
// (a Gaussian or a pillbox) convolved with the scene's lens floor (a Gaussian) and with the streak its motion
// leaves during the exposure, as one discrete 2-D kernel whose second moments are exactly the stated ones. Where the
// photo's lens distortion stretches the image unequally along and across (docs/distortion.md), the round PSF is drawn
// through the distortion's local linear map (`shape`): an elliptical kernel.
#include <string>

#include <opencv2/core.hpp>

namespace blurcue::render {

struct Psf {
  std::string method = "gaussian";  // the defocus's shape: "gaussian" or "disc"
  // The radius of defocus x floor (2 x the std of its line-spread function; r^2 = R^2 + 4 f^2 for a disc of radius R
  // and a floor of std f), the whole PSF's radius without the motion. A floor larger than r / 2 is r / 2 (no defocus).
  double r_px = 0;
  double floor_sigma_px = 0;  // the lens floor's std inside r_px (only shapes the kernel of a pillbox)
  cv::Vec2d motion_px{0, 0};  // the streak: where the object moves during the exposure (px, image x right, y down)
  // The linear map the round PSF (defocus x floor) is drawn through, of determinant 1: the lens distortion's Jacobian
  // at the object's place over sqrt(det J) (calib::ShapeAt); identity: round. The kernel's covariance is then
  // r^2 / 4 x shape shape^T, so r_px stays the round radius (the geometric mean of the principal radii).
  cv::Matx22d shape{1, 0, 0, 1};

  // The pillbox's radius R inside r_px: sqrt(r^2 - 4 f^2), 0 when the floor is the whole of r.
  double DefocusRadiusPx() const;
  // The floor's std as drawn: min(floor_sigma_px, r_px / 2).
  double FloorSigmaPx() const;
  double MotionLengthPx() const { return cv::norm(motion_px); }
  // Whether the shape is not the identity (an elliptical kernel).
  bool Stretched() const;
  // The radius (2 x the std of the line-spread function, without the motion) across an edge whose normal is
  // `normal` (any length): r |shape^T n|. (1, 0): across a vertical edge, the profile along x; (0, 1): along y.
  double RadiusAcrossPx(const cv::Vec2d& normal) const;
  // The lens floor's std as drawn across an edge whose normal is `normal`: FloorSigmaPx() |shape^T n|. The floor is
  // inside the round PSF the shape stretches, so it is stretched along and across as the photo's floor is there
  // (docs/distortion.md); floor_sigma_px is the round value (their geometric mean).
  double FloorAcrossPx(const cv::Vec2d& normal) const;
  // Whether it needs the general kernel (one 2-D pass): a streak, a pillbox with a floor, or a shape. Otherwise the
  // separable Gaussian or the pillbox pass draws it (a Gaussian defocus x a Gaussian floor is the Gaussian of r).
  bool General() const;
  bool operator==(const Psf& o) const;
  bool operator!=(const Psf& o) const { return !(*this == o); }
};

// Throws Error(kDomain) naming the value unless r, the floor and the streak are finite and within the largest blur
// (optics::kMaxBlurRadiusPx), the shape is finite with determinant 1 (to 1e-6) and stretches by at most 2, and the
// method is gaussian or disc.
void CheckPsf(const Psf& psf);

// The discrete kernel (CV_32F, (2 h + 1)^2, normalised, centred): the defocus kernel of blur.h (GaussianBlurCpu's
// sampled Gaussian of r / 2, or DiscKernel of R) convolved with the sampled Gaussian of the floor (GaussianKernelSigma:
// its variance is exactly f^2) and with the streak. Its line-spread variance is r^2 / 4 across and along any axis,
// plus |m|^2 / 12 along the motion m: the streak is the segment from -m/2 to m/2 sampled densely and each sample
// spread bilinearly over its four nearest pixels, the segment's drawn length chosen so that its variance along m is
// exactly |m|^2 / 12 (bilinear spreading adds a little of its own, up to 1/4 px^2 across a diagonal streak).
// A shape (an elliptical PSF, covariance r^2 / 4 x shape shape^T) is drawn as the round PSF at the ellipse's mean
// variance (trace / 2; its defocus and floor scaled alike) convolved with a small kernel carrying the ellipse's
// anisotropic part exactly (copies of one 3 x 3 kernel; the isotropic variance it adds is taken out of the round
// part): the kernel's covariance is exactly the ellipse's, from sub-pixel up; a pillbox's rim is softened a little.
cv::Mat PsfKernel(const Psf& psf);
// Its half-width h, without building it.
int PsfHalfWidth(const Psf& psf);

// The radius (2 x the std of the line-spread function) PsfKernel's kernel has across the motion: r_px, but for a
// sub-pixel r under a streak whose drawing spreads it more across (StreakKernel's across variance e > r^2 / 4: a
// streak between pixel centres cannot be thinner), 2 sqrt(e). What a frame shows, and so what the record states; a
// PSF with this radius is drawn with the same kernel.
double DrawnRadiusPx(const Psf& psf);

// The streak alone (normalised, centred, odd square), as PsfKernel makes it: its variance along the motion exceeds
// its variance across it (returned in across_px2 when given) by exactly |m|^2 / 12.
cv::Mat StreakKernel(const cv::Vec2d& motion_px, double* across_px2 = nullptr);

}  // namespace blurcue::render
