#pragma once
// Blur of images in linear light with premultiplied alpha, on the GPU and as a CPU reference with the same kernel.
// Radii are in the DESIGN.md unit: a Gaussian of std s has r = 2 s.
#include <memory>

#include <opencv2/core.hpp>

namespace blurcue::render {

// Half-width of the discrete Gaussian for std s: ceil(3 s), as wide as s needs and no wider.
int GaussianTaps(double sigma_px);

// CPU reference: the shader's separable kernel (normalised, clamp-to-edge) on CV_32FC4 premultiplied linear RGBA.
cv::Mat GaussianBlurCpu(const cv::Mat& rgba, double r_px);

class GlContext;
class Program;
class FullscreenPass;

// The GPU path. Needs a current GL context; loads its shaders from ShaderDir().
class GlBlur {
 public:
  GlBlur();
  ~GlBlur();
  GlBlur(const GlBlur&) = delete;
  GlBlur& operator=(const GlBlur&) = delete;
  // Two passes (horizontal, vertical) of the Gaussian of r = 2 s; CV_32FC4 in and out.
  cv::Mat Gaussian(const cv::Mat& rgba, double r_px);

 private:
  std::unique_ptr<Program> gaussian_;
  std::unique_ptr<FullscreenPass> pass_;
};

}  // namespace blurcue::render
