#pragma once
// The camera's lens distortion (camera.json's dist_coeffs, OpenCV's model and order: k1 k2 p1 p2 [k3 [k4 k5 k6
// [s1 s2 s3 s4 [tau_x tau_y]]]]) as a map from the ideal (pinhole) image to the photo, its Jacobian and the local
// stretch it gives a blur. Pixel coordinates follow OpenCV (pixel centres at integers); "ideal px" are where the
// camera_matrix alone (no distortion) puts a point, "image px" are the photo's. Like cv::projectPoints, the skew of
// camera_matrix is ignored.
#include <array>

#include "core/camera.h"

namespace blurcue {

using Point2 = std::array<double, 2>;
// Row-major 2x2: {d out_x / d in_x, d out_x / d in_y, d out_y / d in_x, d out_y / d in_y}.
using Jacobian2 = std::array<double, 4>;

class LensDistortion {
 public:
  explicit LensDistortion(const Camera& camera);

  // True when every coefficient is 0 (or none is given): the photo is the ideal image.
  bool Identity() const { return identity_; }
  // Ideal px -> image px.
  Point2 Distort(const Point2& ideal_px) const;
  // Image px -> ideal px (Newton on Distort, to 1e-9 px). Throws Error(kDomain) where the map folds over (its
  // Jacobian is singular) or does not converge: a distortion that no lens makes there.
  Point2 Undistort(const Point2& image_px) const;
  // d image px / d ideal px at an ideal point (exact, from the model's derivatives).
  Jacobian2 JacobianAt(const Point2& ideal_px) const;

  // How much the photo stretches a blur across an edge through `ideal_px` whose normal in the ideal image is
  // `normal_ideal` (any length): s = 1 / |J^-T n| with n the unit normal. A line-spread function of std sigma (ideal
  // px) across that edge has std s sigma (image px) in the photo, measured along the edge's normal there.
  double StretchAcross(const Point2& ideal_px, const Point2& normal_ideal) const;
  // The stretch of a round blur at an ideal point, one number: sqrt(det J), the geometric mean of the stretches
  // along the map's two principal directions (it keeps the blur's area). What an isotropic kernel drawn at that
  // place of the photo is scaled by.
  double StretchIsotropic(const Point2& ideal_px) const;

 private:
  // Normalized ideal (x, y) -> normalized distorted, and its Jacobian when `jac` is given.
  Point2 DistortNormalized(double x, double y, Jacobian2* jac) const;

  bool identity_ = true;
  double fx_ = 1, fy_ = 1, cx_ = 0, cy_ = 0;
  // k1..k6, p1, p2, s1..s4; tilt matrix (row-major 3x3, identity without tau).
  double k_[6] = {0, 0, 0, 0, 0, 0}, p_[2] = {0, 0}, s_[4] = {0, 0, 0, 0};
  bool tilt_ = false;
  std::array<double, 9> tilt_matrix_{1, 0, 0, 0, 1, 0, 0, 0, 1};
};

}  // namespace blurcue
