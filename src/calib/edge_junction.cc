#include "calib/edge_junction.h"

#include <algorithm>
#include <cmath>

namespace blurcue::calib::detail {
namespace {

// The share of the samples whose distance from a crossing line is below t (uniform on [lo, hi]).
double Below(double t, double lo, double hi) {
  if (!(hi > lo)) return t > lo ? 1.0 : 0.0;
  return std::clamp((t - lo) / (hi - lo), 0.0, 1.0);
}

}  // namespace

JunctionShare::JunctionShare(const JunctionGeometry& g, double r, double phi) {
  const double R = std::max(0.0, r * std::cos(phi)), s = std::max(0.0, 0.5 * r * std::sin(phi));
  const double reach = R + 4 * s + 0.5;
  const int half = 24;
  const double dx = std::max(reach / half, 0.02);
  const int n = 2 * half + 1;
  // The 2-D PSF on the grid: the disc's coverage of each cell (4 x 4 points), then the Gaussian along each axis.
  std::vector<double> h(size_t(n) * n, 0.0);
  if (R > 0.5 * dx) {
    for (int i = 0; i < n; ++i)
      for (int j = 0; j < n; ++j) {
        int in = 0;
        for (int a = 0; a < 4; ++a)
          for (int b = 0; b < 4; ++b) {
            const double u = (i - half + (a + 0.5) / 4 - 0.5) * dx, v = (j - half + (b + 0.5) / 4 - 0.5) * dx;
            in += u * u + v * v <= R * R;
          }
        h[size_t(i) * n + j] = in;
      }
  } else {
    h[size_t(half) * n + half] = 1;
  }
  if (s > 0.25 * dx) {
    const int taps = std::min(half, int(std::ceil(4 * s / dx)));
    std::vector<double> k(2 * taps + 1);
    for (int t = -taps; t <= taps; ++t) k[t + taps] = std::exp(-0.5 * (t * dx / s) * (t * dx / s));
    std::vector<double> tmp(h.size(), 0.0);
    for (int i = 0; i < n; ++i)  // along v
      for (int j = 0; j < n; ++j)
        for (int t = -taps; t <= taps; ++t)
          if (j + t >= 0 && j + t < n) tmp[size_t(i) * n + j] += k[t + taps] * h[size_t(i) * n + j + t];
    std::fill(h.begin(), h.end(), 0.0);
    for (int i = 0; i < n; ++i)  // along u
      for (int t = -taps; t <= taps; ++t)
        if (i + t >= 0 && i + t < n)
          for (int j = 0; j < n; ++j) h[size_t(i) * n + j] += k[t + taps] * tmp[size_t(i + t) * n + j];
  }
  double total = 0;
  for (double w : h) total += w;
  // Per column u (across the edge): the PSF's share past a crossing line, averaged over the samples. A PSF offset
  // (u across, v along) from a sample reads the board at (d - u, s - v): past line a where the sample's distance
  // from it, c_a, is below v - ka u; past line b where c_b is below kb u - v; past the next lines (a section's length
  // further) the colour turns back.
  const double L = g.length_px;
  cumulative_.assign(n + 1, 0.0);
  for (int i = 0; i < n; ++i) {
    const double u = (i - half) * dx;
    double w = 0;
    for (int j = 0; j < n; ++j) {
      const double hv = h[size_t(i) * n + j];
      if (hv == 0) continue;
      const double v = (j - half) * dx, ta = v - g.ka * u, tb = g.kb * u - v;
      const double past = Below(ta, g.c_lo_px, g.c_hi_px) - Below(ta - L, g.c_lo_px, g.c_hi_px) +
                          Below(tb, g.c_lo_px, g.c_hi_px) - Below(tb - L, g.c_lo_px, g.c_hi_px);
      w += hv * past;
    }
    cumulative_[i + 1] = cumulative_[i] + (total > 0 ? w / total : 0);
  }
  x0_ = -(half + 0.5) * dx, dx_ = dx;
}

double JunctionShare::operator()(double x) const {
  const double t = (x - x0_) / dx_;
  if (!(t > 0)) return 0;
  const int last = int(cumulative_.size()) - 1;
  if (t >= last) return cumulative_[last];
  const int i = int(t);
  const double f = t - i;
  return (1 - f) * cumulative_[i] + f * cumulative_[i + 1];
}

}  // namespace blurcue::calib::detail
