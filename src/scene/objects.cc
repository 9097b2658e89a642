#include "scene/objects.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <utility>
#include <vector>

#include <opencv2/calib3d.hpp>

#include "core/distortion.h"

namespace blurcue::scene {

SurfaceTexture::SurfaceTexture(cv::Mat image) : image_(std::move(image)) {
  static std::atomic<uint64_t> next{1};
  id_ = next.fetch_add(1);
}

CardAxes AxesOf(const VirtualObject& o) {
  const double a = o.rotation_deg * M_PI / 180, c = std::cos(a), s = std::sin(a);
  const cv::Vec3d x(c, s, 0), y(-s, c, 0), z(0, 0, 1);
  const double w = o.size_mm, h = o.card_height_mm > 0 ? o.card_height_mm : o.size_mm;
  return o.standing ? CardAxes{w * x, h * z, -y} : CardAxes{w * x, h * y, z};
}

std::vector<cv::Point3d> CardCorners(const VirtualObject& o) {
  const CardAxes a = AxesOf(o);
  const cv::Vec3d c = o.center_board_mm;
  std::vector<cv::Point3d> corners;
  for (const auto& [su, sv] : {std::pair{-0.5, 0.5}, {0.5, 0.5}, {0.5, -0.5}, {-0.5, -0.5}}) {
    const cv::Vec3d p = c + su * a.u + sv * a.v;
    corners.emplace_back(p[0], p[1], p[2]);
  }
  return corners;
}

VirtualObject CardBesideBoard(const Board& board, int edge, bool left, double size_mm) {
  VirtualObject o;
  o.kind = VirtualObject::Kind::kCard;
  const double s = board.square_mm;
  o.size_mm = size_mm > 0 ? size_mm : 2 * s;
  o.center_board_mm = {left ? -s - o.size_mm / 2 : board.WidthMm() + s + o.size_mm / 2, (edge - 1) * s, 0};
  return o;
}

VirtualObject BallOnBoard(const Board& board, int section, double y_mm, double radius_mm, double from_y_mm) {
  VirtualObject o;
  o.kind = VirtualObject::Kind::kBall;
  o.size_mm = radius_mm;
  o.center_board_mm = {(section - 0.5) * board.square_mm, y_mm, radius_mm};
  o.spin_deg = -(y_mm - from_y_mm) / radius_mm * 180 / M_PI;  // rolling away from the camera without slipping
  return o;
}

cv::Matx23d LocalImageMap(const Camera& camera, const cv::Vec3d& rvec, const cv::Vec3d& tvec, const VirtualObject& o) {
  const LensDistortion distortion(camera);
  cv::Matx33d rotation;
  cv::Rodrigues(rvec, rotation);
  const cv::Vec3d c = rotation * o.center_board_mm + tvec;
  if (distortion.Identity() || !(c[2] > 0)) return cv::Matx23d(1, 0, 0, 0, 1, 0);
  const std::array<double, 9> k = camera.Intrinsics();
  const Point2 ideal{k[0] * c[0] / c[2] + k[2], k[4] * c[1] / c[2] + k[5]};
  const Point2 photo = distortion.Distort(ideal);
  const Jacobian2 j = distortion.JacobianAt(ideal);
  return cv::Matx23d(j[0], j[1], photo[0] - j[0] * ideal[0] - j[1] * ideal[1],  //
                     j[2], j[3], photo[1] - j[2] * ideal[0] - j[3] * ideal[1]);
}

Footprint FootprintOf(const Camera& camera, const cv::Vec3d& rvec, const cv::Vec3d& tvec, const VirtualObject& o) {
  cv::Matx33d rotation;
  cv::Rodrigues(rvec, rotation);
  Footprint f;
  f.z_center_mm = (rotation * o.center_board_mm + tvec)[2];
  std::vector<cv::Point2d> px;
  if (o.kind == VirtualObject::Kind::kBall) {
    // A sphere's pixels show its visible cap: from its nearest point (z_c - R) to the farthest point of its rim, the
    // circle where the lines of sight touch it (centre c (1 - R^2/|c|^2), radius R sqrt(1 - R^2/|c|^2), in the
    // plane normal to c). Its hidden back is never drawn, so its depth is not the object's. Its pixels hug its
    // outline (its bounding box's projection reaches far wider; a layer is blurred whole, so its area is a frame's
    // cost).
    const cv::Vec3d c = rotation * o.center_board_mm + tvec;
    const double d2 = c.dot(c), R = o.size_mm;
    f.z_min_mm = f.z_center_mm - R;
    if (d2 > R * R) {
      const double keep = 1 - R * R / d2, uz = c[2] / std::sqrt(d2);
      f.z_max_mm = c[2] * keep + R * std::sqrt(keep) * std::sqrt(std::max(0.0, 1 - uz * uz));
    } else {
      f.z_max_mm = f.z_center_mm + R;  // the camera inside the ball: every part of it may show
    }
    px = OutlineOf(camera, rvec, tvec, o, 64);
  } else {
    const std::vector<cv::Point3d> corners = CardCorners(o);
    cv::projectPoints(corners, rvec, tvec, cv::Matx33d(camera.Intrinsics().data()), camera.dist_coeffs, px);
    f.z_min_mm = 1e300, f.z_max_mm = -1e300;
    for (const cv::Point3d& c : corners) {
      const double z = (rotation * cv::Vec3d(c) + tvec)[2];
      f.z_min_mm = std::min(f.z_min_mm, z), f.z_max_mm = std::max(f.z_max_mm, z);
    }
  }
  if (!camera.dist_coeffs.empty() && !LensDistortion(camera).Identity()) {
    // What the renderer draws: the pinhole outline through the local affine map.
    Camera pinhole = camera;
    pinhole.dist_coeffs.clear();
    const cv::Matx23d a = LocalImageMap(camera, rvec, tvec, o);
    std::vector<cv::Point2d> drawn;
    if (o.kind == VirtualObject::Kind::kBall) {
      drawn = OutlineOf(pinhole, rvec, tvec, o, 64);
    } else {
      cv::projectPoints(CardCorners(o), rvec, tvec, cv::Matx33d(camera.Intrinsics().data()), cv::noArray(), drawn);
    }
    for (const cv::Point2d& p : drawn) px.push_back(cv::Point2d(a * cv::Vec3d(p.x, p.y, 1)));
  }
  double x0 = 1e300, y0 = 1e300, x1 = -1e300, y1 = -1e300;
  for (const cv::Point2d& p : px)
    x0 = std::min(x0, p.x), y0 = std::min(y0, p.y), x1 = std::max(x1, p.x), y1 = std::max(y1, p.y);
  // A ball's outline polygon has its points on the rim: the pad covers its sagitta (< 0.01 of the radius at 64
  // points). A card's corners are its extent.
  const double pad = o.kind == VirtualObject::Kind::kBall ? 0.01 * std::max(x1 - x0, y1 - y0) : 0;
  f.bounds = cv::Rect(cv::Point(int(std::floor(x0 - pad)) - 1, int(std::floor(y0 - pad)) - 1),
                      cv::Point(int(std::ceil(x1 + pad)) + 2, int(std::ceil(y1 + pad)) + 2));
  return f;
}

std::vector<cv::Point2d> OutlineOf(const Camera& camera, const cv::Vec3d& rvec, const cv::Vec3d& tvec,
                                   const VirtualObject& o, int points) {
  std::vector<cv::Point3d> rim;
  const cv::Vec3d c = o.center_board_mm;
  if (o.kind == VirtualObject::Kind::kCard) {
    rim = CardCorners(o);
  } else {
    // The rim the camera's centre sees: the circle where lines from the eye touch the sphere.
    cv::Matx33d rotation;
    cv::Rodrigues(rvec, rotation);
    const cv::Vec3d eye = -(rotation.t() * tvec);
    const cv::Vec3d to = c - eye;
    const double d = cv::norm(to), rho = o.size_mm;
    const cv::Vec3d u = to / d;
    const cv::Vec3d centre = c - u * (rho * rho / d);
    const double radius = rho * std::sqrt(std::max(0.0, 1 - rho * rho / (d * d)));
    cv::Vec3d a = u.cross(cv::Vec3d(1, 0, 0));
    if (cv::norm(a) < 1e-6) a = u.cross(cv::Vec3d(0, 1, 0));
    a = cv::normalize(a);
    const cv::Vec3d b = u.cross(a);
    for (int i = 0; i < points; ++i) {
      const double phi = 2 * M_PI * i / points;
      const cv::Vec3d p = centre + radius * (std::cos(phi) * a + std::sin(phi) * b);
      rim.emplace_back(p[0], p[1], p[2]);
    }
  }
  std::vector<cv::Point2d> px;
  cv::projectPoints(rim, rvec, tvec, cv::Matx33d(camera.Intrinsics().data()), camera.dist_coeffs, px);
  return px;
}

}  // namespace blurcue::scene
