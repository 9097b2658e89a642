#include "render/blur.h"

#include <cmath>
#include <vector>

#include <opencv2/imgproc.hpp>

#include "render/gl_objects.h"

namespace blurcue::render {

int GaussianTaps(double sigma_px) { return sigma_px <= 0 ? 0 : int(std::ceil(3 * sigma_px)); }

cv::Mat GaussianBlurCpu(const cv::Mat& rgba, double r_px) {
  CV_Assert(rgba.type() == CV_32FC4);
  const double s = r_px / 2;
  const int taps = GaussianTaps(s);
  if (taps == 0) return rgba.clone();
  cv::Mat kernel(2 * taps + 1, 1, CV_32F);
  double sum = 0;
  for (int i = -taps; i <= taps; ++i) sum += kernel.at<float>(i + taps) = float(std::exp(-0.5 * i * i / (s * s)));
  kernel /= sum;
  cv::Mat out;
  cv::sepFilter2D(rgba, out, CV_32F, kernel, kernel, cv::Point(-1, -1), 0, cv::BORDER_REPLICATE);
  return out;
}

GlBlur::GlBlur()
    : gaussian_(std::make_unique<Program>(
          Program::FromFiles(ShaderDir() / "fullscreen.vert", ShaderDir() / "blur_gaussian.frag"))),
      pass_(std::make_unique<FullscreenPass>()) {}

GlBlur::~GlBlur() = default;

cv::Mat GlBlur::Gaussian(const cv::Mat& rgba, double r_px) {
  CV_Assert(rgba.type() == CV_32FC4);
  const double s = r_px / 2;
  const int taps = GaussianTaps(s);
  if (taps == 0) return rgba.clone();
  Texture source(rgba.cols, rgba.rows), middle(rgba.cols, rgba.rows), target(rgba.cols, rgba.rows);
  source.Upload(rgba);
  Framebuffer to_middle(middle), to_target(target);
  gaussian_->Use();
  glUniform1i(gaussian_->Uniform("u_image"), 0);
  glUniform1f(gaussian_->Uniform("u_sigma_px"), float(s));
  glUniform1i(gaussian_->Uniform("u_taps"), taps);
  to_middle.Bind();
  source.Bind(0);
  glUniform2f(gaussian_->Uniform("u_direction"), 1, 0);
  pass_->Draw();
  to_target.Bind();
  middle.Bind(0);
  glUniform2f(gaussian_->Uniform("u_direction"), 0, 1);
  pass_->Draw();
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  return target.Download();
}

}  // namespace blurcue::render
