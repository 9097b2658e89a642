#include "core/distortion.h"

#include <cmath>

#include "core/error.h"

namespace blurcue {

LensDistortion::LensDistortion(const Camera& camera) {
  const std::array<double, 9> k = camera.Intrinsics();
  fx_ = k[0], fy_ = k[4], cx_ = k[2], cy_ = k[5];
  const std::vector<double>& d = camera.dist_coeffs;
  auto at = [&](size_t i) { return i < d.size() ? d[i] : 0.0; };
  // OpenCV's order: k1 k2 p1 p2 k3 k4 k5 k6 s1 s2 s3 s4 tau_x tau_y.
  k_[0] = at(0), k_[1] = at(1), p_[0] = at(2), p_[1] = at(3), k_[2] = at(4);
  k_[3] = at(5), k_[4] = at(6), k_[5] = at(7);
  for (int i = 0; i < 4; ++i) s_[i] = at(8 + i);
  for (double c : d) identity_ = identity_ && c == 0;
  const double tau_x = at(12), tau_y = at(13);
  tilt_ = tau_x != 0 || tau_y != 0;
  if (tilt_) {
    // cv::detail::computeTiltProjectionMatrix: R = Ry(tau_y) Rx(tau_x), then the projection back onto z = 1.
    const double cx = std::cos(tau_x), sx = std::sin(tau_x), cy = std::cos(tau_y), sy = std::sin(tau_y);
    const double rx[9] = {1, 0, 0, 0, cx, sx, 0, -sx, cx};
    const double ry[9] = {cy, 0, -sy, 0, 1, 0, sy, 0, cy};
    double r[9];
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        r[3 * i + j] = 0;
        for (int m = 0; m < 3; ++m) r[3 * i + j] += ry[3 * i + m] * rx[3 * m + j];
      }
    const double proj[9] = {r[8], 0, -r[2], 0, r[8], -r[5], 0, 0, 1};
    for (int i = 0; i < 3; ++i)
      for (int j = 0; j < 3; ++j) {
        tilt_matrix_[3 * i + j] = 0;
        for (int m = 0; m < 3; ++m) tilt_matrix_[3 * i + j] += proj[3 * i + m] * r[3 * m + j];
      }
  }
}

Point2 LensDistortion::DistortNormalized(double x, double y, Jacobian2* jac) const {
  const double r2 = x * x + y * y, r4 = r2 * r2, r6 = r4 * r2;
  const double num = 1 + k_[0] * r2 + k_[1] * r4 + k_[2] * r6, den = 1 + k_[3] * r2 + k_[4] * r4 + k_[5] * r6;
  const double radial = num / den;
  const double xd = x * radial + 2 * p_[0] * x * y + p_[1] * (r2 + 2 * x * x) + s_[0] * r2 + s_[1] * r4;
  const double yd = y * radial + p_[0] * (r2 + 2 * y * y) + 2 * p_[1] * x * y + s_[2] * r2 + s_[3] * r4;
  Jacobian2 j{};
  if (jac) {
    // d radial / d r2, then the chain through r2 = x^2 + y^2.
    const double dnum = k_[0] + 2 * k_[1] * r2 + 3 * k_[2] * r4, dden = k_[3] + 2 * k_[4] * r2 + 3 * k_[5] * r4;
    const double drad = (dnum * den - num * dden) / (den * den);
    const double sx = s_[0] + 2 * s_[1] * r2, sy = s_[2] + 2 * s_[3] * r2;  // d (s r2 + s' r4) / d r2
    j[0] = radial + 2 * x * x * drad + 2 * p_[0] * y + 6 * p_[1] * x + 2 * x * sx;
    j[1] = 2 * x * y * drad + 2 * p_[0] * x + 2 * p_[1] * y + 2 * y * sx;
    j[2] = 2 * x * y * drad + 2 * p_[0] * x + 2 * p_[1] * y + 2 * x * sy;
    j[3] = radial + 2 * y * y * drad + 6 * p_[0] * y + 2 * p_[1] * x + 2 * y * sy;
  }
  if (!tilt_) {
    if (jac) *jac = j;
    return {xd, yd};
  }
  const auto& h = tilt_matrix_;
  const double v0 = h[0] * xd + h[1] * yd + h[2], v1 = h[3] * xd + h[4] * yd + h[5], v2 = h[6] * xd + h[7] * yd + h[8];
  const double inv = v2 != 0 ? 1 / v2 : 1;
  if (jac) {
    // d (v0 / v2, v1 / v2) / d (xd, yd), then times j.
    const double a = (h[0] * v2 - v0 * h[6]) * inv * inv, b = (h[1] * v2 - v0 * h[7]) * inv * inv;
    const double c = (h[3] * v2 - v1 * h[6]) * inv * inv, e = (h[4] * v2 - v1 * h[7]) * inv * inv;
    *jac = {a * j[0] + b * j[2], a * j[1] + b * j[3], c * j[0] + e * j[2], c * j[1] + e * j[3]};
  }
  return {v0 * inv, v1 * inv};
}

Point2 LensDistortion::Distort(const Point2& p) const {
  if (identity_) return p;
  const Point2 d = DistortNormalized((p[0] - cx_) / fx_, (p[1] - cy_) / fy_, nullptr);
  return {fx_ * d[0] + cx_, fy_ * d[1] + cy_};
}

Jacobian2 LensDistortion::JacobianAt(const Point2& p) const {
  if (identity_) return {1, 0, 0, 1};
  Jacobian2 j;
  DistortNormalized((p[0] - cx_) / fx_, (p[1] - cy_) / fy_, &j);
  // Normalized -> px on both sides: diag(fx, fy) J diag(1/fx, 1/fy).
  return {j[0], j[1] * fx_ / fy_, j[2] * fy_ / fx_, j[3]};
}

Point2 LensDistortion::Undistort(const Point2& image_px) const {
  if (identity_) return image_px;
  const double tx = (image_px[0] - cx_) / fx_, ty = (image_px[1] - cy_) / fy_;
  // Newton from the distorted point itself (the ideal point is near it for any real lens).
  double x = tx, y = ty;
  for (int it = 0; it < 50; ++it) {
    Jacobian2 j;
    const Point2 d = DistortNormalized(x, y, &j);
    const double ex = d[0] - tx, ey = d[1] - ty;
    if (std::hypot(ex * fx_, ey * fy_) < 1e-9) return {fx_ * x + cx_, fy_ * y + cy_};
    const double det = j[0] * j[3] - j[1] * j[2];
    if (!(std::abs(det) > 1e-12))
      throw Error(ErrorKind::kDomain, "dist_coeffs fold the image over near pixel (" + Num(image_px[0]) + ", " +
                                          Num(image_px[1]) + "): the distortion cannot be undone there");
    double dx = (j[3] * ex - j[1] * ey) / det, dy = (-j[2] * ex + j[0] * ey) / det;
    // A damped step where the map bends hard: never farther than the point is from the centre.
    const double limit = 0.5 * (1 + std::hypot(x, y)), len = std::hypot(dx, dy);
    if (len > limit) dx *= limit / len, dy *= limit / len;
    x -= dx, y -= dy;
  }
  throw Error(ErrorKind::kDomain, "dist_coeffs cannot be undone at pixel (" + Num(image_px[0]) + ", " +
                                      Num(image_px[1]) + "): no ideal point distorts to it (Newton did not converge)");
}

double LensDistortion::StretchAcross(const Point2& ideal_px, const Point2& normal) const {
  const double len = std::hypot(normal[0], normal[1]);
  if (identity_ || !(len > 0)) return 1;
  const Jacobian2 j = JacobianAt(ideal_px);
  const double det = j[0] * j[3] - j[1] * j[2];
  const double nx = normal[0] / len, ny = normal[1] / len;
  // J^-T n = (1 / det) (j3 nx - j2 ny, -j1 nx + j0 ny).
  const double mx = (j[3] * nx - j[2] * ny) / det, my = (-j[1] * nx + j[0] * ny) / det;
  return 1 / std::hypot(mx, my);
}

double LensDistortion::StretchIsotropic(const Point2& ideal_px) const {
  if (identity_) return 1;
  const Jacobian2 j = JacobianAt(ideal_px);
  return std::sqrt(std::abs(j[0] * j[3] - j[1] * j[2]));
}

}  // namespace blurcue
