#pragma once
// Tests only: an edge's blur read off a linear-light photo independently of src/calib's measurement - the plain
// differenced profile, for tests that hold synth's truth (or a drawn object's floor) against the image itself.
#include <cmath>
#include <vector>

#include <opencv2/core.hpp>

namespace blurcue::synth::testing {

// 2 x the std of the photo's line-spread function across the edge through `m` with unit normal `n` (CV_32F linear
// light): pixels within 8 px of m along the edge and 9 px across, binned at 0.1 px by signed distance, the binned
// profile differenced, its variance less the pixel's own 1/12.
inline double PhotoRadiusAcross(const cv::Mat& lin, const cv::Point2d& m, const cv::Point2d& n) {
  const cv::Point2d t(n.y, -n.x);
  const int nb = 180;
  std::vector<double> sum(nb, 0), count(nb, 0);
  for (int py = int(m.y) - 14; py <= int(m.y) + 14; ++py)
    for (int px = int(m.x) - 14; px <= int(m.x) + 14; ++px) {
      const cv::Point2d d(px - m.x, py - m.y);
      const double a = d.dot(t), c = d.dot(n);
      if (std::abs(a) > 8 || std::abs(c) >= 9) continue;
      const int b = int((c + 9) / 0.1);
      sum[b] += lin.at<float>(py, px), count[b] += 1;
    }
  std::vector<double> xs, vs;
  for (int b = 0; b < nb; ++b)
    if (count[b] > 0) xs.push_back(-9 + (b + 0.5) * 0.1), vs.push_back(sum[b] / count[b]);
  double m0 = 0, m1 = 0, m2 = 0;
  for (size_t i = 0; i + 1 < vs.size(); ++i) {
    const double g = vs[i + 1] - vs[i], xm = 0.5 * (xs[i] + xs[i + 1]);
    m0 += g, m1 += g * xm, m2 += g * xm * xm;
  }
  return 2 * std::sqrt(m2 / m0 - (m1 / m0) * (m1 / m0) - 1.0 / 12);
}

}  // namespace blurcue::synth::testing
