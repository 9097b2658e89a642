#include "synth/post_filter.h"

#include <cmath>

#include <opencv2/imgproc.hpp>

#include "core/error.h"

namespace blurcue::synth {

const char* Name(PostFilter filter) {
  switch (filter) {
    case PostFilter::kNone: return "none";
    case PostFilter::kGaussian: return "gaussian";
    case PostFilter::kSharpen: return "sharpen";
  }
  return "none";
}

PostFilter ParsePostFilter(const std::string& text) {
  for (const PostFilter f : {PostFilter::kNone, PostFilter::kGaussian, PostFilter::kSharpen})
    if (text == Name(f)) return f;
  throw Error(ErrorKind::kUsage, "--post-filter must be none, gaussian or sharpen, got '" + text + "'");
}

std::vector<float> PostFilterTaps(const PostFilterOptions& o) {
  if (o.kind == PostFilter::kNone || !(o.sigma_px > 0)) return {1.0f};
  // Out to 4 sigma, and at least one tap each side: a std well under a pixel still weighs the neighbours (that is
  // what makes the profile depend on the edge's phase).
  const int reach = std::max(1, static_cast<int>(std::ceil(4 * o.sigma_px)));
  std::vector<double> g(2 * reach + 1);
  double sum = 0;
  for (int k = -reach; k <= reach; ++k) sum += g[k + reach] = std::exp(-0.5 * (k / o.sigma_px) * (k / o.sigma_px));
  std::vector<float> taps(g.size());
  for (size_t i = 0; i < g.size(); ++i) {
    double t = g[i] / sum;
    if (o.kind == PostFilter::kSharpen) t = (static_cast<int>(i) == reach ? 1 + o.amount : 0) - o.amount * t;
    taps[i] = static_cast<float>(t);
  }
  return taps;
}

double PostFilterVariancePx2(const std::vector<float>& taps) {
  const int reach = static_cast<int>(taps.size()) / 2;
  double sum = 0, second = 0;
  for (int k = -reach; k <= reach; ++k) sum += taps[k + reach], second += double(k) * k * taps[k + reach];
  return second / sum;
}

Json PostFilterTruth(const PostFilterOptions& o, const std::vector<float>& taps) {
  Json list = Json::array();
  for (const float t : taps) list.push_back(t);
  return {{"kind", Name(o.kind)}, {"sigma_px", o.sigma_px}, {"amount", o.amount}, {"taps", list},
          {"variance_px2", PostFilterVariancePx2(taps)},
          {"note", "applied to the sampled image (rows and columns) after the noise; every section's r_px^2 = "
                   "r_optical_px^2 + 4 variance_px2 (the taps' second moment)"}};
}

void ApplyPostFilter(cv::Mat& linear, const std::vector<float>& taps) {
  CV_Assert(linear.type() == CV_32FC1);
  if (taps.size() <= 1) return;
  const cv::Mat k(taps, true);
  cv::sepFilter2D(linear, linear, CV_32F, k, k, cv::Point(-1, -1), 0, cv::BORDER_REPLICATE);
}

}  // namespace blurcue::synth
