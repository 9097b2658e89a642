#include "synth/scene_distort.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace blurcue::synth::detail {
namespace {

// Keys' cubic convolution weights (a = -1/2) for taps at -1, 0, 1, 2 around fraction t in [0, 1).
inline void KeysWeights(double t, double w[4]) {
  const double t2 = t * t, t3 = t2 * t;
  w[0] = -0.5 * t3 + t2 - 0.5 * t;
  w[1] = 1.5 * t3 - 2.5 * t2 + 1;
  w[2] = -1.5 * t3 + 2 * t2 + 0.5 * t;
  w[3] = 0.5 * t3 - 0.5 * t2;
}

}  // namespace

IdealCanvas CanvasFor(const LensDistortion& distortion, int W, int H) {
  double x0 = 0, x1 = W - 1, y0 = 0, y1 = H - 1;
  auto take = [&](double x, double y) {
    const Point2 p = distortion.Undistort({x, y});
    x0 = std::min(x0, p[0]), x1 = std::max(x1, p[0]), y0 = std::min(y0, p[1]), y1 = std::max(y1, p[1]);
  };
  // Half a pixel beyond the centres: the outermost sub-pixels reach there.
  for (int x = 0; x <= W; ++x) take(x - 0.5, -0.5), take(x - 0.5, H - 0.5);
  for (int y = 0; y <= H; ++y) take(-0.5, y - 0.5), take(W - 0.5, y - 0.5);
  // Two pixels more on every side for the cubic's reach (two sub-pixels at most) and rounding.
  IdealCanvas c;
  c.ox = static_cast<int>(std::ceil(-x0)) + 2;
  c.oy = static_cast<int>(std::ceil(-y0)) + 2;
  c.width = static_cast<int>(std::ceil(x1)) + 3 + c.ox;
  c.height = static_cast<int>(std::ceil(y1)) + 3 + c.oy;
  return c;
}

std::vector<cv::Mat> DistortAndDownsample(const std::vector<cv::Mat>& ideal_ss, const LensDistortion& distortion,
                                          const IdealCanvas& canvas, int ss, int H, int W) {
  std::vector<cv::Mat> out;
  CV_Assert(ideal_ss.size() <= 4);
  for (size_t k = 0; k < ideal_ss.size(); ++k) {
    CV_Assert(ideal_ss[k].type() == CV_32F && ideal_ss[k].rows == canvas.height * ss &&
              ideal_ss[k].cols == canvas.width * ss);
    out.emplace_back(H, W, CV_32F, cv::Scalar(0));
  }
  const double inv_ss2 = 1.0 / (double(ss) * ss);
  cv::parallel_for_(cv::Range(0, H), [&](const cv::Range& range) {
    for (int Y = range.start; Y < range.end; ++Y)
      for (int X = 0; X < W; ++X) {
        std::array<double, 4> sum{};
        for (int j = 0; j < ss; ++j)
          for (int i = 0; i < ss; ++i) {
            // This sub-pixel's centre in photo px, its ideal point, and that point in canvas sub-pixel indices.
            const double xd = X + (i + 0.5) / ss - 0.5, yd = Y + (j + 0.5) / ss - 0.5;
            const Point2 p = distortion.Undistort({xd, yd});
            const double sx = (p[0] + canvas.ox + 0.5) * ss - 0.5, sy = (p[1] + canvas.oy + 0.5) * ss - 0.5;
            const int ix = static_cast<int>(std::floor(sx)), iy = static_cast<int>(std::floor(sy));
            double wx[4], wy[4];
            KeysWeights(sx - ix, wx);
            KeysWeights(sy - iy, wy);
            for (size_t k = 0; k < ideal_ss.size(); ++k) {
              const cv::Mat& img = ideal_ss[k];
              double v = 0;
              for (int b = 0; b < 4; ++b) {
                const int r = std::clamp(iy - 1 + b, 0, img.rows - 1);
                const float* row = img.ptr<float>(r);
                double h = 0;
                for (int a = 0; a < 4; ++a) h += wx[a] * row[std::clamp(ix - 1 + a, 0, img.cols - 1)];
                v += wy[b] * h;
              }
              sum[k] += v;
            }
          }
        for (size_t k = 0; k < ideal_ss.size(); ++k) out[k].at<float>(Y, X) = static_cast<float>(sum[k] * inv_ss2);
      }
  });
  return out;
}

}  // namespace blurcue::synth::detail
