#include "synth/scene_blur.h"

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstdint>
#include <thread>

#include <opencv2/core.hpp>

#include "core/error.h"

namespace blurcue::synth::detail {
namespace {

// Area of a disc of radius R between y = a and y = b.
double DiscStripArea(double R, double a, double b) {
  a = std::clamp(a, -R, R), b = std::clamp(b, -R, R);
  auto F = [R](double y) { return y * std::sqrt(std::max(0.0, R * R - y * y)) + R * R * std::asin(y / R); };
  return F(b) - F(a);
}

void BuildDisc(double R, Level* l) {
  const int n = R <= 0.5 ? 0 : static_cast<int>(std::ceil(R - 0.5));
  l->reach = n;
  l->row_weight.assign(2 * n + 1, 0);
  l->row_half.assign(2 * n + 1, 0);
  double total = 0;
  for (int dy = -n; dy <= n; ++dy) {
    const double area = R > 0 ? DiscStripArea(R, dy - 0.5, dy + 0.5) : 1;
    l->row_weight[dy + n] = area;
    l->row_half[dy + n] = R > 0 ? area / 2 : 0.5;  // segment of length = area at unit density
    total += area;
  }
  for (double& w : l->row_weight) w /= total;
  l->reach = std::max(n, static_cast<int>(std::ceil(l->row_half[n] + 0.5)));
}

// Variance across columns of a disc level: each row's segment [-h, h] integrated over unit cells.
double ColumnVariance(const Level& l) {
  double v = 0;
  for (size_t k = 0; k < l.row_weight.size(); ++k) {
    const double h = l.row_half[k];
    double s = 0;
    for (int i = -static_cast<int>(h) - 1; i <= static_cast<int>(h) + 1; ++i)
      s += i * i * std::max(0.0, std::min(i + 0.5, h) - std::max(i - 0.5, -h));
    v += l.row_weight[k] * s / (2 * h);
  }
  return v;
}

double RowVariance(const std::vector<double>& w) {
  const int n = static_cast<int>(w.size()) / 2;
  double v = 0;
  for (int i = 0; i < static_cast<int>(w.size()); ++i) v += (i - n) * (i - n) * w[i];
  return v;
}

void BuildGaussian(double sigma, int n, Level* l) {
  l->taps.assign(2 * n + 1, 0);
  double total = 0;
  for (int i = -n; i <= n; ++i) total += l->taps[i + n] = std::exp(-0.5 * i * i / (sigma * sigma));
  for (double& w : l->taps) w /= total;
  l->reach = n;
}

// A kernel of the family whose discrete variance is var_ss exactly (bisection on the continuous parameter).
Level MakeLevel(double r_px, int ss, Psf psf) {
  Level l;
  l.r_px = r_px;
  l.psf = psf;
  l.var_ss = (r_px * ss) * (r_px * ss) / 4;
  if (l.var_ss <= 0) {
    l.var_ss = 0;
    l.reach = 0;
    return l;
  }
  const double target = l.var_ss;
  if (psf == Psf::kDisc) {
    double lo = 0.5, hi = 2 * std::sqrt(target) + 2;
    for (int it = 0; it < 80; ++it) {
      const double mid = 0.5 * (lo + hi);
      Level t;
      BuildDisc(mid, &t);
      (RowVariance(t.row_weight) < target ? lo : hi) = mid;
    }
    BuildDisc(0.5 * (lo + hi), &l);
    // Rows of a small disc cut into cells are not round: widen (or narrow) every row's segment by one factor so
    // the spread across columns matches the spread across rows, i.e. the kernel is isotropic in second moment.
    const std::vector<double> halves = l.row_half;
    double klo = 0.05, khi = 4;
    for (int it = 0; it < 60; ++it) {
      const double mid = 0.5 * (klo + khi);
      for (size_t k = 0; k < halves.size(); ++k) l.row_half[k] = halves[k] * mid;
      (ColumnVariance(l) < target ? klo : khi) = mid;
    }
    for (size_t k = 0; k < halves.size(); ++k) l.row_half[k] = halves[k] * 0.5 * (klo + khi);
    const int rows = static_cast<int>(l.row_weight.size()) / 2;
    l.reach = std::max(rows, static_cast<int>(std::ceil(*std::max_element(l.row_half.begin(), l.row_half.end()) + 0.5)));
  } else {
    // Width fixed first (3 sigma, at least one tap) so the variance is continuous in sigma.
    const int n = std::max(1, static_cast<int>(std::ceil(3 * std::sqrt(target))));
    double lo = 1e-3, hi = 4 * std::sqrt(target) + 4;
    for (int it = 0; it < 80; ++it) {
      const double mid = 0.5 * (lo + hi);
      Level t;
      BuildGaussian(mid, n, &t);
      (RowVariance(t.taps) < target ? lo : hi) = mid;
    }
    BuildGaussian(0.5 * (lo + hi), n, &l);
  }
  return l;
}

// Radius ladder: fine steps where the blur is about a pixel (shape matters most there), then 10 % steps.
std::vector<double> Ladder(double r_max) {
  std::vector<double> r;
  for (int i = 0; i <= 8; ++i) r.push_back(0.125 * i);
  while (r.back() < r_max) r.push_back(r.back() * 1.1);
  return r;
}

// A ring of processed rows, computed on demand. Rows are requested in a window that slides down the image, so a
// ring of twice the reach plus one never evicts a row that will be asked for again.
class RowRing {
 public:
  RowRing(int size, int width) : size_(size), width_(width), data_(size_t(size) * width), tag_(size, INT32_MIN) {}
  template <class Fill>
  const double* Get(int row, Fill&& fill) {
    const int slot = ((row % size_) + size_) % size_;
    double* p = &data_[size_t(slot) * width_];
    if (tag_[slot] != row) {
      fill(row, p);
      tag_[slot] = row;
    }
    return p;
  }

 private:
  int size_, width_;
  std::vector<double> data_;
  std::vector<int> tag_;
};

}  // namespace

std::vector<Level> ChooseLevels(double r_min, double r_max, std::optional<double> fixed, int ss, Psf psf) {
  std::vector<Level> levels;
  if (fixed) {
    levels.push_back(MakeLevel(*fixed, ss, psf));
    return levels;
  }
  const std::vector<double> ladder = Ladder(r_max);
  size_t first = 0;
  while (first + 1 < ladder.size() && ladder[first + 1] <= r_min) ++first;
  for (size_t i = first; i < ladder.size(); ++i) {
    levels.push_back(MakeLevel(ladder[i], ss, psf));
    if (ladder[i] >= r_max) break;
  }
  return levels;
}

double AppliedVarianceSs(const std::vector<Level>& levels, double r_px, int ss) {
  std::vector<double> var(levels.size());
  for (size_t k = 0; k < levels.size(); ++k) var[k] = levels[k].var_ss;
  // The same choice of levels and weights as BlurAndDownsample.
  const double v = 0.25 * r_px * ss * r_px * ss;
  int k = static_cast<int>(std::upper_bound(var.begin(), var.end(), v) - var.begin()) - 1;
  k = std::clamp(k, 0, static_cast<int>(var.size()) - 1);
  double w = 1;
  if (k + 1 < static_cast<int>(var.size())) w = std::clamp((var[k + 1] - v) / (var[k + 1] - var[k]), 0.0, 1.0);
  // Each level's own spread from its arrays: across rows and columns (equal by construction; averaged).
  auto actual = [](const Level& l) {
    if (l.identity()) return 0.0;
    if (l.psf == Psf::kGaussian) return RowVariance(l.taps);
    return 0.5 * (RowVariance(l.row_weight) + ColumnVariance(l));
  };
  double out = w * actual(levels[k]);
  if (k + 1 < static_cast<int>(levels.size())) out += (1 - w) * actual(levels[k + 1]);
  return out;
}

std::vector<double> FloorTaps(double sigma_px, int ss) {
  const double s = sigma_px * ss;
  if (!(s > 0)) return {1.0};
  const int n = std::max(1, static_cast<int>(std::ceil(4 * s)));
  std::vector<double> taps(2 * n + 1);
  double total = 0;
  for (int i = -n; i <= n; ++i) total += taps[i + n] = std::exp(-0.5 * i * i / (s * s));
  for (double& t : taps) t /= total;
  return taps;
}

double TapsVariance(const std::vector<double>& taps) { return RowVariance(taps); }

cv::Mat BlurAndDownsample(const cv::Mat& sharp, const View& view, int H, int W, const std::vector<Level>& levels,
                          int ss, int m, bool keep_subpixels) {
  const int wss = W * ss, wp = sharp.cols;
  cv::Mat out = keep_subpixels ? cv::Mat(H * ss, W * ss, CV_32F, cv::Scalar(0)) : cv::Mat(H, W, CV_32F, cv::Scalar(0));
  std::vector<double> var(levels.size());
  int max_reach = 0;
  for (size_t k = 0; k < levels.size(); ++k) var[k] = levels[k].var_ss, max_reach = std::max(max_reach, levels[k].reach);
  const double ss2 = double(ss) * ss;

  auto body = [&](const cv::Range& range) {
    // Exclusive prefix sums of sharp rows (disc); horizontally filtered rows per Gaussian level.
    RowRing prefix(2 * max_reach + 2, wp + 1);
    std::vector<std::unique_ptr<RowRing>> hrows(levels.size());
    for (size_t k = 0; k < levels.size(); ++k)
      if (levels[k].psf == Psf::kGaussian && !levels[k].identity())
        hrows[k] = std::make_unique<RowRing>(2 * levels[k].reach + 2, wp);
    std::vector<int> lo(wss);
    std::vector<double> wlo(wss), acc(wss), row_out(wss), blurred(wss);
    std::vector<float> rr(wss);

    auto fill_prefix = [&](int row, double* p) {
      const float* s = sharp.ptr<float>(row);
      double sum = 0;
      p[0] = 0;
      for (int x = 0; x < wp; ++x) p[x + 1] = sum += s[x];
    };

    for (int Y = range.start; Y < range.end; ++Y) {
      float* o = keep_subpixels ? nullptr : out.ptr<float>(Y);
      for (int y = Y * ss; y < (Y + 1) * ss; ++y) {
        const int py = y + m;  // padded row
        // Per sub-pixel: the level just below the wanted variance and its weight.
        RadiusRow(view, y, wss, rr.data());
        int lo_min = INT32_MAX, lo_max = -1;
        for (int x = 0; x < wss; ++x) {
          const double v = 0.25 * double(rr[x]) * ss * double(rr[x]) * ss;
          int k = static_cast<int>(std::upper_bound(var.begin(), var.end(), v) - var.begin()) - 1;
          k = std::clamp(k, 0, static_cast<int>(var.size()) - 1);
          double w = 1;
          if (k + 1 < static_cast<int>(var.size())) w = (var[k + 1] - v) / (var[k + 1] - var[k]);
          lo[x] = k;
          wlo[x] = std::clamp(w, 0.0, 1.0);
          lo_min = std::min(lo_min, k);
          lo_max = std::max(lo_max, k);
        }
        std::fill(row_out.begin(), row_out.end(), 0.0);
        const int k_end = std::min(lo_max + 1, static_cast<int>(levels.size()) - 1);
        for (int k = lo_min; k <= k_end; ++k) {
          // Columns that use level k with a non-zero weight.
          int x0 = wss, x1 = -1;
          for (int x = 0; x < wss; ++x) {
            const double w = lo[x] == k ? wlo[x] : (lo[x] + 1 == k ? 1 - wlo[x] : 0);
            if (w > 0) x0 = std::min(x0, x), x1 = x;
          }
          if (x1 < x0) continue;
          const Level& L = levels[k];
          if (L.identity()) {
            const float* s = sharp.ptr<float>(py) + m;
            for (int x = x0; x <= x1; ++x) blurred[x] = s[x];
          } else if (L.psf == Psf::kDisc) {
            std::fill(acc.begin() + x0, acc.begin() + x1 + 1, 0.0);
            for (int dy = -L.reach; dy <= L.reach; ++dy) {
              const int idx = dy + (static_cast<int>(L.row_weight.size()) / 2);
              if (idx < 0 || idx >= static_cast<int>(L.row_weight.size()) || L.row_weight[idx] == 0) continue;
              const double* p = prefix.Get(py + dy, fill_prefix);
              const double h = L.row_half[idx];
              // Integral of the piecewise-constant row over [X - h, X + h]: the prefix sum read with linear
              // interpolation at t + 1/2 (cells are centred on integers).
              const double th = h + 0.5, tl = -h + 0.5;
              const int oh = static_cast<int>(std::floor(th)), ol = static_cast<int>(std::floor(tl));
              const double fh = th - oh, fl = tl - ol;
              const double scale = L.row_weight[idx] / (2 * h);
              for (int x = x0; x <= x1; ++x) {
                const int X = x + m;
                const double hi_v = p[X + oh] + fh * (p[X + oh + 1] - p[X + oh]);
                const double lo_v = p[X + ol] + fl * (p[X + ol + 1] - p[X + ol]);
                acc[x] += scale * (hi_v - lo_v);
              }
            }
            for (int x = x0; x <= x1; ++x) blurred[x] = acc[x];
          } else {
            const int n = L.reach;
            auto fill_h = [&](int row, double* p) {
              const float* s = sharp.ptr<float>(row);
              for (int X = m; X < m + wss; ++X) {  // only the image's columns are read back
                double sum = 0;
                for (int i = -n; i <= n; ++i) sum += L.taps[i + n] * s[X + i];
                p[X] = sum;
              }
            };
            std::fill(acc.begin() + x0, acc.begin() + x1 + 1, 0.0);
            for (int dy = -n; dy <= n; ++dy) {
              const double* p = hrows[k]->Get(py + dy, fill_h);
              const double w = L.taps[dy + n];
              for (int x = x0; x <= x1; ++x) acc[x] += w * p[x + m];
            }
            for (int x = x0; x <= x1; ++x) blurred[x] = acc[x];
          }
          for (int x = x0; x <= x1; ++x) {
            const double w = lo[x] == k ? wlo[x] : (lo[x] + 1 == k ? 1 - wlo[x] : 0);
            row_out[x] += w * blurred[x];
          }
        }
        if (keep_subpixels) {
          float* sub = out.ptr<float>(y);
          for (int x = 0; x < wss; ++x) sub[x] = static_cast<float>(row_out[x]);
        } else {
          for (int x = 0; x < wss; ++x) o[x / ss] += static_cast<float>(row_out[x] / ss2);
        }
      }
    }
  };
  const int threads = std::max(1u, std::thread::hardware_concurrency());
  cv::parallel_for_(cv::Range(0, H), body, std::min(H, 4 * threads));
  return out;
}

}  // namespace blurcue::synth::detail
