#include "core/distortion.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/calib3d.hpp>

#include "core/error.h"

namespace blurcue {
namespace {

Camera TestCamera(std::vector<double> dist) {
  Camera c = ThesisCamera().Resized(1148, 764);
  c.camera_matrix = std::array<double, 9>{1030, 0, 571.5, 0, 1020, 384.25, 0, 0, 1};
  c.dist_coeffs = std::move(dist);
  return c;
}

// Where OpenCV's own projection puts an ideal pixel (a ray through it, distorted by cv::projectPoints).
Point2 OpenCvDistort(const Camera& c, const Point2& ideal_px) {
  const auto k = c.Intrinsics();
  const cv::Point3d ray((ideal_px[0] - k[2]) / k[0], (ideal_px[1] - k[5]) / k[4], 1);
  std::vector<cv::Point2d> out;
  cv::projectPoints(std::vector<cv::Point3d>{ray}, cv::Vec3d(0, 0, 0), cv::Vec3d(0, 0, 0),
                    cv::Matx33d(k[0], 0, k[2], 0, k[4], k[5], 0, 0, 1), c.dist_coeffs, out);
  return {out[0].x, out[0].y};
}

const std::vector<std::vector<double>> kCoefficientSets = {
    {-0.12, 0, 0, 0},
    {0.05, 0, 0, 0, 0},
    {-0.2, 0.05, 0.001, -0.002, 0.01},
    {-0.1, 0.02, 0.0005, 0.001, -0.003, 0.02, -0.01, 0.004},
    {-0.1, 0.02, 0.0005, 0.001, -0.003, 0.02, -0.01, 0.004, 0.001, -0.002, 0.0015, 0.0008},
    {-0.1, 0.02, 0.0005, 0.001, -0.003, 0.02, -0.01, 0.004, 0.001, -0.002, 0.0015, 0.0008, 0.01, -0.02},
};
const std::vector<Point2> kPoints = {{0, 0}, {571.5, 384.25}, {1147, 763}, {100, 700}, {900, 50}, {300, 384}};

TEST(LensDistortion, DistortMatchesOpenCvProjectPoints) {
  for (const auto& d : kCoefficientSets) {
    const Camera c = TestCamera(d);
    const LensDistortion dist(c);
    for (const Point2& p : kPoints) {
      const Point2 ours = dist.Distort(p), theirs = OpenCvDistort(c, p);
      EXPECT_NEAR(ours[0], theirs[0], 1e-6) << d.size() << " coefficients at " << p[0] << "," << p[1];
      EXPECT_NEAR(ours[1], theirs[1], 1e-6) << d.size() << " coefficients at " << p[0] << "," << p[1];
    }
  }
}

TEST(LensDistortion, JacobianMatchesDifferencesOfOpenCv) {
  for (const auto& d : kCoefficientSets) {
    const Camera c = TestCamera(d);
    const LensDistortion dist(c);
    for (const Point2& p : kPoints) {
      const double h = 1e-3;
      const Point2 xp = OpenCvDistort(c, {p[0] + h, p[1]}), xm = OpenCvDistort(c, {p[0] - h, p[1]});
      const Point2 yp = OpenCvDistort(c, {p[0], p[1] + h}), ym = OpenCvDistort(c, {p[0], p[1] - h});
      const Jacobian2 numeric = {(xp[0] - xm[0]) / (2 * h), (yp[0] - ym[0]) / (2 * h), (xp[1] - xm[1]) / (2 * h),
                                 (yp[1] - ym[1]) / (2 * h)};
      const Jacobian2 j = dist.JacobianAt(p);
      for (int i = 0; i < 4; ++i) EXPECT_NEAR(j[i], numeric[i], 1e-6) << d.size() << " coefficients, entry " << i;
    }
  }
}

TEST(LensDistortion, UndistortInvertsDistortAndMatchesOpenCv) {
  for (const auto& d : kCoefficientSets) {
    const Camera c = TestCamera(d);
    const LensDistortion dist(c);
    const auto k = c.Intrinsics();
    for (const Point2& p : kPoints) {
      const Point2 ideal = dist.Undistort(p);
      const Point2 back = dist.Distort(ideal);
      EXPECT_NEAR(back[0], p[0], 1e-7);
      EXPECT_NEAR(back[1], p[1], 1e-7);
      std::vector<cv::Point2d> out;
      const cv::Matx33d km(k[0], 0, k[2], 0, k[4], k[5], 0, 0, 1);
      cv::undistortPoints(std::vector<cv::Point2d>{{p[0], p[1]}}, out, km, c.dist_coeffs, cv::noArray(), km,
                          cv::TermCriteria(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, 500, 1e-14));
      EXPECT_NEAR(ideal[0], out[0].x, 1e-4) << d.size() << " coefficients";
      EXPECT_NEAR(ideal[1], out[0].y, 1e-4) << d.size() << " coefficients";
    }
  }
}

// Pure radial k1: along the radius rho the map x (1 + k1 x^2) stretches by 1 + 3 k1 rho^2 (normalized), across it
// by 1 + k1 rho^2, by hand.
TEST(LensDistortion, StretchOfRadialDistortionByHand) {
  Camera c = TestCamera({-0.12, 0, 0, 0});
  c.camera_matrix = std::array<double, 9>{1000, 0, 574, 0, 1000, 382, 0, 0, 1};
  const LensDistortion dist(c);
  const double x = 0.5;  // normalized, on the horizontal through the principal point
  const Point2 p = {574 + 1000 * x, 382};
  EXPECT_NEAR(dist.StretchAcross(p, {1, 0}), 1 - 3 * 0.12 * x * x, 1e-12);  // edge across the radius
  EXPECT_NEAR(dist.StretchAcross(p, {0, 3}), 1 - 0.12 * x * x, 1e-12);      // edge along the radius
  EXPECT_NEAR(dist.StretchIsotropic(p), std::sqrt((1 - 3 * 0.12 * x * x) * (1 - 0.12 * x * x)), 1e-12);
  // At 45 degrees the radial and tangential directions are the diagonals.
  const double d = 0.3;  // x = y = d, rho^2 = 2 d^2
  const Point2 q = {574 + 1000 * d, 382 + 1000 * d};
  EXPECT_NEAR(dist.StretchAcross(q, {1, 1}), 1 - 3 * 0.12 * 2 * d * d, 1e-12);
  EXPECT_NEAR(dist.StretchAcross(q, {1, -1}), 1 - 0.12 * 2 * d * d, 1e-12);
}

TEST(LensDistortion, NoCoefficientsIsIdentity) {
  for (const auto& d : {std::vector<double>{}, std::vector<double>{0, 0, 0, 0, 0}}) {
    const LensDistortion dist(TestCamera(d));
    EXPECT_TRUE(dist.Identity());
    EXPECT_EQ(dist.Distort({12.5, 700}), (Point2{12.5, 700}));
    EXPECT_EQ(dist.StretchAcross({12.5, 700}, {0.3, 0.4}), 1.0);
  }
}

TEST(LensDistortion, FoldedMapIsADomainError) {
  // k1 = -1 folds the image over at rho^2 = 1/3 (d (rho (1 - rho^2)) / d rho = 0): points beyond have no ideal
  // point that distorts to them.
  const LensDistortion dist(TestCamera({-1, 0, 0, 0}));
  try {
    dist.Undistort({571.5 + 1030 * 0.6, 384.25});
    FAIL() << "no error";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kDomain);
    EXPECT_NE(std::string(e.what()).find("dist_coeffs"), std::string::npos);
  }
}

}  // namespace
}  // namespace blurcue
