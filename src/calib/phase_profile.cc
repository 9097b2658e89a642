#include "calib/phase_profile.h"

#include <algorithm>
#include <cmath>

#include "calib/edge_window.h"

namespace blurcue::calib::detail {
namespace {

constexpr double kBinPx = 0.1;  // one row's samples share a distance across a level edge: bins far finer than 1 px
// The noise std (linear) is taken to be no less than this: a noise-free 8-bit image still has its quantisation.
constexpr double kMinNoise = 5e-4;
constexpr size_t kMinNoiseSamples = 12;

// The mean of the middle half: robust to a printing spot as the median is, without snapping to 8-bit code values.
double InterquartileMean(std::vector<float>& v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size(), lo = n / 4, hi = std::max(lo + 1, n - n / 4);
  double sum = 0;
  for (size_t i = lo; i < hi; ++i) sum += v[i];
  return sum / double(hi - lo);
}

}  // namespace

std::vector<Bin> ProfileBins(const cv::Mat& linear, const EdgeSegment& segment, double along_fraction,
                             double half_px, size_t min_samples, double* noise) {
  const EdgeFrame f = MakeEdgeFrame(segment);
  const double margin = 0.5 * (1 - std::clamp(along_fraction, 0.0, 1.0)) * f.length;
  const double bow = std::isfinite(segment.bow_px) ? segment.bow_px : 0;
  const int nb = static_cast<int>(std::ceil(2 * half_px / kBinPx));
  std::vector<std::vector<float>> values(nb);
  std::vector<double> sum_d(nb, 0.0);
  double xmin = 1e18, xmax = -1e18, ymin = 1e18, ymax = -1e18;
  for (double s : {margin, f.length - margin})
    for (double d : {-half_px, half_px}) {
      const cv::Point2d p = f.a + s * f.t + d * f.n;
      xmin = std::min(xmin, p.x), xmax = std::max(xmax, p.x), ymin = std::min(ymin, p.y), ymax = std::max(ymax, p.y);
    }
  const int x0 = std::max(0, int(std::ceil(xmin))), x1 = std::min(linear.cols - 1, int(std::floor(xmax)));
  const int y0 = std::max(0, int(std::ceil(ymin))), y1 = std::min(linear.rows - 1, int(std::floor(ymax)));
  for (int y = y0; y <= y1; ++y) {
    const float* row = linear.ptr<float>(y);
    for (int x = x0; x <= x1; ++x) {
      const cv::Point2d q(x - f.a.x, y - f.a.y);
      const double s = q.dot(f.t);
      if (s < margin || s > f.length - margin || !std::isfinite(row[x])) continue;
      const double u = 2 * s / f.length - 1;
      const double d = q.dot(f.n) - bow * (1 - u * u);
      if (std::abs(d) > half_px) continue;
      const int i = std::clamp(static_cast<int>((d + half_px) / kBinPx), 0, nb - 1);
      values[i].push_back(row[x]);
      sum_d[i] += d;
    }
  }
  std::vector<Bin> bins;
  std::vector<float> dev, dev2;  // |value - its bin's middle|: the noise, robustly (a spot is a few of them)
  for (int i = 0; i < nb; ++i)
    if (values[i].size() >= std::max<size_t>(1, min_samples)) {
      const double n = static_cast<double>(values[i].size());
      bins.push_back({sum_d[i] / n, InterquartileMean(values[i]), n});
      // A pair's deviations from its mean are sqrt(3/4) of a triple's (std sqrt(1/2) against sqrt(2/3) of the noise's).
      const double scale = n >= 3 ? 1 : std::sqrt(4.0 / 3);
      for (const float v : values[i]) (n >= 3 ? dev : dev2).push_back(float(std::abs(v - bins.back().v) * scale));
    }
  if (dev.size() < kMinNoiseSamples) dev.insert(dev.end(), dev2.begin(), dev2.end());
  *noise = kMinNoise;
  if (!dev.empty()) {
    std::nth_element(dev.begin(), dev.begin() + dev.size() / 2, dev.end());
    *noise = std::max(kMinNoise, 1.4826 * dev[dev.size() / 2]);
  }
  return bins;
}

}  // namespace blurcue::calib::detail
