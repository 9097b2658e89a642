#include "plan/power.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace blurcue::plan {

double BinomialPmf(int k, int n, double p) {
  if (k < 0 || k > n) return 0;
  if (p <= 0) return k == 0 ? 1 : 0;
  if (p >= 1) return k == n ? 1 : 0;
  const double log_choose = std::lgamma(n + 1.0) - std::lgamma(k + 1.0) - std::lgamma(n - k + 1.0);
  return std::exp(log_choose + k * std::log(p) + (n - k) * std::log1p(-p));
}

double BinomialTestP(int k, int n, double p) {
  if (n <= 0) return 1;
  // scipy.stats.binomtest, alternative "two-sided": the outcomes whose probability is at most d * (1 + 1e-7).
  const double d = BinomialPmf(k, n, p);
  const double bound = d * (1 + 1e-7);
  double total = 0;
  for (int j = 0; j <= n; ++j) {
    const double q = BinomialPmf(j, n, p);
    if (q <= bound) total += q;
  }
  return std::min(1.0, total);
}

double OneParticipantTestP(int k, int n, double chance) {
  return n < 2 ? std::numeric_limits<double>::quiet_NaN() : BinomialTestP(k, n, chance);
}

std::vector<double> BinomialTestPAll(int n, double p) {
  if (n <= 0) return {1.0};
  std::vector<double> pmf(size_t(n) + 1);
  for (int j = 0; j <= n; ++j) pmf[size_t(j)] = BinomialPmf(j, n, p);
  std::vector<double> sorted = pmf;
  std::sort(sorted.begin(), sorted.end());
  std::vector<double> below(sorted.size() + 1, 0);  // below[i]: the sum of the i least likely outcomes
  for (size_t i = 0; i < sorted.size(); ++i) below[i + 1] = below[i] + sorted[i];
  std::vector<double> out(pmf.size());
  for (size_t k = 0; k < pmf.size(); ++k) {
    const double bound = pmf[k] * (1 + 1e-7);
    const size_t count = size_t(std::upper_bound(sorted.begin(), sorted.end(), bound) - sorted.begin());
    out[k] = std::min(1.0, below[count]);
  }
  return out;
}

std::pair<double, double> Wilson95(int k, int n) {
  if (n <= 0) return {0, 1};
  const double z = 1.959963984540054;  // the 97.5 % point of the standard normal
  const double p = double(k) / n, denom = 1 + z * z / n;
  const double centre = (p + z * z / (2.0 * n)) / denom;
  const double half = z / denom * std::sqrt(p * (1 - p) / n + z * z / (4.0 * n * n));
  // At k = 0 and k = n the bound is exactly 0 or 1, as the report's stats.wilson.
  return {k == 0 ? 0.0 : std::max(0.0, centre - half), k == n ? 1.0 : std::min(1.0, centre + half)};
}

namespace {

// Lentz's continued fraction for I_x(a, b) (Numerical Recipes 6.4), converging for x < (a + 1) / (a + b + 2).
double BetaContinuedFraction(double a, double b, double x) {
  const double tiny = 1e-300;
  double c = 1, d = 1 - (a + b) * x / (a + 1);
  if (std::abs(d) < tiny) d = tiny;
  d = 1 / d;
  double h = d;
  for (int m = 1; m <= 500; ++m) {
    const double m2 = 2.0 * m;
    double aa = m * (b - m) * x / ((a + m2 - 1) * (a + m2));
    d = 1 + aa * d;
    if (std::abs(d) < tiny) d = tiny;
    c = 1 + aa / c;
    if (std::abs(c) < tiny) c = tiny;
    d = 1 / d;
    h *= d * c;
    aa = -(a + m) * (a + b + m) * x / ((a + m2) * (a + m2 + 1));
    d = 1 + aa * d;
    if (std::abs(d) < tiny) d = tiny;
    c = 1 + aa / c;
    if (std::abs(c) < tiny) c = tiny;
    d = 1 / d;
    const double step = d * c;
    h *= step;
    if (std::abs(step - 1) < 1e-15) break;
  }
  return h;
}

}  // namespace

double IncompleteBeta(double a, double b, double x) {
  if (x <= 0) return 0;
  if (x >= 1) return 1;
  const double front =
      std::exp(std::lgamma(a + b) - std::lgamma(a) - std::lgamma(b) + a * std::log(x) + b * std::log1p(-x));
  // The fraction converges fast on one side of the mean; use the symmetry I_x(a, b) = 1 - I_{1-x}(b, a) on the other.
  if (x < (a + 1) / (a + b + 2)) return front * BetaContinuedFraction(a, b, x) / a;
  return 1 - front * BetaContinuedFraction(b, a, 1 - x) / b;
}

double OneSampleTTestP(const std::vector<double>& values, double mu) {
  const size_t n = values.size();
  if (n < 2) return 1;
  double mean = 0;
  for (double v : values) mean += v;
  mean /= double(n);
  double ss = 0;
  for (double v : values) ss += (v - mean) * (v - mean);
  const double sd = std::sqrt(ss / double(n - 1));
  if (!(sd > 1e-12)) return std::abs(mean - mu) > 1e-12 ? 0 : 1;
  const double t = (mean - mu) / (sd / std::sqrt(double(n)));
  const double df = double(n - 1);
  // P(|T| > |t|) = I_{df / (df + t^2)}(df / 2, 1 / 2).
  return IncompleteBeta(df / 2, 0.5, df / (df + t * t));
}

double WelchTTestP(const std::vector<double>& a, const std::vector<double>& b) {
  if (a.size() < 2 || b.size() < 2) return 1;
  auto moments = [](const std::vector<double>& v) {
    double mean = 0, ss = 0;
    for (double x : v) mean += x;
    mean /= double(v.size());
    for (double x : v) ss += (x - mean) * (x - mean);
    return std::pair<double, double>{mean, ss / double(v.size() - 1) / double(v.size())};  // mean, its variance
  };
  const auto [ma, va] = moments(a);
  const auto [mb, vb] = moments(b);
  const double se2 = va + vb;
  if (!(se2 > 1e-24)) return std::abs(ma - mb) > 1e-12 ? 0 : 1;
  const double t = (ma - mb) / std::sqrt(se2);
  const double df = se2 * se2 / (va * va / double(a.size() - 1) + vb * vb / double(b.size() - 1));
  return IncompleteBeta(df / 2, 0.5, df / (df + t * t));
}

double StudentT975(int df) {
  // Two-sided P(|T| > t) = I_{df / (df + t^2)}(df / 2, 1 / 2) falls from 1 at t = 0: find where it is 0.05.
  double lo = 0, hi = 1e6;
  for (int i = 0; i < 200 && hi - lo > 1e-10; ++i) {
    const double t = (lo + hi) / 2;
    (IncompleteBeta(df / 2.0, 0.5, df / (df + t * t)) > 0.05 ? lo : hi) = t;
  }
  return (lo + hi) / 2;
}

double OlsSlope(const std::vector<std::pair<double, double>>& points) {
  const double n = double(points.size());
  double mx = 0, my = 0;
  for (const auto& [x, y] : points) mx += x, my += y;
  mx /= n, my /= n;
  double sxx = 0, sxy = 0;
  for (const auto& [x, y] : points) sxx += (x - mx) * (x - mx), sxy += (x - mx) * (y - my);
  return points.size() >= 2 && sxx > 1e-12 ? sxy / sxx : std::numeric_limits<double>::quiet_NaN();
}

double SignFlipNormalP(double sum, double square, double step) {
  if (!(square > 0)) return 1;
  return std::min(1.0, std::erfc(std::max(0.0, std::abs(sum) - step) / std::sqrt(2 * square)));
}

double SignFlipP(const std::vector<double>& deviations) {
  const size_t g = deviations.size();
  if (g == 0) return std::numeric_limits<double>::quiet_NaN();
  double observed = 0, square = 0;
  for (const double d : deviations) observed += d, square += d * d;
  const double target = std::abs(observed) - 1e-9;
  if (target <= 0) return 1;  // a sum of 0: every pattern is as far
  // Beyond 24 participants the sum of independent +-d has its normal limit (mean 0, variance the sum of d^2), its
  // lattice corrected by the smallest step (equal deviations: the exact binomial's continuity correction); 2^12 sums
  // a half below that.
  if (g > kSignFlipExactUpTo) {
    double step = INFINITY;
    for (const double d : deviations)
      if (std::abs(d) > 1e-12) step = std::min(step, std::abs(d));
    return SignFlipNormalP(observed, square, step);
  }
  // The sums of every sign pattern of one half.
  auto sums = [&](size_t from, size_t to) {
    std::vector<double> out(size_t(1) << (to - from));
    for (size_t mask = 0; mask < out.size(); ++mask) {
      double s = 0;
      for (size_t i = from; i < to; ++i) s += (mask >> (i - from) & 1) ? deviations[i] : -deviations[i];
      out[mask] = s;
    }
    return out;
  };
  const std::vector<double> a = sums(0, g / 2);
  std::vector<double> b = sums(g / 2, g);
  std::sort(b.begin(), b.end());
  double hits = 0;
  for (const double x : a) {
    // |x + y| >= target: y >= target - x, or y <= -target - x.
    hits += double(b.end() - std::lower_bound(b.begin(), b.end(), target - x));
    hits += double(std::upper_bound(b.begin(), b.end(), -target - x) - b.begin());
  }
  return std::min(1.0, hits / std::ldexp(1.0, int(g)));
}

}  // namespace blurcue::plan
