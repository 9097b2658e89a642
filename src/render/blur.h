#pragma once
// Blur of images in linear light with premultiplied alpha, on the GPU and as a CPU reference with the same kernel.
// Radii are in the DESIGN.md unit: a Gaussian of std s has r = 2 s.
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

#include <epoxy/gl.h>

#include "optics/thin_lens.h"
#include "render/psf.h"

namespace blurcue::render {

// The largest blur radius the blur functions take (optics::kMaxBlurRadiusPx, 500 px).
using optics::kMaxBlurRadiusPx;
// Throws Error(kDomain) "blur radius must be in [0, 500] px, got nan" unless r_px is finite and in that range.
void CheckBlurRadius(double r_px);

// The Butterworth cut-off's range, cycles per image width: above it the filter passes every frequency an image of
// any size holds, so a larger value only hides a mistake.
constexpr double kMaxCutoffCyclesPerWidth = 1e5;

// Half-width of the discrete Gaussian for std s: ceil(3 s) (at least 1), as wide as s needs and no wider.
int GaussianTaps(double sigma_px);
// The width t of the discrete kernel exp(-i^2 / 2 t^2), |i| <= GaussianTaps(s), normalised, whose variance is
// exactly s^2. Sampling a narrow Gaussian at whole pixels loses most of its variance (s = 0.3 px would keep a tenth:
// r 0.6 px drawn as 0.18) and truncating it at 3 s a little, so t > s; from s = 1 px on they differ by ~1 %.
double GaussianKernelSigma(double sigma_px);

// CPU reference: the shader's separable kernel (normalised, clamp-to-edge) on CV_32FC4 premultiplied linear RGBA.
// Every blur function here (CPU and GL) refuses a radius CheckBlurRadius refuses; r = 0 leaves the image as it is.
cv::Mat GaussianBlurCpu(const cv::Mat& rgba, double r_px);

// The pillbox kernel for radius r (px): weight clamp(R + 0.5 - distance, 0, 1), normalised, (2 t + 1)^2 taps with
// t = ceil(R + 0.5), where R = DiscCoverageRadiusPx(r) is the coverage radius whose discrete kernel has exactly the
// line-spread variance r^2 / 4 of the DESIGN.md unit. The same formula as shaders/blur_disc.frag.
double DiscCoverageRadiusPx(double r_px);
cv::Mat DiscKernel(double r_px);
cv::Mat DiscBlurCpu(const cv::Mat& rgba, double r_px);

// Multiplies the image's spectrum by transfer(f), f the radial frequency in cycles per pixel, the image taken as
// band-limited samples mirrored about its borders (through its DCT: no padding, no wrap-around). `transfer` must be
// real and even (a symmetric PSF) and is called from several threads. CV_32FC4 in and out.
cv::Mat FilterInFrequency(const cv::Mat& rgba, const std::function<double(double)>& transfer);

// Second-order Butterworth low-pass (the thesis's pre-research filter), in the frequency domain:
// H = 1 / (1 + (D / D0)^(2 n)), D the distance from zero frequency in cycles per image width, D0 = cutoff.
// The image is mirror-padded first so its borders do not wrap around. Throws Error(kDomain) unless the cut-off is
// in (0, kMaxCutoffCyclesPerWidth] and the order in 1..16.
cv::Mat ButterworthBlurCpu(const cv::Mat& rgba, double cutoff_cycles_per_width, int order = 2);
// (Its equivalent Gaussian, which the record states, is scene::ButterworthEquivalentSigma.)
// The depth-matching study's stimulus (thesis 3.2): `picture` (8-bit sRGB, alpha = its shape) scaled to
// `height_px`, low-passed by the 2nd-order Butterworth at `cutoff` cycles per picture width (0 = sharp), centred on
// a uniform grey field of `field` size with linear grey level `grey`. Returns 8-bit BGR sRGB.
cv::Mat PictureOnGrey(const cv::Mat& picture, cv::Size field, int height_px, double cutoff, double grey = 0.18);

// `picture` scaled to height_px with a transparent margin of margin_px, passed through filter(layer, picture width
// in px) as CV_32FC4 linear premultiplied, and composited centred on a uniform field of linear grey. 8-bit BGR sRGB.
cv::Mat PictureOnField(const cv::Mat& picture, cv::Size field, int height_px, int margin_px,
                       const std::function<cv::Mat(const cv::Mat&, int)>& filter, double grey);

// A scene::DepthMatchingLayout's frame: `upper` (a PictureOnGrey of the upper half's size) over `lower` (a
// LowerHalf), stacked into `frame` (allocated only when its size changes: a trial stepping through levels reuses
// it). 8-bit BGR.
void StackDepthMatchingFrame(const cv::Mat& upper, const cv::Mat& lower, cv::Mat* frame);

// 8-bit sRGB BGR/BGRA/grey -> CV_32FC4 linear premultiplied BGRA, and back (alpha kept when `keep_alpha`).
cv::Mat ToLinearPremultiplied(const cv::Mat& image8);
cv::Mat FromLinearPremultiplied(const cv::Mat& rgba, bool keep_alpha);

class Texture;
class GrowingTarget;
class FullscreenPass;
class GaussianBlurShader;
class DiscBlurShader;
class KernelBlurShader;

// The GPU path. Needs a current GL context; loads its shaders from ShaderDir(). Its scratch texture is made once and
// grown, so blurring layer after layer in a frame loop allocates nothing.
class GlBlur {
 public:
  GlBlur();
  ~GlBlur();
  GlBlur(const GlBlur&) = delete;
  GlBlur& operator=(const GlBlur&) = delete;
  // CV_32FC4 in and out through a texture: BlurTexture on a copy.
  cv::Mat BlurImage(const cv::Mat& rgba, const std::string& method, double r_px);
  cv::Mat BlurImage(const cv::Mat& rgba, const Psf& psf);
  // Two passes (horizontal, vertical) of the Gaussian of r = 2 s.
  cv::Mat Gaussian(const cv::Mat& rgba, double r_px) { return BlurImage(rgba, "gaussian", r_px); }
  // One pass of the pillbox of radius r.
  cv::Mat Disc(const cv::Mat& rgba, double r_px) { return BlurImage(rgba, "disc", r_px); }
  // On the GPU, texture in and out (RGBA32F, same size): "gaussian" or "disc"; r <= 0 leaves it unchanged.
  void BlurTexture(Texture& texture, const std::string& method, double r_px);
  void BlurTexture(Texture& texture, const Psf& psf);
  // One layer's blur: a rectangle of a texture (its own image: the kernel clamps at its border) and its PSF: the
  // separable Gaussian's two passes, the pillbox's one, or a general kernel's one (Psf::General: a streak, a pillbox
  // with a floor; PsfKernel's weights, worked out on the CPU and uploaded into a kernel atlas made once and grown).
  struct Region {
    cv::Rect rect;
    Psf psf;
  };
  // Blurs each region of `target` in place; regions must not overlap, and outside them nothing is read or written.
  // Every region's first pass runs, then every region's second, so llvmpipe renders each stage of a frame's layers
  // in one go (its cost is per pass, not per layer).
  void BlurRegions(GrowingTarget& target, const std::vector<Region>& regions);

 private:
  void Blur(const Texture& texture, GLuint framebuffer, const std::vector<Region>& regions);
  std::unique_ptr<GaussianBlurShader> gaussian_;
  std::unique_ptr<DiscBlurShader> disc_;
  std::unique_ptr<KernelBlurShader> kernel_;
  std::unique_ptr<GrowingTarget> kernel_atlas_;  // the general kernels of a Blur call side by side (red channel)
  cv::Mat kernel_atlas_cpu_;                     // and their weights before the upload (kept between frames)
  std::vector<cv::Mat> kernels_;                 // per region of the last call, its general kernel and its PSF:
  std::vector<Psf> kernel_psf_;                  // reused while a region's PSF stays the same
  std::vector<cv::Point> kernel_origin_;         // per region, its kernel's place in the atlas (x < 0: none)
  std::vector<int> kernel_taps_;
  std::unique_ptr<GrowingTarget> scratch_;
  std::unique_ptr<FullscreenPass> pass_;
  std::vector<double> kernel_sigma_;  // per region of a Blur call, the Gaussian's kernel width (kept: no frame allocates)
};

}  // namespace blurcue::render
