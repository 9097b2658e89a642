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
#include "render/shaders.h"
#include "scene/frame.h"

namespace blurcue::render {

using scene::GreyMarginPx;
using scene::LayerOnField;
using scene::ScaledWidthPx;

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

namespace {

// The line-spread variance (px^2, along x) of the normalised coverage-ramp pillbox of coverage radius R.
double DiscKernelVariance(double coverage_r) {
  const int t = int(std::ceil(coverage_r + 0.5));
  double sum = 0, second = 0;
  for (int y = -t; y <= t; ++y)
    for (int x = -t; x <= t; ++x) {
      const double w = std::clamp(coverage_r + 0.5 - std::hypot(x, y), 0.0, 1.0);
      sum += w, second += w * x * x;
    }
  return second / sum;
}

}  // namespace

double DiscCoverageRadiusPx(double r_px) {
  // A whole-pixel disc's variance is not a continuous disc's: below R = 0.5 it is a single tap (no blur at all), and
  // up to a few px it swings by up to 10 % as rings of taps enter. So R is found where the discrete kernel's own
  // variance is r^2 / 4 (it grows with R: only the outermost ring ramps). From 8 px on, the continuous disc widened
  // by the ramp's pixel variance (r^2 = R^2 + 1/3) is within 0.1 %, and the search would cost (2 r)^2 taps a step.
  if (r_px <= 0) return 0;
  if (r_px >= 8) return std::sqrt(r_px * r_px - 1.0 / 3.0);
  const double target = r_px * r_px / 4;
  double lo = 0.5, hi = r_px + 1;  // variance 0 at R = 0.5; above target at r + 1
  for (int i = 0; i < 60; ++i) {
    const double mid = 0.5 * (lo + hi);
    (DiscKernelVariance(mid) < target ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
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

namespace {

// A side OpenCV's DCT takes fast: even, with no prime factor above 5 (cv::getOptimalDFTSize).
int FastEvenSize(int n) {
  int p = cv::getOptimalDFTSize(n);
  while (p % 2) p = cv::getOptimalDFTSize(p + 1);
  return p;
}

// How far (px) the line-spread function of `transfer` reaches: the smallest m with the LSF's absolute mass beyond
// |x| > m below 1e-4 of the total (a quarter of an 8-bit level even next to black, where sRGB is steepest), found
// from the LSF itself - the inverse DFT of transfer along one frequency axis - over a period of 4 n samples.
int LsfReachPx(const std::function<double(double)>& transfer, int n) {
  int period = cv::getOptimalDFTSize(4 * n);
  while (period % 2) period = cv::getOptimalDFTSize(period + 1);
  // A real, even spectrum in OpenCV's packed form for a real inverse DFT: Re 0, (Re k, Im k = 0)..., Re N/2.
  cv::Mat spectrum = cv::Mat::zeros(1, period, CV_64F);
  spectrum.at<double>(0) = transfer(0);
  for (int k = 1; k < period / 2; ++k) spectrum.at<double>(2 * k - 1) = transfer(double(k) / period);
  spectrum.at<double>(period - 1) = transfer(0.5);
  cv::Mat lsf;
  cv::dft(spectrum, lsf, cv::DFT_INVERSE | cv::DFT_SCALE | cv::DFT_REAL_OUTPUT);
  double total = 0;
  for (int x = 0; x < period; ++x) total += std::abs(lsf.at<double>(x));
  double beyond = total - std::abs(lsf.at<double>(0));
  for (int m = 1; m < period / 2; ++m) {
    if (beyond < 1e-4 * total) return m - 1;
    beyond -= std::abs(lsf.at<double>(m)) + std::abs(lsf.at<double>(period - m));
  }
  return period / 2;
}

}  // namespace

cv::Mat FilterInFrequency(const cv::Mat& rgba, const std::function<double(double)>& transfer) {
  CV_Assert(rgba.type() == CV_32FC4);
  // The image is taken as band-limited samples mirrored about its borders (half-sample symmetric, OpenCV's
  // BORDER_REFLECT), so nothing wraps round. The DFT of that extension, of period 2w x 2h, is the image's DCT-II: a
  // real, even transfer function multiplies its coefficients, coefficient (u, v) lying at (u / 2w, v / 2h) cycles per
  // px. One real DCT per channel does what a complex DFT of the mirrored 2w x 2h image does, with about a sixteenth
  // of the work; the channels run in parallel, and a constant channel (an opaque image's alpha) is not transformed.
  const int w = rgba.cols, h = rgba.rows;
  // The DCT's side: the image's own when OpenCV transforms it fast (exact). Otherwise the image mirrored out to the
  // next fast even side past the reach of the kernel (a 4592 x 3056 photo's 41 and 191 would take OpenCV's DCT
  // four times as long): beyond that reach the extension differs from the true mirror, but the kernel no longer
  // sees it (LsfReachPx: below 1e-4 of its mass). An odd side with no fast padding is mirrored whole (2w, exact).
  auto side = [&](int n) {
    if (n % 2 == 0 && FastEvenSize(n) == n) return n;
    const int padded = FastEvenSize(n + LsfReachPx(transfer, n));
    return padded < 2 * n ? padded : n % 2 ? 2 * n : n;
  };
  const int ew = side(w), eh = side(h);
  // The transfer function tabulated along the radial frequency (2^18 steps up to the corner's sqrt(1/2) cycles/px;
  // linear interpolation is off by (step^2 / 8) |H''|: below 4e-5 for a 2nd-order Butterworth down to a cut-off of
  // 1 cycle per 4592 px) and looked up per coefficient.
  constexpr int kSteps = 1 << 18;
  const double f_max = std::sqrt(0.5);
  std::vector<float> table(kSteps + 2);
  cv::parallel_for_(cv::Range(0, kSteps + 2), [&](const cv::Range& r) {
    for (int i = r.start; i < r.end; ++i) table[size_t(i)] = float(transfer(f_max * i / kSteps));
  });
  cv::Mat H(eh, ew, CV_32F);
  std::vector<double> fu2(size_t(ew), 0.0);
  for (int u = 0; u < ew; ++u) fu2[size_t(u)] = (u / (2.0 * ew)) * (u / (2.0 * ew));
  cv::parallel_for_(cv::Range(0, eh), [&](const cv::Range& rows) {
    for (int v = rows.start; v < rows.end; ++v) {
      float* row = H.ptr<float>(v);
      const double fv2 = (v / (2.0 * eh)) * (v / (2.0 * eh));
      for (int u = 0; u < ew; ++u) {
        const double at = std::sqrt(fu2[size_t(u)] + fv2) * (kSteps / f_max);
        const int i = int(at);
        const float t = float(at - i);
        row[u] = table[size_t(i)] + t * (table[size_t(i) + 1] - table[size_t(i)]);
      }
    }
  });
  // Each channel on its own (taken out, mirrored out, transformed, filtered, transformed back), the channels in
  // parallel; the result is put together once from the channels' image parts (no whole padded copy is made).
  std::vector<cv::Mat> channels(size_t(rgba.channels()));
  const float gain_at_zero = table[0];
  cv::parallel_for_(cv::Range(0, int(channels.size())), [&](const cv::Range& range) {
    for (int c = range.start; c < range.end; ++c) {
      cv::Mat channel;
      cv::extractChannel(rgba, channel, c);
      double lo = 0, hi = 0;
      cv::minMaxLoc(channel, &lo, &hi);
      if (lo == hi) {  // only the zero frequency: the filter scales it by transfer(0)
        channels[size_t(c)] = cv::Mat(h, w, CV_32F, cv::Scalar(lo * gain_at_zero));
        continue;
      }
      cv::Mat padded, coefficients;
      cv::copyMakeBorder(channel, padded, 0, eh - h, 0, ew - w, cv::BORDER_REFLECT);
      cv::dct(padded, coefficients);
      cv::multiply(coefficients, H, coefficients);
      cv::dct(coefficients, padded, cv::DCT_INVERSE);
      channels[size_t(c)] = padded(cv::Rect(0, 0, w, h));
    }
  });
  cv::Mat out;
  cv::merge(channels, out);
  return out;
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
  const int width_px = ScaledWidthPx(picture.size(), height_px);
  cv::Mat scaled;
  cv::resize(picture, scaled, cv::Size(width_px, height_px), 0, 0, cv::INTER_AREA);
  // A transparent margin lets the blur spread past the picture's outline.
  cv::Mat layer;
  cv::copyMakeBorder(ToLinearPremultiplied(scaled), layer, margin_px, margin_px, margin_px, margin_px,
                     cv::BORDER_CONSTANT, cv::Scalar(0, 0, 0, 0));
  if (filter) layer = filter(layer, width_px);
  cv::Mat out(field, CV_32FC3, cv::Scalar(grey, grey, grey));
  const cv::Rect at = LayerOnField(field, layer.size());
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
  const int width_px = ScaledWidthPx(picture.size(), height_px);
  // The cut-off is per picture width; the padded layer is wider, so scale it to the layer's width.
  auto butterworth = [cutoff](const cv::Mat& layer, int picture_width_px) {
    return cutoff > 0 ? ButterworthBlurCpu(layer, cutoff * layer.cols / picture_width_px) : layer;
  };
  return PictureOnField(picture, field, height_px, GreyMarginPx({width_px, height_px}), butterworth, grey);
}

void StackDepthMatchingFrame(const cv::Mat& upper, const cv::Mat& lower, cv::Mat* frame) {
  CV_Assert(upper.type() == CV_8UC3 && lower.type() == CV_8UC3 && upper.cols == lower.cols);
  frame->create(upper.rows + lower.rows, upper.cols, CV_8UC3);  // allocates only the first time
  upper.copyTo(frame->rowRange(0, upper.rows));
  lower.copyTo(frame->rowRange(upper.rows, frame->rows));
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
    : gaussian_(std::make_unique<GaussianBlurShader>()),
      disc_(std::make_unique<DiscBlurShader>()),
      kernel_(std::make_unique<KernelBlurShader>()),
      kernel_atlas_(std::make_unique<GrowingTarget>()),
      scratch_(std::make_unique<GrowingTarget>()),
      pass_(std::make_unique<FullscreenPass>()) {}

GlBlur::~GlBlur() = default;

void GlBlur::BlurTexture(Texture& texture, const std::string& method, double r_px) {
  Psf psf;
  psf.method = method, psf.r_px = r_px;
  BlurTexture(texture, psf);
}

void GlBlur::BlurTexture(Texture& texture, const Psf& psf) {
  const Framebuffer framebuffer(texture);
  Blur(texture, framebuffer.id(), {{cv::Rect(0, 0, texture.width_px(), texture.height_px()), psf}});
}

void GlBlur::BlurRegions(GrowingTarget& target, const std::vector<Region>& regions) {
  if (regions.empty()) return;
  for (const Region& region : regions) target.Reserve(region.rect.x + region.rect.width, region.rect.y + region.rect.height);
  Blur(target.texture(), target.framebuffer(), regions);
}

void GlBlur::Blur(const Texture& texture, GLuint framebuffer, const std::vector<Region>& regions) {
  // Before anything: a NaN radius would otherwise skip the blur and return the image as is.
  for (const Region& region : regions) CheckPsf(region.psf);
  GrowingTarget& scratch = *scratch_;
  scratch.Reserve(texture.width_px(), texture.height_px());
  // The general kernels (a streak, a pillbox with a floor) side by side in one atlas, uploaded in one go.
  kernel_origin_.assign(regions.size(), cv::Point(-1, -1));
  kernel_taps_.assign(regions.size(), 0);
  int atlas_w = 0, atlas_h = 0;
  // A region whose PSF is the one it had in the last call keeps its kernel: a static object's general kernel (an
  // elliptical one under distortion, a pillbox with a floor) is worked out and uploaded once, not every frame.
  bool changed = kernels_.size() != regions.size();
  kernels_.resize(regions.size());
  kernel_psf_.resize(regions.size());
  for (size_t k = 0; k < regions.size(); ++k) {
    if (!regions[k].psf.General()) {
      // Emptied, so that the atlas is laid out again (its places shift) and a later call cannot reuse a stale kernel.
      if (!kernels_[k].empty()) kernels_[k].release(), changed = true;
      continue;
    }
    if (kernels_[k].empty() || kernel_psf_[k] != regions[k].psf) {
      kernels_[k] = PsfKernel(regions[k].psf);
      kernel_psf_[k] = regions[k].psf;
      changed = true;
    }
    kernel_origin_[k] = cv::Point(atlas_w, 0);
    kernel_taps_[k] = kernels_[k].rows / 2;
    atlas_w += kernels_[k].cols, atlas_h = std::max(atlas_h, kernels_[k].rows);
  }
  if (atlas_w > 0) {
    if (changed || kernel_atlas_cpu_.rows != atlas_h || kernel_atlas_cpu_.cols != atlas_w) {
      kernel_atlas_cpu_.create(atlas_h, atlas_w, CV_32FC4);
      kernel_atlas_cpu_.setTo(cv::Scalar::all(0));
      for (size_t k = 0; k < regions.size(); ++k) {
        if (kernel_origin_[k].x < 0) continue;
        const cv::Mat& w = kernels_[k];
        cv::Mat channels[4] = {w, w, w, w};
        cv::merge(channels, 4, kernel_atlas_cpu_(cv::Rect(kernel_origin_[k], w.size())));
      }
      kernel_atlas_->Upload(kernel_atlas_cpu_);
    }
    kernel_atlas_->texture().BindImageForReading(1);
  }
  // The first pass of every region into the scratch target: the Gaussian's horizontal pass, or the whole disc or
  // general kernel. The kernels read their texels as an image (imageLoad): on llvmpipe a third cheaper than
  // texelFetch through the sampler, where a blur spends most of its time.
  glBindFramebuffer(GL_FRAMEBUFFER, scratch.framebuffer());
  texture.BindImageForReading(0);
  auto viewport = [](const cv::Rect& r) { glViewport(r.x, r.y, r.width, r.height); };
  auto taps = [](const Region& region) { return GaussianTaps(region.psf.r_px / 2); };
  auto one_pass = [](const Region& region) { return region.psf.General() || region.psf.method == "disc"; };
  auto blurs = [&](const Region& region) {
    return region.psf.General() ? true : region.psf.method == "disc" ? region.psf.r_px > 0 : taps(region) > 0;
  };
  kernel_sigma_.assign(regions.size(), 1.0);  // a one-pass kernel's second pass is a copy: any width
  for (size_t k = 0; k < regions.size(); ++k) {
    const Region& region = regions[k];
    if (!blurs(region)) continue;
    const cv::Rect& r = region.rect;
    viewport(r);
    if (region.psf.General()) {
      kernel_->Use().SetRegion(r.x, r.y, r.br().x, r.br().y)
          .SetKernel(kernel_origin_[k].x, kernel_origin_[k].y, kernel_taps_[k]);
    } else if (region.psf.method == "disc") {
      const double coverage_r = DiscCoverageRadiusPx(region.psf.r_px);
      disc_->Use().SetRegion(r.x, r.y, r.br().x, r.br().y).SetKernel(float(coverage_r), int(std::ceil(coverage_r + 0.5)));
    } else {
      // GaussianKernelSigma (a root search): the discrete kernel's variance is exactly s^2; worked out once for both
      // passes.
      kernel_sigma_[k] = GaussianKernelSigma(region.psf.r_px / 2);
      gaussian_->Use().SetRegion(r.x, r.y, r.br().x, r.br().y).SetKernel(kernel_sigma_[k], taps(region))
          .SetDirection(1, 0);
    }
    pass_->Draw();
  }
  // The second pass of every region back into the texture: the Gaussian's vertical pass, or a one-pass kernel's
  // result copied (a pass of no taps is an exact copy).
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
  scratch.texture().BindImageForReading(0);
  gaussian_->Use();
  for (size_t k = 0; k < regions.size(); ++k) {
    const Region& region = regions[k];
    if (!blurs(region)) continue;
    const cv::Rect& r = region.rect;
    viewport(r);
    gaussian_->SetRegion(r.x, r.y, r.br().x, r.br().y)
        .SetKernel(kernel_sigma_[k], one_pass(region) ? 0 : taps(region))
        .SetDirection(0, 1);
    pass_->Draw();
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

cv::Mat GlBlur::BlurImage(const cv::Mat& rgba, const std::string& method, double r_px) {
  Psf psf;
  psf.method = method, psf.r_px = r_px;
  return BlurImage(rgba, psf);
}

cv::Mat GlBlur::BlurImage(const cv::Mat& rgba, const Psf& psf) {
  CV_Assert(rgba.type() == CV_32FC4);
  Texture texture(rgba.cols, rgba.rows);
  texture.Upload(rgba);
  BlurTexture(texture, psf);
  return texture.Download();
}

}  // namespace blurcue::render
