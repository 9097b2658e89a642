#include "render/real_picture.h"

#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include "core/error.h"
#include "core/image.h"

namespace blurcue::render {
namespace {

// The depth-matching stand-in photo against the thin lens worked by hand: a white square 120 mm high at 400 mm,
// lens focused at 1 m, f = 21 mm, f/5.6, 23.4 mm sensor over 960 px. Height = 120 f / (u - f) / pitch; the
// edge's line-spread function (the derivative of the linear-light profile) has 2 std = the disc radius
// R = (D f / 2) |u - u0| / (u (u0 - f)) / pitch.
TEST(RealPicturePhoto, SizeAndBlurFollowTheThinLens) {
  const Camera camera = ThesisCamera().Resized(960, 640);
  const double f = 21, pitch = 23.4 / 960, aperture = 21 / 5.6, u = 400, u0 = 1000;
  const double height_px = 120 * f / (u - f) / pitch;                           // 272.8
  const double r_px = aperture * f / 2 * std::abs(u - u0) / (u * (u0 - f)) / pitch;  // 2.47
  const cv::Mat square(400, 400, CV_8UC4, cv::Scalar(255, 255, 255, 255));
  const cv::Mat photo = RealPicturePhoto(square, camera, u0, u, 120, 0.18);
  ASSERT_EQ(photo.cols, 960);
  ASSERT_EQ(photo.rows, 640);
  cv::Mat linear = DecodeSrgb8(photo);
  std::vector<double> row(960);
  for (int x = 0; x < 960; ++x) row[size_t(x)] = linear.at<cv::Vec3f>(320, x)[1];
  // Width at half the step, in px with linear interpolation on both edges.
  const double lo = 0.18, hi = row[480], half = (lo + hi) / 2;
  auto crossing = [&](int from, int step) {
    for (int x = from; x > 0 && x < 959; x += step)
      if ((row[size_t(x)] - half) * (row[size_t(x + step)] - half) <= 0)
        return x + step * (row[size_t(x)] - half) / (row[size_t(x)] - row[size_t(x + step)]);
    return -1.0;
  };
  const double width = crossing(480, 1) - crossing(480, -1);
  EXPECT_NEAR(width, height_px, 1.0);
  // The left edge's line-spread function: its second moment about its centroid.
  const int edge = int(std::lround(crossing(480, -1)));
  double sum = 0, mean = 0, second = 0;
  for (int x = edge - 8; x <= edge + 8; ++x) {
    const double w = row[size_t(x)] - row[size_t(x - 1)];  // derivative between x - 1 and x, centred at x - 0.5
    sum += w;
    mean += w * (x - 0.5);
  }
  mean /= sum;
  for (int x = edge - 8; x <= edge + 8; ++x) {
    const double w = row[size_t(x)] - row[size_t(x - 1)];
    second += w * (x - 0.5 - mean) * (x - 0.5 - mean);
  }
  // Pixel area adds 1/12 px^2 to the variance of a sampled edge.
  const double measured_r = 2 * std::sqrt(std::max(0.0, second / sum - 1.0 / 12));
  EXPECT_NEAR(measured_r, r_px, 0.15) << "thin-lens r " << r_px;
  EXPECT_GT(r_px, 2.0);  // the case means something: a visible blur
}

// A picture just beyond the focal length would be imaged millions of px tall and blurred by as many: refused with
// the distance, before any of it reaches an int or an allocation.
TEST(RealPicturePhoto, PictureAtTheFocalLengthIsRefused) {
  const Camera camera = ThesisCamera().Resized(960, 640);
  const cv::Mat square(40, 40, CV_8UC4, cv::Scalar(255, 255, 255, 255));
  try {
    RealPicturePhoto(square, camera, 1000, 21.001, 120, 0.18);
    FAIL() << "a picture 1 um beyond f was imaged";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kDomain);
    EXPECT_NE(std::string(e.what()).find("a 120 mm picture at 21 mm would be imaged"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace blurcue::render
