// GL tests (label "gl"): they run on Mesa's llvmpipe through EGL with no display.
#include "render/blur.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>

#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "render/gl_context.h"
#include "render/gl_objects.h"
#include "scene/frame.h"

namespace blurcue::render {
namespace {

class GlTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { context_ = GlContext::CreateOffscreen().release(); }
  static void TearDownTestSuite() { delete context_; }
  static GlContext* context_;
};
GlContext* GlTest::context_ = nullptr;

// Premultiplied linear RGBA: a sharp bright square with an alpha edge on a transparent field.
cv::Mat Square(int w, int h) {
  cv::Mat img(h, w, CV_32FC4, cv::Scalar(0, 0, 0, 0));
  img(cv::Rect(w / 4, h / 4, w / 2, h / 2)).setTo(cv::Scalar(0.8, 0.5, 0.2, 1.0));
  img(cv::Rect(w / 4, h / 4, w / 8, h / 2)).setTo(cv::Scalar(0.05, 0.05, 0.05, 1.0));
  return img;
}

TEST_F(GlTest, ContextIsLlvmpipeCore33OrLater) {
  const std::string d = context_->Describe();
  EXPECT_NE(d.find("Core Profile"), std::string::npos) << d;
}

TEST_F(GlTest, ShaderCompileErrorNamesTheShaderAndCarriesTheLog) {
  try {
    Program::FromSource("#version 330 core\nvoid main() { gl_Position = vec4(0); }\n",
                        "#version 330 core\nout vec4 o; void main() { o = undefined_thing; }\n", "broken.frag");
    FAIL() << "expected a compile error";
  } catch (const Error& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("broken.frag"), std::string::npos) << what;
    EXPECT_NE(what.find("undefined_thing"), std::string::npos) << what;
  }
}

TEST_F(GlTest, GaussianMatchesCpuReference) {
  GlBlur blur;
  const cv::Mat img = Square(160, 120);
  for (double r : {1.0, 4.0, 8.0, 16.0}) {
    const cv::Mat gl = blur.Gaussian(img, r), cpu = GaussianBlurCpu(img, r);
    cv::Mat diff;
    cv::absdiff(gl, cpu, diff);
    const cv::Scalar mean = cv::mean(diff);
    double max = 0;
    cv::minMaxLoc(diff.reshape(1), nullptr, &max);
    EXPECT_LE((mean[0] + mean[1] + mean[2] + mean[3]) / 4, 0.5 / 255) << "r = " << r;
    EXPECT_LE(max, 3.0 / 255) << "r = " << r;
  }
}

TEST_F(GlTest, PooledTargetKeepsItsTextureAndBlursOnlyItsRegion) {
  // A layer in the bottom-left of a larger pooled target blurs exactly as the layer alone would (the CPU reference,
  // clamp at the layer's border): whatever lies beyond the region - here 1000, which would show at once - is neither
  // read nor written. And a smaller region reuses the target's texture: a frame loop allocates nothing.
  GrowingTarget target;
  target.Reserve(200, 150);
  const GLuint id = target.texture().id();
  cv::Mat garbage(target.texture().height_px(), target.texture().width_px(), CV_32FC4, cv::Scalar::all(1000));
  target.Upload(garbage);
  const cv::Mat img = Square(96, 70);
  target.Upload(img);
  target.Reserve(96, 70);
  EXPECT_EQ(target.texture().id(), id);
  GlBlur blur;
  for (const std::string method : {"gaussian", "disc"}) {
    target.Upload(img);
    blur.BlurRegions(target, {{cv::Rect(0, 0, img.cols, img.rows), method, 6.0}});
    const cv::Mat cpu = method == "disc" ? DiscBlurCpu(img, 6.0) : GaussianBlurCpu(img, 6.0);
    EXPECT_LE(cv::norm(target.Download(img.cols, img.rows), cpu, cv::NORM_INF), 3.0 / 255) << method;
    const cv::Mat beyond = target.Download(target.texture().width_px(), target.texture().height_px());
    EXPECT_EQ(beyond.at<cv::Vec4f>(100, 150)[0], 1000.f) << method;  // outside the region: untouched
  }
  EXPECT_EQ(target.texture().id(), id);
}

TEST(CpuBlur, GaussianKeepsBrightness) {
  // Normalised kernel (eq. 4.6): the sum of light is unchanged away from the borders.
  const cv::Mat img = Square(200, 200);
  const cv::Mat out = GaussianBlurCpu(img, 8);
  EXPECT_NEAR(cv::sum(out)[0], cv::sum(img)[0], 1e-3 * cv::sum(img)[0]);
  EXPECT_NEAR(cv::sum(out)[3], cv::sum(img)[3], 1e-3 * cv::sum(img)[3]);
}

TEST(CpuBlur, GaussianEdgeHasRequestedRadius) {
  // r = 2 x std of the LSF: the derivative of a blurred step has std r / 2.
  cv::Mat img(1, 400, CV_32FC4, cv::Scalar(0, 0, 0, 1));
  img.colRange(200, 400).setTo(cv::Scalar(1, 1, 1, 1));
  const double r = 10;
  const cv::Mat out = GaussianBlurCpu(img, r);
  double m0 = 0, m1 = 0, m2 = 0;
  for (int x = 1; x < 400; ++x) {
    const double d = out.at<cv::Vec4f>(0, x)[0] - out.at<cv::Vec4f>(0, x - 1)[0];
    const double pos = x - 0.5;
    m0 += d, m1 += d * pos, m2 += d * pos * pos;
  }
  const double var = m2 / m0 - (m1 / m0) * (m1 / m0);
  EXPECT_NEAR(2 * std::sqrt(var), r, 0.05 * r);
}

}  // namespace
}  // namespace blurcue::render

namespace blurcue::render {
namespace {

TEST_F(GlTest, DiscMatchesCpuReference) {
  GlBlur blur;
  const cv::Mat img = Square(120, 100);
  for (double r : {0.7, 3.0, 8.0}) {
    cv::Mat diff;
    cv::absdiff(blur.Disc(img, r), DiscBlurCpu(img, r), diff);
    const cv::Scalar mean = cv::mean(diff);
    double max = 0;
    cv::minMaxLoc(diff.reshape(1), nullptr, &max);
    EXPECT_LE((mean[0] + mean[1] + mean[2] + mean[3]) / 4, 0.5 / 255) << "r = " << r;
    EXPECT_LE(max, 3.0 / 255) << "r = " << r;
  }
}

// 2 x std of the derivative of a blurred vertical step, first channel.
double EdgeRadius(const cv::Mat& out) {
  const int y = out.rows / 2;
  double m0 = 0, m1 = 0, m2 = 0;
  for (int x = 1; x < out.cols; ++x) {
    const double d = out.at<cv::Vec4f>(y, x)[0] - out.at<cv::Vec4f>(y, x - 1)[0];
    const double pos = x - 0.5;
    m0 += d, m1 += d * pos, m2 += d * pos * pos;
  }
  return 2 * std::sqrt(m2 / m0 - (m1 / m0) * (m1 / m0));
}

TEST(CpuBlur, DiscEdgeHasRequestedRadius) {
  // A disc of radius R has an LSF (a semicircle) of std R / 2, so r = R.
  cv::Mat img(41, 300, CV_32FC4, cv::Scalar(0, 0, 0, 1));
  img.colRange(150, 300).setTo(cv::Scalar(1, 1, 1, 1));
  for (double r : {4.0, 10.0, 16.0}) EXPECT_NEAR(EdgeRadius(DiscBlurCpu(img, r)), r, 0.05 * r) << r;
}

// Below a few px a whole-pixel disc is not a continuous one: R = sqrt(r^2 - 1/3) drew nothing below r = 0.8 px and
// 10 % too much at 1.2 px. The edge's LSF (its differences) is the kernel's marginal exactly: its 2 x std is r.
TEST(CpuBlur, SubPixelEdgeHasRequestedRadiusForBothKernels) {
  cv::Mat img(21, 60, CV_32FC4, cv::Scalar(0, 0, 0, 1));
  img.colRange(30, 60).setTo(cv::Scalar(1, 1, 1, 1));
  for (double r : {0.25, 0.4, 0.6, 0.8, 1.0, 1.2, 1.5, 2.0, 3.0, 5.0, 7.9}) {
    EXPECT_NEAR(EdgeRadius(DiscBlurCpu(img, r)), r, std::max(0.005, 0.005 * r)) << "disc " << r;
    EXPECT_NEAR(EdgeRadius(GaussianBlurCpu(img, r)), r, std::max(0.005, 0.005 * r)) << "gaussian " << r;
  }
}

TEST_F(GlTest, SubPixelEdgeHasRequestedRadiusForBothKernels) {
  GlBlur blur;
  cv::Mat img(21, 60, CV_32FC4, cv::Scalar(0, 0, 0, 1));
  img.colRange(30, 60).setTo(cv::Scalar(1, 1, 1, 1));
  for (double r : {0.25, 0.4, 0.6, 0.8, 1.2, 2.0, 3.0}) {
    EXPECT_NEAR(EdgeRadius(blur.Disc(img, r)), r, std::max(0.005, 0.005 * r)) << "disc " << r;
    EXPECT_NEAR(EdgeRadius(blur.Gaussian(img, r)), r, std::max(0.005, 0.005 * r)) << "gaussian " << r;
  }
}

TEST(CpuBlur, ButterworthKeepsMeanAndSoftensMoreAtLowerCutoff) {
  cv::Mat step(41, 256, CV_32FC4, cv::Scalar(0, 0, 0, 1));
  step.colRange(128, 256).setTo(cv::Scalar(1, 1, 1, 1));
  const cv::Mat soft = ButterworthBlurCpu(step, 8), sharp = ButterworthBlurCpu(step, 40);
  EXPECT_NEAR(cv::mean(soft)[0], cv::mean(step)[0], 0.01);
  EXPECT_NEAR(cv::mean(soft)[3], 1.0, 0.01);
  // The second moment of a Butterworth LSF of order >= 2 is zero (H''(0) = 0: the ringing lobes cancel it), so
  // r = 2 std is no measure of it; the 10-90 % rise distance is.
  auto rise = [](const cv::Mat& out) {
    int x10 = -1, x90 = -1;
    for (int x = 0; x < out.cols; ++x) {
      const float v = out.at<cv::Vec4f>(out.rows / 2, x)[0];
      if (x10 < 0 && v >= 0.1f) x10 = x;
      if (x90 < 0 && v >= 0.9f) x90 = x;
    }
    return x90 - x10;
  };
  EXPECT_GT(rise(soft), 3 * rise(sharp));
}

TEST(CpuBlur, ButterworthEquivalentGaussianHasItsEdgeRise) {
  // The equivalent Gaussian of a Butterworth cut-off (the one that halves contrast at the cut-off) against the
  // Butterworth as filtered: the 10-90 % rise of a step (interpolated, in px) through ButterworthBlurCpu and through
  // GaussianBlurCpu at r = 2 s agree within 10 % (the closed forms say 6.5 %); and the area under the two transfer
  // functions (pi fc / sqrt 2 and 1 / (sqrt(2 pi) s)) within 5 %.
  cv::Mat step(9, 1024, CV_32FC4, cv::Scalar(0, 0, 0, 1));
  step.colRange(512, 1024).setTo(cv::Scalar(1, 1, 1, 1));
  auto rise = [](const cv::Mat& out) {
    auto at = [&](int x) { return double(out.at<cv::Vec4f>(out.rows / 2, x)[0]); };
    auto cross = [&](double level) {
      for (int x = 1; x < out.cols; ++x)
        if (at(x) >= level && at(x - 1) < level) return x - 1 + (level - at(x - 1)) / (at(x) - at(x - 1));
      return -1.0;
    };
    return cross(0.9) - cross(0.1);
  };
  for (double cutoff : {16.0, 32.0}) {
    const double s_px = scene::ButterworthEquivalentSigma(cutoff) * step.cols;
    const double butterworth = rise(ButterworthBlurCpu(step, cutoff)), gaussian = rise(GaussianBlurCpu(step, 2 * s_px));
    EXPECT_NEAR(butterworth / gaussian, 1.0, 0.10) << cutoff << ": " << butterworth << " vs " << gaussian << " px";
    EXPECT_NEAR(gaussian, 2 * 1.2815515655 * s_px, 0.03 * gaussian) << cutoff;  // the sampled Gaussian is one
    const double area_butterworth = M_PI * cutoff / std::sqrt(2.0), area_gaussian = 1 / (std::sqrt(2 * M_PI) * s_px);
    EXPECT_NEAR(area_butterworth / step.cols / area_gaussian, 1.0, 0.05) << cutoff;
  }
}

TEST(CpuBlur, FrequencyFilterIsConvolutionWithTheMirroredImage) {
  // A Gaussian transfer exp(-2 pi^2 s^2 f^2) through the DCT must equal the spatial convolution with the sampled
  // Gaussian over the mirrored image (cv::GaussianBlur, BORDER_REFLECT, kernel to 6 s): at s = 3 px the two differ
  // only by the kernel's truncation and aliasing (< 1e-5), so any error in the frequency mapping or the extension
  // shows: sides OpenCV transforms fast (exact), odd ones (mirrored whole), and ones padded to a fast side past the
  // kernel's reach (82 = 2 x 41, 38 = 2 x 19).
  for (const cv::Size size : {cv::Size(64, 48), cv::Size(63, 37), cv::Size(82, 38)}) {
    cv::Mat img(size, CV_32FC4);
    cv::randu(img, 0.f, 1.f);
    const double s = 3;
    const cv::Mat freq = FilterInFrequency(img, [s](double f) { return std::exp(-2 * M_PI * M_PI * s * s * f * f); });
    cv::Mat spatial;
    cv::GaussianBlur(img, spatial, cv::Size(37, 37), s, s, cv::BORDER_REFLECT);
    EXPECT_LT(cv::norm(freq, spatial, cv::NORM_INF), 1e-4) << size;
  }
}

TEST(LinearPremultiplied, RoundTripsEightBitImages) {
  cv::Mat img(8, 8, CV_8UC4);
  cv::randu(img, 0, 256);
  img.col(0).setTo(cv::Scalar(10, 200, 30, 255));
  const cv::Mat back = FromLinearPremultiplied(ToLinearPremultiplied(img), true);
  // Colour is exact where alpha is 255; elsewhere un-premultiplying 8-bit alpha loses a level at most.
  EXPECT_EQ(cv::norm(img.col(0), back.col(0), cv::NORM_INF), 0);
  cv::Mat a, b;
  cv::extractChannel(img, a, 3);
  cv::extractChannel(back, b, 3);
  EXPECT_EQ(cv::norm(a, b, cv::NORM_INF), 0);
}

}  // namespace
}  // namespace blurcue::render

#include "calib/edge_blur.h"
#include "core/image.h"

namespace blurcue::render {
namespace {

// The renderer's blur, measured by the calibration's own measurement: a slanted step in linear light, blurred on
// the GPU, written as 8-bit sRGB like any stimulus, read back and measured.
TEST_F(GlTest, RenderedEdgeMeasuresAsTheRequestedRadius) {
  GlBlur blur;
  const int w = 240, h = 200;
  cv::Mat step(h, w, CV_32FC4);
  const double angle = 6 * M_PI / 180;  // slanted, so the edge is sampled at many sub-pixel phases
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      // Area coverage of the bright side by 4x4 sub-samples: a sharp, anti-aliased step.
      double cover = 0;
      for (int sy = 0; sy < 4; ++sy)
        for (int sx = 0; sx < 4; ++sx) {
          const double px = x + (sx + 0.5) / 4 - 0.5 - w / 2.0, py = y + (sy + 0.5) / 4 - 0.5 - h / 2.0;
          cover += (py * std::cos(angle) - px * std::sin(angle) > 0) / 16.0;
        }
      const float v = float(0.05 + 0.75 * cover);
      step.at<cv::Vec4f>(y, x) = cv::Vec4f(v, v, v, 1);
    }
  const cv::Point2d centre(w / 2.0 - 0.5, h / 2.0 - 0.5), along(std::cos(angle), std::sin(angle));
  const calib::EdgeSegment segment{centre - 80.0 * along, centre + 80.0 * along, 90};
  for (const char* method : {"gaussian", "disc"})
    for (double r : {2.0, 5.0, 12.0}) {
      const cv::Mat blurred = std::string(method) == "disc" ? blur.Disc(step, r) : blur.Gaussian(step, r);
      // Through 8-bit sRGB and back, as a stimulus on disk would be.
      cv::Mat bgr;
      cv::cvtColor(FromLinearPremultiplied(blurred, false), bgr, cv::COLOR_BGR2GRAY);
      const calib::ModelFit fit = calib::MeasureEdgeModel(DecodeSrgb8(bgr), segment);
      ASSERT_TRUE(fit.ok) << method << " r = " << r << " flags " << (fit.flags.empty() ? "" : fit.flags[0]) << " r_fit " << fit.r_px;
      std::printf("%s r %.1f measured %.3f\n", method, r, fit.r_px);
      EXPECT_NEAR(fit.r_px, r, 0.05 * r) << method;
    }
}

}  // namespace
}  // namespace blurcue::render

namespace blurcue::render {
namespace {

TEST(PictureOnGrey, FieldIsGreyAndLowerCutoffsSoftenThePicture) {
  cv::Mat picture(120, 80, CV_8UC4, cv::Scalar(0, 0, 0, 0));
  cv::ellipse(picture, cv::Point(40, 60), cv::Size(35, 55), 0, 0, 360, cv::Scalar(60, 120, 220, 255), cv::FILLED);
  cv::rectangle(picture, cv::Rect(20, 40, 40, 10), cv::Scalar(20, 20, 20, 255), cv::FILLED);
  const cv::Size field(320, 240);
  const cv::Mat sharp = PictureOnGrey(picture, field, 120, 0), soft = PictureOnGrey(picture, field, 120, 3),
                softer = PictureOnGrey(picture, field, 120, 1.5);
  // The field away from the picture is the requested grey (linear 0.18 -> sRGB 118).
  EXPECT_EQ(sharp.at<cv::Vec3b>(5, 5), cv::Vec3b(118, 118, 118));
  EXPECT_EQ(soft.at<cv::Vec3b>(5, 5), cv::Vec3b(118, 118, 118));
  // Sharper pictures have more edge energy; the low-pass keeps the picture's mean light.
  auto energy = [](const cv::Mat& img) {
    cv::Mat g, dx;
    cv::cvtColor(img, g, cv::COLOR_BGR2GRAY);
    cv::Sobel(g, dx, CV_32F, 1, 0);
    return cv::norm(dx, cv::NORM_L2);
  };
  EXPECT_GT(energy(sharp), 1.5 * energy(soft));
  EXPECT_GT(energy(soft), 1.2 * energy(softer));
  EXPECT_NEAR(cv::mean(DecodeSrgb8(soft))[0], cv::mean(DecodeSrgb8(sharp))[0], 0.01);
}

// NaN, infinity, negative and absurd radii are refused with the value in the message, never a crash, a hang or
// an image returned unblurred.
const double kBadRadii[] = {std::nan(""), INFINITY, -1.0, 500.5, 1e9, 1e308};

void ExpectRefused(const std::function<void()>& call, double r, const std::string& text) {
  try {
    call();
    ADD_FAILURE() << "r = " << r << " was accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kDomain) << e.what();
    EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
  }
}

TEST(CpuBlur, RefusesNonFiniteNegativeAndHugeRadii) {
  const cv::Mat img = Square(32, 24);
  for (double r : kBadRadii) {
    ExpectRefused([&] { GaussianBlurCpu(img, r); }, r, "blur radius must be in [0, 500] px, got ");
    ExpectRefused([&] { DiscBlurCpu(img, r); }, r, "blur radius must be in [0, 500] px, got ");
  }
  ExpectRefused([&] { GaussianBlurCpu(img, std::nan("")); }, 0, "got nan");
}

TEST(CpuBlur, LargestRadiusBlursAndZeroKeepsTheImage) {
  const cv::Mat img = Square(32, 24);
  const cv::Mat same = GaussianBlurCpu(img, 0), wide = GaussianBlurCpu(img, kMaxBlurRadiusPx);
  EXPECT_EQ(cv::norm(same, img, cv::NORM_INF), 0);
  // r = 500 px on a 32 px image: nearly flat, the square's colour spread over the whole image.
  double lo = 0, hi = 0;
  cv::minMaxLoc(wide.reshape(1), &lo, &hi);
  EXPECT_GT(lo, 0.0);
  EXPECT_LT(hi, 0.8);
}

TEST(CpuBlur, ButterworthRefusesNonFiniteZeroAndHugeCutoffs) {
  const cv::Mat img = Square(32, 24);
  for (double cutoff : {std::nan(""), double(INFINITY), 0.0, -2.0, 1e308})
    ExpectRefused([&] { ButterworthBlurCpu(img, cutoff); }, cutoff, "Butterworth cut-off must be in (0, ");
  cv::Mat picture(40, 30, CV_8UC4, cv::Scalar(40, 80, 120, 255));
  ExpectRefused([&] { PictureOnGrey(picture, cv::Size(64, 48), 20, std::nan("")); }, 0, "got nan");
}

TEST_F(GlTest, RefusesNonFiniteNegativeAndHugeRadii) {
  GlBlur blur;
  const cv::Mat img = Square(32, 24);
  for (double r : kBadRadii) {
    ExpectRefused([&] { blur.Gaussian(img, r); }, r, "blur radius must be in [0, 500] px, got ");
    ExpectRefused([&] { blur.Disc(img, r); }, r, "blur radius must be in [0, 500] px, got ");
  }
}

TEST_F(GlTest, ImageWiderThanTheLargestTextureIsRefused) {
  GLint max_side = 0;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_side);
  GlBlur blur;
  const cv::Mat wide(2, max_side + 1, CV_32FC4, cv::Scalar(0.5, 0.5, 0.5, 1));
  try {
    blur.Gaussian(wide, 2);
    FAIL() << "a " << wide.cols << " px wide image was blurred on a GL whose textures end at " << max_side;
  } catch (const Error& e) {
    EXPECT_EQ(e.kind(), ErrorKind::kInput);
    EXPECT_NE(std::string(e.what()).find("does not fit this GL's textures"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace blurcue::render
