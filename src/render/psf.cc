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

// The segment from -L/2 to L/2 along unit d, n points spread bilinearly; its variances along d and across it.
cv::Mat Splat(const cv::Vec2d& d, double length, int n, double* along, double* across) {
  const int h = int(std::ceil(length / 2)) + 1;
  cv::Mat k = cv::Mat::zeros(2 * h + 1, 2 * h + 1, CV_32F);
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
  double sum = 0, second_along = 0, second_across = 0;
  for (int y = 0; y < k.rows; ++y)
    for (int x = 0; x < k.cols; ++x) {
      const double w = k.at<float>(y, x), u = (x - h) * d[0] + (y - h) * d[1], v = -(x - h) * d[1] + (y - h) * d[0];
      sum += w, second_along += w * u * u, second_across += w * v * v;
    }
  *along = second_along / sum, *across = second_across / sum;
  return k / sum;
}

// The anisotropic part of an elliptical PSF: a kernel whose covariance is exactly mu I + D, with D = [[d, c], [c, -d]]
// the ellipse's deviator and mu = |d| + |c| the least isotropic variance that lets it be drawn with non-negative
// weights: the n-fold convolution of one point-symmetric 3 x 3 kernel of covariance (mu I + D) / n (covariances add),
// weights alpha at (+-1, 0), beta at (0, +-1), gamma+ at +-(1, 1), gamma- at +-(1, -1), the rest at the centre:
// xx = 2 (alpha + gamma+ + gamma-), yy = 2 (beta + gamma+ + gamma-), xy = 2 (gamma+ - gamma-). n is the fewest copies
// whose centre weight stays >= 0. No search: the moments are exact by construction, from sub-pixel up.
int AnisotropicCopies(double d, double c) { return std::max(1, int(std::ceil(2 * (std::abs(d) + std::abs(c)) - std::abs(c)))); }
cv::Mat AnisotropicKernel(double d, double c, double* mu_px2) {
  const double mu = std::abs(d) + std::abs(c);
  *mu_px2 = mu;
  const int n = AnisotropicCopies(d, c);
  const double xx = (mu + d) / n, yy = (mu - d) / n, xy = c / n;
  const double gp = std::max(xy, 0.0) / 2, gm = std::max(-xy, 0.0) / 2;
  const double alpha = xx / 2 - gp - gm, beta = yy / 2 - gp - gm;
  // Row y = -1, 0, +1; column x = -1, 0, +1.
  cv::Mat k3 = (cv::Mat_<float>(3, 3) << float(gp), float(beta), float(gm),  //
                float(alpha), float(1 - 2 * (alpha + beta + gp + gm)), float(alpha),  //
                float(gm), float(beta), float(gp));
  cv::Mat k = k3;
  for (int i = 1; i < n; ++i) k = Convolve(k, k3);
  return k;
}

// The ellipse's deviator ((xx - yy) / 2, xy of r^2 / 4 x shape shape^T), px^2, and its mean variance (trace / 2).
cv::Vec2d DeviatorOf(const Psf& psf, double* mean_px2) {
  const cv::Matx22d m = psf.shape * psf.shape.t() * (psf.r_px * psf.r_px / 4);
  *mean_px2 = 0.5 * (m(0, 0) + m(1, 1));
  return {0.5 * (m(0, 0) - m(1, 1)), m(0, 1)};
}

}  // namespace

cv::Mat StreakKernel(const cv::Vec2d& m, double* across_px2) {
  const double length = cv::norm(m);
  if (across_px2) *across_px2 = 0;
  if (!(length > 0)) return cv::Mat::ones(1, 1, CV_32F);
  const cv::Vec2d d = m / length;
  // The drawn length whose kernel's variance along d exceeds its variance across by the continuous segment's,
  // L^2 / 12: the samples' bilinear spreading adds some both ways (PsfKernel takes the across part out of the
  // isotropic part), their spacing takes some away. The excess grows with the drawn length: bisect.
  const double target = length * length / 12;
  double lo = 0, hi = length + 2, along = 0, across = 0;
  const int n = int(std::ceil(8 * hi)) + 1;  // 8 samples a px or more, one count for the whole search (continuous in L)
  for (int i = 0; i < 40; ++i) {
    const double mid = 0.5 * (lo + hi);
    Splat(d, mid, n, &along, &across);
    (along - across < target ? lo : hi) = mid;
  }
  cv::Mat k = Splat(d, 0.5 * (lo + hi), n, &along, &across);
  if (across_px2) *across_px2 = across;
  return k;
}

namespace {
}  // namespace

double Psf::FloorSigmaPx() const { return std::clamp(floor_sigma_px, 0.0, std::max(0.0, r_px) / 2); }

double Psf::DefocusRadiusPx() const {
  const double f = FloorSigmaPx();
  return std::sqrt(std::max(0.0, r_px * r_px - 4 * f * f));
}

bool Psf::Stretched() const { return shape != cv::Matx22d(1, 0, 0, 1); }

double Psf::RadiusAcrossPx(const cv::Vec2d& normal) const {
  const double len = cv::norm(normal);
  if (!(len > 0)) return r_px;
  return r_px * cv::norm(shape.t() * (normal / len));
}

double Psf::FloorAcrossPx(const cv::Vec2d& normal) const {
  const double len = cv::norm(normal);
  if (!(len > 0)) return FloorSigmaPx();
  return FloorSigmaPx() * cv::norm(shape.t() * (normal / len));
}

bool Psf::General() const {
  return MotionLengthPx() > 0 || Stretched() || (method == "disc" && FloorSigmaPx() > 0);
}

bool Psf::operator==(const Psf& o) const {
  return method == o.method && r_px == o.r_px && floor_sigma_px == o.floor_sigma_px && motion_px == o.motion_px &&
         shape == o.shape;
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
  const cv::Matx22d& m = psf.shape;
  const double det = m(0, 0) * m(1, 1) - m(0, 1) * m(1, 0);
  const cv::Matx22d mm = m * m.t();
  const double largest = 0.5 * (mm(0, 0) + mm(1, 1)) + std::hypot(0.5 * (mm(0, 0) - mm(1, 1)), mm(0, 1));
  if (!(std::abs(det - 1) <= 1e-6 && largest <= 4))  // NaN fails too; a stretch of 2 is far past any real lens's
    throw Error(ErrorKind::kDomain, "PSF shape must have determinant 1 and stretch by at most 2, got [" +
                                        Num(m(0, 0)) + ", " + Num(m(0, 1)) + "; " + Num(m(1, 0)) + ", " +
                                        Num(m(1, 1)) + "]");
}

cv::Mat PsfKernel(const Psf& psf) {
  CheckPsf(psf);
  // A shape first: its anisotropic part is one small kernel (AnisotropicKernel) that also adds an isotropic mu, taken
  // out of the round part like the streak's spreading; the round part is drawn at the ellipse's mean variance (its
  // defocus and floor scaled alike by sqrt(trace / 2) / (r / 2)).
  double mean = psf.r_px * psf.r_px / 4, e = 0;
  cv::Mat stretch;
  if (psf.Stretched() && psf.r_px > 0) {
    const cv::Vec2d dev = DeviatorOf(psf, &mean);
    stretch = AnisotropicKernel(dev[0], dev[1], &e);
  }
  const double scale = psf.r_px > 0 ? std::sqrt(mean) / (psf.r_px / 2) : 1.0;
  // The streak: the variance its spreading adds across it (and the shape's mu: e) is taken out of the isotropic part
  // (the floor first, then the defocus), so that across the motion the kernel's variance is r^2 / 4 and along it
  // r^2 / 4 + L^2 / 12. Where r^2 / 4 < e (a sub-pixel defocus under a diagonal streak) what is left over stays.
  double e_streak = 0;
  const cv::Mat streak = psf.MotionLengthPx() > 0 ? StreakKernel(psf.motion_px, &e_streak) : cv::Mat();
  e += e_streak;
  cv::Mat iso;
  if (psf.method == "disc") {
    const double f = psf.FloorSigmaPx() * scale, R = psf.DefocusRadiusPx() * scale;
    const double f2 = f * f - e;
    const double R_drawn = f2 >= 0 ? R : std::sqrt(std::max(0.0, R * R + 4 * f2));
    cv::Mat disc = R_drawn > 0 ? DiscKernel(R_drawn) : cv::Mat::ones(1, 1, CV_32F);
    iso = Convolve(disc, GaussianKernel2d(std::sqrt(std::max(0.0, f2))));
  } else {
    iso = GaussianKernel2d(std::sqrt(std::max(0.0, mean - e)));
  }
  cv::Mat k = streak.empty() ? iso : Convolve(iso, streak);
  if (!stretch.empty()) k = Convolve(k, stretch);
  return k / cv::sum(k)[0];
}

double DrawnRadiusPx(const Psf& psf) {
  // The spreading's variance across is at most 1/4 px^2 (a bilinear splat's): from r = 1 px on it is inside r.
  if (!(psf.MotionLengthPx() > 0) || psf.r_px >= 1) return psf.r_px;
  double across = 0;
  StreakKernel(psf.motion_px, &across);
  return std::max(psf.r_px, 2 * std::sqrt(across));
}

int PsfHalfWidth(const Psf& psf) {
  CheckPsf(psf);
  // The round part at the ellipse's mean variance (at most its largest, <= 2 r / 2 by CheckPsf) and the shape's copies.
  double mean = psf.r_px * psf.r_px / 4;
  int copies = 0;
  if (psf.Stretched() && psf.r_px > 0) {
    const cv::Vec2d dev = DeviatorOf(psf, &mean);
    copies = AnisotropicCopies(dev[0], dev[1]);
  }
  const double scale = psf.r_px > 0 ? std::sqrt(mean) / (psf.r_px / 2) : 1.0;
  int h = copies;
  if (psf.method == "disc") {
    const double R = psf.DefocusRadiusPx() * scale;
    h += (R > 0 ? int(std::ceil(DiscCoverageRadiusPx(R) + 0.5)) : 0) + GaussianTaps(psf.FloorSigmaPx() * scale);
  } else {
    h += GaussianTaps(std::sqrt(mean));
  }
  // The streak's drawn length is at most L + 2 (StreakKernel's search).
  if (psf.MotionLengthPx() > 0) h += int(std::ceil((psf.MotionLengthPx() + 2) / 2)) + 1;
  return h;
}

}  // namespace blurcue::render
