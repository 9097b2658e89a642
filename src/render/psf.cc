#include "render/psf.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "core/error.h"
#include "core/typed.h"
#include "render/blur.h"

namespace blurcue::render {
namespace {

std::string Num(double v) {
  std::ostringstream s;
  s << v;
  return s.str();
}

// The full 2-D convolution of two odd square kernels (the result's centre is both centres').
cv::Mat Convolve(const cv::Mat& a, const cv::Mat& b) {
  const int ha = a.rows / 2, hb = b.rows / 2, h = ha + hb;
  cv::Mat out = cv::Mat::zeros(2 * h + 1, 2 * h + 1, CV_32F);
  for (int ay = 0; ay < a.rows; ++ay)
    for (int ax = 0; ax < a.cols; ++ax) {
      const float wa = a.at<float>(ay, ax);
      if (wa == 0) continue;
      for (int by = 0; by < b.rows; ++by) {
        float* row = out.ptr<float>(ay + by) + ax;
        const float* brow = b.ptr<float>(by);
        for (int bx = 0; bx < b.cols; ++bx) row[bx] += wa * brow[bx];
      }
    }
  return out;
}

// The sampled Gaussian of std s with exactly that variance (GaussianKernelSigma), as a 2-D kernel; 1 x 1 for s = 0.
cv::Mat GaussianKernel2d(double s) {
  const int taps = GaussianTaps(s);
  if (taps == 0) return cv::Mat::ones(1, 1, CV_32F);
  const double t = GaussianKernelSigma(s);
  cv::Mat g(2 * taps + 1, 1, CV_64F);
  double sum = 0;
  for (int i = -taps; i <= taps; ++i) sum += g.at<double>(i + taps) = std::exp(-0.5 * i * i / (t * t));
  g /= sum;
  cv::Mat k = g * g.t();
  k.convertTo(k, CV_32F);
  return k;
}

// The segment from -L/2 to L/2 along unit d, n points spread bilinearly; its variance along d.
cv::Mat Splat(const cv::Vec2d& d, double length, double* variance_along) {
  const int h = int(std::ceil(length / 2)) + 1;
  cv::Mat k = cv::Mat::zeros(2 * h + 1, 2 * h + 1, CV_32F);
  const int n = std::max(2, int(std::ceil(8 * length)) + 1);
  for (int i = 0; i < n; ++i) {
    const double s = (-0.5 + (i + 0.5) / n) * length;
    const double x = h + s * d[0], y = h + s * d[1];
    const int x0 = int(std::floor(x)), y0 = int(std::floor(y));
    const double ax = x - x0, ay = y - y0;
    k.at<float>(y0, x0) += float((1 - ax) * (1 - ay) / n);
    k.at<float>(y0, x0 + 1) += float(ax * (1 - ay) / n);
    k.at<float>(y0 + 1, x0) += float((1 - ax) * ay / n);
    k.at<float>(y0 + 1, x0 + 1) += float(ax * ay / n);
  }
  double sum = 0, second = 0;
  for (int y = 0; y < k.rows; ++y)
    for (int x = 0; x < k.cols; ++x) {
      const double w = k.at<float>(y, x), u = (x - h) * d[0] + (y - h) * d[1];
      sum += w, second += w * u * u;
    }
  *variance_along = second / sum;
  return k / sum;
}

}  // namespace

double Psf::FloorSigmaPx() const { return std::clamp(floor_sigma_px, 0.0, std::max(0.0, r_px) / 2); }

double Psf::DefocusRadiusPx() const {
  const double f = FloorSigmaPx();
  return std::sqrt(std::max(0.0, r_px * r_px - 4 * f * f));
}

bool Psf::General() const {
  return MotionLengthPx() > 0 || (method == "disc" && FloorSigmaPx() > 0);
}

void CheckPsf(const Psf& psf) {
  CheckBlurRadius(psf.r_px);
  if (psf.method != "gaussian" && psf.method != "disc")
    throw Error(ErrorKind::kUsage, "blur method for objects must be gaussian or disc, got " + Echo(psf.method));
  if (!(psf.floor_sigma_px >= 0 && psf.floor_sigma_px <= kMaxBlurRadiusPx))
    throw Error(ErrorKind::kDomain, "lens floor sigma must be in [0, " + Num(kMaxBlurRadiusPx) + "] px, got " +
                                        Num(psf.floor_sigma_px));
  if (!(psf.MotionLengthPx() <= kMaxBlurRadiusPx))  // NaN fails too
    throw Error(ErrorKind::kDomain, "motion streak must be at most " + Num(kMaxBlurRadiusPx) + " px long, got (" +
                                        Num(psf.motion_px[0]) + ", " + Num(psf.motion_px[1]) + ")");
}

cv::Mat StreakKernel(const cv::Vec2d& m) {
  const double length = cv::norm(m);
  if (!(length > 0)) return cv::Mat::ones(1, 1, CV_32F);
  const cv::Vec2d d = m / length;
  // The drawn length whose kernel has the variance along d of the continuous segment, L^2 / 12: the samples'
  // spreading adds some, their spacing takes some away. The variance grows with the drawn length: bisect.
  const double target = length * length / 12;
  double lo = 0, hi = length + 2, v = 0;
  for (int i = 0; i < 40; ++i) {
    const double mid = 0.5 * (lo + hi);
    Splat(d, mid, &v);
    (v < target ? lo : hi) = mid;
  }
  return Splat(d, 0.5 * (lo + hi), &v);
}

cv::Mat PsfKernel(const Psf& psf) {
  CheckPsf(psf);
  cv::Mat iso;
  if (psf.method == "disc") {
    const double R = psf.DefocusRadiusPx();
    cv::Mat disc = R > 0 ? DiscKernel(R) : cv::Mat::ones(1, 1, CV_32F);
    iso = Convolve(disc, GaussianKernel2d(psf.FloorSigmaPx()));
  } else {
    iso = GaussianKernel2d(psf.r_px / 2);
  }
  cv::Mat k = psf.MotionLengthPx() > 0 ? Convolve(iso, StreakKernel(psf.motion_px)) : iso;
  return k / cv::sum(k)[0];
}

int PsfHalfWidth(const Psf& psf) {
  CheckPsf(psf);
  int h = 0;
  if (psf.method == "disc") {
    const double R = psf.DefocusRadiusPx();
    h = (R > 0 ? int(std::ceil(DiscCoverageRadiusPx(R) + 0.5)) : 0) + GaussianTaps(psf.FloorSigmaPx());
  } else {
    h = GaussianTaps(psf.r_px / 2);
  }
  // The streak's drawn length is at most L + 2 (StreakKernel's search).
  if (psf.MotionLengthPx() > 0) h += int(std::ceil((psf.MotionLengthPx() + 2) / 2)) + 1;
  return h;
}

}  // namespace blurcue::render
