#include "calib/phase_fit.h"

#include <algorithm>
#include <array>
#include <cmath>

#include "calib/family_esf.h"

namespace blurcue::calib {
namespace {

constexpr double kMinSigmaPx = 0.3, kMaxSigmaPx = 1.6, kMinAmount = 0.02, kMaxAmount = 1.5;

// The second moment of the Gaussian at whole pixels an unsharp mask subtracts (px^2): the mask's is -amount x it.
double GaussianTapsVariance(double sigma_px) { return detail::TapsVariance(detail::FamilyTaps({sigma_px, 0})); }

// The search's point: a Gaussian's std; a mask's std and the magnitude of its taps' second moment, amount x
// GaussianTapsVariance(std) (px^2). The profiles pin that second moment (a section reads sqrt(r1^2 + 4 V)) far more
// than the std: their chi-square is a narrow valley along amount x variance = const, curved in (std, amount), where
// the search from the grid's 0.7 at 0.6 px stayed put for a true 0.25 at 0.9 px (chi-square per point 3.5, edges
// 4-7 read 7-12 % high, undetermined_coverage.py's seed 12). Along std at a held second moment the valley is an axis.
PhaseFamily FromPoint(const std::array<double, 2>& x, bool mask) {
  PhaseFamily f;
  f.sigma_px = std::clamp(x[0], kMinSigmaPx, kMaxSigmaPx);
  f.sharpen = mask ? std::clamp(x[1] / GaussianTapsVariance(f.sigma_px), kMinAmount, kMaxAmount) : 0.0;
  f.fitted = true;
  return f;
}

}  // namespace

PhaseFamily RefinePhaseFamily(const PhaseFamily& start, const std::function<double(const PhaseFamily&)>& chi2,
                              int evaluations) {
  if (!(start.sigma_px > 0)) return start;
  // A Gaussian has one parameter (its std), an unsharp mask two (std, second moment: FromPoint): a simplex of n + 1
  // points. The first steps are about a grid step of PhaseFamilies() (0.1 px in std; 0.1 in amount at the start's
  // std), so the search starts across the valley between the families it lies in.
  const bool mask = start.sharpen > 0;
  const int n = mask ? 2 : 1;
  using Point = std::array<double, 2>;
  const double g0 = GaussianTapsVariance(start.sigma_px);
  std::vector<Point> x(n + 1, Point{start.sigma_px, start.sharpen * g0});
  x[1][0] += start.sigma_px + 0.1 > kMaxSigmaPx ? -0.1 : 0.1;
  if (mask) x[2][1] += (start.sharpen + 0.1 > kMaxAmount ? -0.1 : 0.1) * g0;
  int used = 0;
  auto value = [&](const Point& p) {
    ++used;
    return chi2(FromPoint(p, mask));
  };
  std::vector<double> v(n + 1);
  for (int i = 0; i <= n; ++i) v[i] = value(x[i]);
  while (used + 2 <= evaluations) {
    std::vector<int> order(n + 1);
    for (int i = 0; i <= n; ++i) order[i] = i;
    std::sort(order.begin(), order.end(), [&](int a, int b) { return v[a] < v[b]; });
    const int best = order[0], worst = order[n], second = order[n - 1];
    Point centre{0, 0};
    for (int i = 0; i <= n; ++i)
      if (i != worst)
        for (int k = 0; k < n; ++k) centre[k] += x[i][k] / n;
    auto along = [&](double t) {
      Point p = x[worst];
      for (int k = 0; k < n; ++k) p[k] = centre[k] + t * (x[worst][k] - centre[k]);
      p[0] = std::clamp(p[0], kMinSigmaPx, kMaxSigmaPx);
      if (mask) {
        const double g = GaussianTapsVariance(p[0]);
        p[1] = std::clamp(p[1], kMinAmount * g, kMaxAmount * g);
      }
      return p;
    };
    const Point reflected = along(-1);
    const double vr = value(reflected);
    if (vr < v[best]) {
      const Point expanded = along(-2);
      const double ve = value(expanded);
      if (ve < vr) x[worst] = expanded, v[worst] = ve;
      else x[worst] = reflected, v[worst] = vr;
    } else if (vr < v[second]) {
      x[worst] = reflected, v[worst] = vr;
    } else {
      const Point contracted = along(0.5);
      const double vc = value(contracted);
      if (vc < std::min(vr, v[worst])) {
        x[worst] = contracted, v[worst] = vc;
      } else {  // shrink towards the best
        for (int i = 0; i <= n && used < evaluations; ++i)
          if (i != best) {
            for (int k = 0; k < n; ++k) x[i][k] = 0.5 * (x[i][k] + x[best][k]);
            v[i] = value(x[i]);
          }
      }
    }
    // Settled: the simplex spans under 0.01 px in std and 0.01 x the start's Gaussian variance in second moment
    // (about 0.01 in amount).
    double span = 0;
    for (int i = 0; i <= n; ++i)
      for (int k = 0; k < n; ++k) span = std::max(span, std::abs(x[i][k] - x[best][k]) / (k == 0 ? 1 : g0));
    if (span < 0.01) break;
  }
  const int best = static_cast<int>(std::min_element(v.begin(), v.end()) - v.begin());
  return FromPoint(x[best], mask);
}

std::array<PhaseFamily, 2> ValleyEnds(const PhaseFamily& found, const std::function<double(const PhaseFamily&)>& chi2,
                                      double margin) {
  std::array<PhaseFamily, 2> ends{found, found};
  if (!(found.sharpen > 0 && found.sigma_px > 0)) return ends;
  const double second = found.sharpen * GaussianTapsVariance(found.sigma_px), limit = chi2(found) + margin;
  for (int side = 0; side < 2; ++side)
    for (int step = 1; step <= 15; ++step) {
      const double sigma = found.sigma_px + (side == 0 ? -0.02 : 0.02) * step;
      if (sigma < kMinSigmaPx || sigma > kMaxSigmaPx) break;
      ends[side] = FromPoint({sigma, second}, true);
      if (chi2(ends[side]) > limit) break;
    }
  return ends;
}

}  // namespace blurcue::calib
