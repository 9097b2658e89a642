// The PSF's kernel against its analytic second moments, and the GL pass against the CPU reference (label "gl": runs
// on Mesa's llvmpipe through EGL with no display).
#include "render/psf.h"

#include <gtest/gtest.h>

#include <cmath>

#include "core/error.h"
#include "render/blur.h"
#include "render/gl_context.h"

#include <opencv2/imgproc.hpp>

namespace blurcue::render {
namespace {

// The kernel's covariance (px^2) about its centroid: xx, yy, xy; and its centroid.
struct Moments {
  double xx = 0, yy = 0, xy = 0, cx = 0, cy = 0, sum = 0;
};
Moments Of(const cv::Mat& k) {
  Moments m;
  for (int y = 0; y < k.rows; ++y)
    for (int x = 0; x < k.cols; ++x) {
      const double w = k.at<float>(y, x);
      m.sum += w, m.cx += w * x, m.cy += w * y;
    }
  m.cx /= m.sum, m.cy /= m.sum;
  for (int y = 0; y < k.rows; ++y)
    for (int x = 0; x < k.cols; ++x) {
      const double w = k.at<float>(y, x) / m.sum, dx = x - m.cx, dy = y - m.cy;
      m.xx += w * dx * dx, m.yy += w * dy * dy, m.xy += w * dx * dy;
    }
  return m;
}

Psf Make(const char* method, double r, double floor, cv::Vec2d motion = {0, 0}) {
  Psf p;
  p.method = method, p.r_px = r, p.floor_sigma_px = floor, p.motion_px = motion;
  return p;
}

TEST(Psf, PillboxWithFloorHasTheStatedRadius) {
  // r^2 = R^2 + 4 f^2: the whole kernel's line-spread variance is r^2 / 4 across x and y, from sub-pixel up.
  for (double r : {0.3, 0.7, 1.2, 3.0, 9.5})
    for (double f : {0.1, 0.35, 0.6}) {
      const Moments m = Of(PsfKernel(Make("disc", r, f)));
      EXPECT_NEAR(m.sum, 1, 1e-5);
      EXPECT_NEAR(2 * std::sqrt(m.xx), r, 1e-3 * r) << "r " << r << " floor " << f;
      EXPECT_NEAR(2 * std::sqrt(m.yy), r, 1e-3 * r) << "r " << r << " floor " << f;
      EXPECT_NEAR(m.xy, 0, 1e-6);
    }
}

TEST(Psf, FloorBeyondTheRadiusIsTheWholeRadius) {
  const Psf p = Make("disc", 0.5, 0.4);  // 2 f = 0.8 > r: no defocus left, the floor drawn as r / 2
  EXPECT_DOUBLE_EQ(p.DefocusRadiusPx(), 0);
  EXPECT_DOUBLE_EQ(p.FloorSigmaPx(), 0.25);
  EXPECT_NEAR(2 * std::sqrt(Of(PsfKernel(p)).xx), 0.5, 1e-3);
}

TEST(Psf, PillboxWithFloorIsWiderTailedThanThePillbox) {
  // Same second moment, other shape: the floor rounds the pillbox's rim (its corner tap is no longer 0).
  const cv::Mat plain = PsfKernel(Make("disc", 3, 0)), floored = PsfKernel(Make("disc", 3, 0.8));
  EXPECT_GT(floored.rows, plain.rows);
  EXPECT_NEAR(Of(plain).xx, Of(floored).xx, 1e-3);
}

TEST(Psf, StreakAddsItsLengthSquaredOverTwelveAlongTheMotion) {
  // A horizontal streak of 6 px on a Gaussian of r 1: var_x = 1/4 + 36/12, var_y = 1/4.
  Moments m = Of(PsfKernel(Make("gaussian", 1, 0, {6, 0})));
  EXPECT_NEAR(m.xx, 0.25 + 3, 1e-3);
  EXPECT_NEAR(m.yy, 0.25, 1e-3);
  EXPECT_NEAR(m.cx, m.cy, 1e-6);  // centred
  // Diagonal and nearly vertical ones on a pillbox with a floor and on a Gaussian: across the motion exactly r^2 / 4,
  // along it r^2 / 4 + L^2 / 12 (the spreading's own variance taken out of the floor or the defocus).
  for (const Psf& p : {Make("disc", 2, 0.3, {3, 4}), Make("disc", 2, 0, {3, 4}), Make("gaussian", 1.1, 0, {0.11, 1.43}),
                       Make("disc", 1.2, 0.6, {-0.4, 6.5})}) {
    m = Of(PsfKernel(p));
    const double l = p.MotionLengthPx(), c = p.motion_px[0] / l, s = p.motion_px[1] / l;
    const double along = c * c * m.xx + s * s * m.yy + 2 * c * s * m.xy;
    const double across = s * s * m.xx + c * c * m.yy - 2 * c * s * m.xy;
    EXPECT_NEAR(across, p.r_px * p.r_px / 4, 2e-3) << p.method << " " << p.motion_px;
    EXPECT_NEAR(along, p.r_px * p.r_px / 4 + l * l / 12, 2e-3) << p.method << " " << p.motion_px;
  }
  // Sub-pixel streaks too.
  for (double length : {0.3, 0.8, 1.7}) {
    m = Of(StreakKernel({0, length}));
    EXPECT_NEAR(m.yy, length * length / 12, 1e-4) << length;
    EXPECT_NEAR(m.xx, 0, 1e-9);
  }
}

TEST(Psf, DrawnRadiusIsTheKernelsAcrossTheMotion) {
  // Under a streak a sub-pixel radius cannot be drawn thinner than the streak's sampling between pixel centres: the
  // radius the record states (DrawnRadiusPx) is the one the kernel has across the motion, from its own moments.
  for (const cv::Vec2d motion : {cv::Vec2d(0.452, 5.697), cv::Vec2d(3, 4), cv::Vec2d(-2.2, 0.7), cv::Vec2d(6, 0)})
    for (double r : {0.0, 0.3, 0.7, 1.5}) {
      const Psf p = Make("gaussian", r, 0, motion);
      const Moments m = Of(PsfKernel(p));
      const double l = p.MotionLengthPx(), c = motion[0] / l, s = motion[1] / l;
      const double across = s * s * m.xx + c * c * m.yy - 2 * c * s * m.xy;
      EXPECT_NEAR(DrawnRadiusPx(p), 2 * std::sqrt(across), 2e-3) << motion << " r " << r;
      EXPECT_GE(DrawnRadiusPx(p), r);
      // Drawn with its drawn radius, the kernel is the same.
      Psf drawn = p;
      drawn.r_px = DrawnRadiusPx(p);
      EXPECT_LT(cv::norm(PsfKernel(drawn), PsfKernel(p), cv::NORM_INF), 1e-6) << motion << " r " << r;
    }
  // Along an axis the streak's samples sit on pixel centres across it: nothing added.
  EXPECT_DOUBLE_EQ(DrawnRadiusPx(Make("gaussian", 0, 0, {6, 0})), 0);
  EXPECT_DOUBLE_EQ(DrawnRadiusPx(Make("gaussian", 0.3, 0, {0, 0})), 0.3);
}

// The unit-determinant map stretching by s along the direction at angle t (rad) and by 1 / s across it.
cv::Matx22d Shape(double s, double t) {
  const double c = std::cos(t), n = std::sin(t);
  const cv::Matx22d rot(c, -n, n, c);
  return rot * cv::Matx22d(s, 0, 0, 1 / s) * rot.t();
}

TEST(Psf, ShapedKernelHasTheEllipsesSecondMoments) {
  // Covariance r^2 / 4 x S S^T, worked by hand for S stretching by s along angle t and 1 / s across:
  // xx = r^2 / 4 (s^2 cos^2 t + sin^2 t / s^2), yy = r^2 / 4 (s^2 sin^2 t + cos^2 t / s^2),
  // xy = r^2 / 4 (s^2 - 1 / s^2) cos t sin t. Gaussian and pillbox with a floor, sub-pixel up, with a streak too.
  for (const char* method : {"gaussian", "disc"})
    for (double r : {0.3, 0.8, 2.0, 6.0})
      for (const auto& [st, t] : {std::pair{1.08, 0.6}, std::pair{0.93, 0.0}, std::pair{1.2, M_PI / 2}}) {
        Psf p = Make(method, r, 0.3 * r);
        p.shape = Shape(st, t);
        const Moments m = Of(PsfKernel(p));
        const double q = r * r / 4, c = std::cos(t), n = std::sin(t);
        const double tol = std::max(1.5e-3, 5e-3 * q);
        EXPECT_NEAR(m.sum, 1, 1e-5);
        EXPECT_NEAR(m.xx, q * (st * st * c * c + n * n / (st * st)), tol) << method << " r " << r << " s " << st;
        EXPECT_NEAR(m.yy, q * (st * st * n * n + c * c / (st * st)), tol) << method << " r " << r << " s " << st;
        EXPECT_NEAR(m.xy, q * (st * st - 1 / (st * st)) * c * n, tol) << method << " r " << r << " s " << st;
        EXPECT_NEAR(p.RadiusAcrossPx({1, 0}), r * std::sqrt(st * st * c * c + n * n / (st * st)), 1e-12);
      }
  // With a horizontal streak of 4 px: the streak's L^2 / 12 on top along x.
  Psf p = Make("gaussian", 2, 0, {4, 0});
  p.shape = Shape(1.1, 0.3);
  const Moments m = Of(PsfKernel(p));
  const double c = std::cos(0.3), n = std::sin(0.3);
  EXPECT_NEAR(m.xx, 1.0 * (1.21 * c * c + n * n / 1.21) + 16.0 / 12, 3e-3);
  EXPECT_NEAR(m.yy, 1.0 * (1.21 * n * n + c * c / 1.21), 3e-3);
  EXPECT_GE(PsfHalfWidth(p), PsfKernel(p).rows / 2);
}

TEST(Psf, RefusesAShapeThatChangesTheArea) {
  Psf p = Make("gaussian", 1, 0);
  p.shape = cv::Matx22d(1.1, 0, 0, 1);
  EXPECT_THROW(PsfKernel(p), Error);
  p.shape = cv::Matx22d(std::nan(""), 0, 0, 1);
  EXPECT_THROW(PsfKernel(p), Error);
}

TEST(Psf, RefusesNanAndUnknownShapes) {
  EXPECT_THROW(PsfKernel(Make("disc", 1, std::nan(""))), Error);
  EXPECT_THROW(PsfKernel(Make("disc", 1, 0, {std::nan(""), 0})), Error);
  EXPECT_THROW(PsfKernel(Make("box", 1, 0)), Error);
  EXPECT_THROW(PsfKernel(Make("gaussian", 1, 0, {600, 0})), Error);
}

TEST(Psf, HalfWidthHoldsTheKernel) {
  for (const Psf& p : {Make("disc", 0.4, 0.2), Make("disc", 5, 0.5, {7, -2}), Make("gaussian", 3, 0, {0.4, 9})})
    EXPECT_GE(PsfHalfWidth(p), PsfKernel(p).rows / 2);
  for (double st : {0.8, 1.05, 1.3})
    for (Psf p : {Make("disc", 0.4, 0.2), Make("disc", 5, 0.5, {7, -2}), Make("gaussian", 3, 0, {0.4, 9})}) {
      p.shape = Shape(st, 0.7);
      EXPECT_GE(PsfHalfWidth(p), PsfKernel(p).rows / 2) << st;
    }
}

TEST(PsfGl, GlPassEqualsCpuReference) {
  const auto context = GlContext::CreateOffscreen();
  cv::Mat img(48, 64, CV_32FC4, cv::Scalar(0, 0, 0, 0));
  img(cv::Rect(16, 12, 30, 20)).setTo(cv::Scalar(0.8, 0.5, 0.2, 1.0));
  img(cv::Rect(20, 14, 4, 10)).setTo(cv::Scalar(0.05, 0.05, 0.05, 1.0));
  GlBlur gl;
  Psf ellipse = Make("gaussian", 1.8, 0.4), ellipse_disc = Make("disc", 2.2, 0.5);
  ellipse.shape = Shape(1.15, 0.5), ellipse_disc.shape = Shape(0.87, -0.6);
  for (const Psf& p : {Make("disc", 2.5, 0.4), Make("gaussian", 1.5, 0, {5, 2}), Make("disc", 0.6, 0.2, {-0.5, 3}),
                       ellipse, ellipse_disc}) {
    cv::Mat cpu;
    cv::filter2D(img, cpu, CV_32F, PsfKernel(p), cv::Point(-1, -1), 0, cv::BORDER_REPLICATE);
    const cv::Mat shown = gl.BlurImage(img, p);
    EXPECT_LT(cv::norm(shown, cpu, cv::NORM_INF), 1e-5) << p.method << " r " << p.r_px;
  }
  // A kernel kept from the last call (the same PSF again) and one laid out anew after a round PSF in between.
  for (const Psf& p : {ellipse, ellipse, Make("gaussian", 1.0, 0), ellipse_disc, ellipse_disc}) {
    cv::Mat cpu;
    if (p.General())
      cv::filter2D(img, cpu, CV_32F, PsfKernel(p), cv::Point(-1, -1), 0, cv::BORDER_REPLICATE);
    else
      cpu = GaussianBlurCpu(img, p.r_px);
    EXPECT_LT(cv::norm(gl.BlurImage(img, p), cpu, cv::NORM_INF), 1e-5) << p.method << " r " << p.r_px;
  }
}

}  // namespace
}  // namespace blurcue::render
