#include "render/blur.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "core/error.h"
#include "core/image.h"
#include "render/gl_objects.h"

namespace blurcue::render {

static std::string Num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

void CheckBlurRadius(double r_px) {
  // Written so that NaN fails too: every comparison with NaN is false.
  if (!(r_px >= 0 && r_px <= kMaxBlurRadiusPx))
    throw Error(ErrorKind::kDomain, "blur radius must be in [0, " + Num(kMaxBlurRadiusPx) + "] px, got " + Num(r_px));
}

int GaussianTaps(double sigma_px) {
  if (sigma_px <= 0) return 0;
  CheckBlurRadius(2 * sigma_px);  // a NaN or huge sigma has no tap count an int holds
  return std::max(1, int(std::ceil(3 * sigma_px)));
}

double GaussianKernelSigma(double s) {
  const int taps = GaussianTaps(s);
  if (taps == 0) return 0;
  auto variance = [taps](double t) {
    double sum = 1, moment = 0;
    for (int i = 1; i <= taps; ++i) {
      const double w = std::exp(-0.5 * i * i / (t * t));
      sum += 2 * w, moment += 2 * w * i * i;
    }
    return moment / sum;
  };
  // The variance grows with t towards the flat kernel's taps (taps + 1) / 3 >= 3 s^2: bisect.
  double lo = 1e-3, hi = s;
  while (variance(hi) < s * s) hi *= 2;
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (variance(mid) < s * s ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

cv::Mat GaussianBlurCpu(const cv::Mat& rgba, double r_px) {
  CV_Assert(rgba.type() == CV_32FC4);
  CheckBlurRadius(r_px);
  const double s = r_px / 2;
  const int taps = GaussianTaps(s);
  if (taps == 0) return rgba.clone();
  // OpenCV's own Gaussian (its fastest separable path) with the sampled kernel of std t over 2 taps + 1 points: the
  // same normalised exp(-i^2 / 2t^2) weights this filter defines.
  const double t = GaussianKernelSigma(s);
  cv::Mat out;
  cv::GaussianBlur(rgba, out, cv::Size(2 * taps + 1, 2 * taps + 1), t, t, cv::BORDER_REPLICATE);
  return out;
}

double DiscCoverageRadiusPx(double r_px) {
  // The one-pixel coverage ramp widens the disc's line-spread function by a pixel's variance (1/12 px^2), which
  // is r^2 / 4 in the DESIGN.md unit; take it out so the kernel's r is the requested one.
  return std::sqrt(std::max(r_px * r_px - 1.0 / 3.0, 0.0));
}

cv::Mat DiscKernel(double requested_r_px) {
  CheckBlurRadius(requested_r_px);
  const double r_px = DiscCoverageRadiusPx(requested_r_px);
  const int t = int(std::ceil(r_px + 0.5));
  cv::Mat k(2 * t + 1, 2 * t + 1, CV_32F);
  for (int y = -t; y <= t; ++y)
    for (int x = -t; x <= t; ++x)
      k.at<float>(y + t, x + t) = float(std::clamp(r_px + 0.5 - std::hypot(x, y), 0.0, 1.0));
  return k / cv::sum(k)[0];
}

cv::Mat DiscBlurCpu(const cv::Mat& rgba, double r_px) {
  CV_Assert(rgba.type() == CV_32FC4);
  CheckBlurRadius(r_px);
  if (r_px <= 0) return rgba.clone();
  cv::Mat out;
  cv::filter2D(rgba, out, CV_32F, DiscKernel(r_px), cv::Point(-1, -1), 0, cv::BORDER_REPLICATE);
  return out;
}

cv::Mat FilterInFrequency(const cv::Mat& rgba, const std::function<double(double)>& transfer) {
  CV_Assert(rgba.type() == CV_32FC4);
  const int w = rgba.cols, h = rgba.rows;
  // Mirror padding to sizes the DFT likes, so the borders do not wrap around.
  const int pw = cv::getOptimalDFTSize(2 * w), ph = cv::getOptimalDFTSize(2 * h);
  cv::Mat padded;
  cv::copyMakeBorder(rgba, padded, 0, ph - h, 0, pw - w, cv::BORDER_REFLECT);
  cv::Mat H(ph, pw, CV_32F);
  for (int v = 0; v < ph; ++v)
    for (int u = 0; u < pw; ++u) {
      const double fu = (u <= pw / 2 ? u : u - pw) / double(pw), fv = (v <= ph / 2 ? v : v - ph) / double(ph);
      H.at<float>(v, u) = float(transfer(std::hypot(fu, fv)));
    }
  std::vector<cv::Mat> channels;
  cv::split(padded, channels);
  for (cv::Mat& c : channels) {
    cv::Mat spectrum, planes[2];
    cv::dft(c, spectrum, cv::DFT_COMPLEX_OUTPUT);
    cv::split(spectrum, planes);
    planes[0] = planes[0].mul(H);
    planes[1] = planes[1].mul(H);
    cv::merge(planes, 2, spectrum);
    cv::dft(spectrum, c, cv::DFT_INVERSE | cv::DFT_SCALE | cv::DFT_REAL_OUTPUT);
  }
  cv::Mat out;
  cv::merge(channels, out);
  return out(cv::Rect(0, 0, w, h)).clone();
}

cv::Mat ButterworthBlurCpu(const cv::Mat& rgba, double cutoff, int order) {
  if (!(cutoff > 0 && cutoff <= kMaxCutoffCyclesPerWidth))
    throw Error(ErrorKind::kDomain, "Butterworth cut-off must be in (0, " + Num(kMaxCutoffCyclesPerWidth) +
                                        "] cycles per image width, got " + Num(cutoff));
  if (order < 1 || order > 16)
    throw Error(ErrorKind::kDomain, "Butterworth order must be in [1, 16], got " + std::to_string(order));
  const double w = rgba.cols;  // the cut-off counts cycles per image width
  return FilterInFrequency(rgba, [&](double f) { return 1.0 / (1.0 + std::pow(f * w / cutoff, 2 * order)); });
}

cv::Mat PictureOnField(const cv::Mat& picture, cv::Size field, int height_px, int margin_px,
                       const std::function<cv::Mat(const cv::Mat&, int)>& filter, double grey) {
  CV_Assert(height_px > 0 && field.width > 0 && field.height > 0);
  const int width_px = std::max(1, int(std::lround(double(picture.cols) * height_px / picture.rows)));
  cv::Mat scaled;
  cv::resize(picture, scaled, cv::Size(width_px, height_px), 0, 0, cv::INTER_AREA);
  // A transparent margin lets the blur spread past the picture's outline.
  cv::Mat layer;
  cv::copyMakeBorder(ToLinearPremultiplied(scaled), layer, margin_px, margin_px, margin_px, margin_px,
                     cv::BORDER_CONSTANT, cv::Scalar(0, 0, 0, 0));
  if (filter) layer = filter(layer, width_px);
  cv::Mat out(field, CV_32FC3, cv::Scalar(grey, grey, grey));
  const cv::Rect at((field.width - layer.cols) / 2, (field.height - layer.rows) / 2, layer.cols, layer.rows);
  const cv::Rect visible = at & cv::Rect(0, 0, field.width, field.height);
  for (int y = visible.y; y < visible.y + visible.height; ++y)
    for (int x = visible.x; x < visible.x + visible.width; ++x) {
      const cv::Vec4f p = layer.at<cv::Vec4f>(y - at.y, x - at.x);
      cv::Vec3f& o = out.at<cv::Vec3f>(y, x);
      const float keep = 1.f - std::clamp(p[3], 0.f, 1.f);
      o = cv::Vec3f(std::max(0.f, p[0] + keep * o[0]), std::max(0.f, p[1] + keep * o[1]),
                    std::max(0.f, p[2] + keep * o[2]));
    }
  return EncodeSrgb8(out);
}

cv::Mat PictureOnGrey(const cv::Mat& picture, cv::Size field, int height_px, double cutoff, double grey) {
  // 0 is sharp; a NaN must not pass for it.
  if (!(cutoff >= 0 && cutoff <= kMaxCutoffCyclesPerWidth))
    throw Error(ErrorKind::kDomain, "Butterworth cut-off must be in [0, " + Num(kMaxCutoffCyclesPerWidth) +
                                        "] cycles per picture width (0 = sharp), got " + Num(cutoff));
  const int width_px = std::max(1, int(std::lround(double(picture.cols) * height_px / picture.rows)));
  // The cut-off is per picture width; the padded layer is wider, so scale it to the layer's width.
  auto butterworth = [cutoff](const cv::Mat& layer, int picture_width_px) {
    return cutoff > 0 ? ButterworthBlurCpu(layer, cutoff * layer.cols / picture_width_px) : layer;
  };
  return PictureOnField(picture, field, height_px, std::max(width_px, height_px) / 4, butterworth, grey);
}

cv::Mat DepthMatchingFrame(const cv::Mat& upper, const cv::Mat& photo, int width_px) {
  const int h = width_px * 3 / 4, half = h / 2;
  CV_Assert(upper.cols == width_px && upper.rows == half && upper.type() == CV_8UC3);
  cv::Mat frame(h, width_px, CV_8UC3);
  upper.copyTo(frame.rowRange(0, half));
  const double scale = std::max(double(width_px) / photo.cols, double(h - half) / photo.rows);
  cv::Mat scaled;
  cv::resize(photo, scaled, cv::Size(), scale, scale, cv::INTER_AREA);
  scaled(cv::Rect((scaled.cols - width_px) / 2, (scaled.rows - (h - half)) / 2, width_px, h - half))
      .copyTo(frame.rowRange(half, h));
  return frame;
}

cv::Mat ToLinearPremultiplied(const cv::Mat& image8) {
  cv::Mat bgra;
  if (image8.channels() == 1) cv::cvtColor(image8, bgra, cv::COLOR_GRAY2BGRA);
  else if (image8.channels() == 3) cv::cvtColor(image8, bgra, cv::COLOR_BGR2BGRA);
  else bgra = image8;
  // Colour is sRGB-encoded, alpha is linear coverage: decode only the colour.
  cv::Mat linear = DecodeSrgb8(bgra);
  for (int y = 0; y < linear.rows; ++y) {
    cv::Vec4f* row = linear.ptr<cv::Vec4f>(y);
    const cv::Vec4b* src = bgra.ptr<cv::Vec4b>(y);
    for (int x = 0; x < linear.cols; ++x) {
      const float a = src[x][3] / 255.f;
      row[x] = cv::Vec4f(row[x][0] * a, row[x][1] * a, row[x][2] * a, a);
    }
  }
  return linear;
}

cv::Mat FromLinearPremultiplied(const cv::Mat& rgba, bool keep_alpha) {
  CV_Assert(rgba.type() == CV_32FC4);
  cv::Mat colour(rgba.size(), CV_32FC3), alpha(rgba.size(), CV_8U);
  for (int y = 0; y < rgba.rows; ++y) {
    const cv::Vec4f* src = rgba.ptr<cv::Vec4f>(y);
    cv::Vec3f* dst = colour.ptr<cv::Vec3f>(y);
    for (int x = 0; x < rgba.cols; ++x) {
      const float a = std::clamp(src[x][3], 0.f, 1.f);
      dst[x] = a > 1e-6f ? cv::Vec3f(src[x][0] / a, src[x][1] / a, src[x][2] / a) : cv::Vec3f(0, 0, 0);
      alpha.at<uint8_t>(y, x) = uint8_t(std::lround(a * 255));
    }
  }
  cv::Mat out = EncodeSrgb8(colour);
  if (!keep_alpha) return out;
  cv::Mat channels[4];
  cv::split(out, channels);
  channels[3] = alpha;
  cv::merge(channels, 4, out);
  return out;
}

GlBlur::GlBlur()
    : gaussian_(std::make_unique<Program>(
          Program::FromFiles(ShaderDir() / "fullscreen.vert", ShaderDir() / "blur_gaussian.frag"))),
      disc_(std::make_unique<Program>(
          Program::FromFiles(ShaderDir() / "fullscreen.vert", ShaderDir() / "blur_disc.frag"))),
      pass_(std::make_unique<FullscreenPass>()) {}

GlBlur::~GlBlur() = default;

void GlBlur::BlurTexture(Texture& texture, const std::string& method, double r_px) {
  CheckBlurRadius(r_px);  // before anything: a NaN radius would otherwise skip the blur and return the image as is
  const int w = texture.width_px(), h = texture.height_px();
  if (!scratch_ || scratch_->width_px() != w || scratch_->height_px() != h) scratch_ = std::make_unique<Texture>(w, h);
  Texture& scratch = *scratch_;
  if (method == "disc") {
    if (r_px <= 0) return;
    const double coverage_r = DiscCoverageRadiusPx(r_px);
    {
      Framebuffer to_scratch(scratch);
      disc_->Use();
      glUniform1i(disc_->Uniform("u_image"), 0);
      glUniform1f(disc_->Uniform("u_radius_px"), float(coverage_r));
      glUniform1i(disc_->Uniform("u_taps"), int(std::ceil(coverage_r + 0.5)));
      to_scratch.Bind();
      texture.Bind(0);
      pass_->Draw();
    }
    std::swap(texture, scratch);
  } else {
    const double s = r_px / 2;
    const int taps = GaussianTaps(s);
    if (taps == 0) return;
    gaussian_->Use();
    glUniform1i(gaussian_->Uniform("u_image"), 0);
    glUniform1f(gaussian_->Uniform("u_sigma_px"), float(GaussianKernelSigma(s)));  // variance exactly s^2
    glUniform1i(gaussian_->Uniform("u_taps"), taps);
    Framebuffer to_scratch(scratch), to_texture(texture);
    to_scratch.Bind();
    texture.Bind(0);
    glUniform2f(gaussian_->Uniform("u_direction"), 1, 0);
    pass_->Draw();
    to_texture.Bind();
    scratch.Bind(0);
    glUniform2f(gaussian_->Uniform("u_direction"), 0, 1);
    pass_->Draw();
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

cv::Mat GlBlur::BlurImage(const cv::Mat& rgba, const std::string& method, double r_px) {
  CV_Assert(rgba.type() == CV_32FC4);
  Texture texture(rgba.cols, rgba.rows);
  texture.Upload(rgba);
  BlurTexture(texture, method, r_px);
  return texture.Download();
}

}  // namespace blurcue::render
