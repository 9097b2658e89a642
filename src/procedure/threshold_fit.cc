#include "procedure/threshold_fit.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <cstdio>
#include <stdexcept>

namespace blurcue::procedure {

namespace {

std::string Text(double v) {
  char text[32];
  std::snprintf(text, sizeof text, "%.4g", v);
  return text;
}

std::string RangeWords(double lo, double hi) { return "the tested range " + Text(lo) + " to " + Text(hi); }

}  // namespace

TrackThreshold StaircasePosterior(const StaircaseFitSpec& spec, const std::vector<double>& levels,
                                  const std::vector<bool>& correct) {
  if (!(spec.hi > 0) || !(spec.lo >= 0) || !(spec.lo < spec.hi) || !(spec.guess >= 0) ||
      !(spec.target > spec.guess) || !(spec.target < 1 - kLapses[std::size(kLapses) - 1]))
    throw std::invalid_argument("StaircasePosterior: a spec outside its bounds");
  TrackThreshold out;
  if (levels.size() != correct.size() || levels.size() < size_t(kMinAnswers)) {
    out.why =
        "not determined: " + std::to_string(levels.size()) + " answers (needs " + std::to_string(kMinAnswers) + ")";
    return out;
  }
  // The answers by level: (k correct of n) at each distinct level shown.
  std::map<double, std::pair<double, double>> at;
  for (size_t i = 0; i < levels.size(); ++i) {
    auto& [k, n] = at[std::max(0.0, levels[i])];
    k += correct[i], n += 1;
  }
  const double lo = std::max(spec.lo, spec.hi / 1000), hi = spec.hi;
  std::vector<double> log_theta(kThetaPoints), slope(kSlopePoints);
  for (int i = 0; i < kThetaPoints; ++i)
    log_theta[size_t(i)] = std::log(lo) + (std::log(hi) - std::log(lo)) * i / (kThetaPoints - 1);
  for (int j = 0; j < kSlopePoints; ++j)
    slope[size_t(j)] =
        std::exp(std::log(kSlopeLow) + (std::log(kSlopeHigh) - std::log(kSlopeLow)) * j / (kSlopePoints - 1));
  // Log-likelihood per grid point (theta, slope, lapse; lapse fastest); a level's terms only for the answers it has
  // (0 x log 0 would be NaN where the function reaches 1). The marginal over slope and lapse below is shifted by the
  // maximum for exp.
  std::vector<double> log_x, right, wrong;
  for (const auto& [x, kn] : at)
    log_x.push_back(std::log(x)), right.push_back(kn.first), wrong.push_back(kn.second - kn.first);
  constexpr size_t kLapseCount = std::size(kLapses);
  double span[kLapseCount], c[kLapseCount];
  for (size_t l = 0; l < kLapseCount; ++l) {
    span[l] = 1 - spec.guess - kLapses[l];
    c[l] = -std::log1p(-(spec.target - spec.guess) / span[l]);
  }
  std::vector<double> ll(size_t(kThetaPoints) * kSlopePoints * kLapseCount, 0.0);
  double top = -INFINITY;
  size_t g = 0;
  for (int i = 0; i < kThetaPoints; ++i)
    for (int j = 0; j < kSlopePoints; ++j, g += kLapseCount) {
      for (size_t x = 0; x < log_x.size(); ++x) {
        const double u = std::exp(slope[size_t(j)] * (log_x[x] - log_theta[size_t(i)]));  // (x / theta)^slope
        for (size_t l = 0; l < kLapseCount; ++l) {
          const double p = spec.guess - span[l] * std::expm1(-c[l] * u);
          if (right[x] > 0) ll[g + l] += right[x] * std::log(p);
          if (wrong[x] > 0) ll[g + l] += wrong[x] * std::log1p(-p);
        }
      }
      for (size_t l = 0; l < kLapseCount; ++l) top = std::max(top, ll[g + l]);
    }
  std::vector<double> cumulative(static_cast<size_t>(kThetaPoints));
  const size_t per_theta = size_t(kSlopePoints) * kLapseCount;
  double total = 0;
  for (size_t i = 0; i < size_t(kThetaPoints); ++i) {
    for (size_t k = 0; k < per_theta; ++k) total += std::exp(ll[i * per_theta + k] - top);
    cumulative[i] = total;
  }
  for (double& c : cumulative) c /= total;
  // The p quantile, each grid point's mass spread evenly over its cell in log theta (half a step either side, the
  // end cells cut at the range): the first cell whose cumulative mass reaches p, interpolated within it.
  const double step = log_theta[1] - log_theta[0];
  auto quantile = [&](double p, size_t* index) {
    const size_t k = std::min(
        size_t(std::lower_bound(cumulative.begin(), cumulative.end(), p) - cumulative.begin()), cumulative.size() - 1);
    *index = k;
    const double before = k == 0 ? 0 : cumulative[k - 1], mass = cumulative[k] - before;
    const double from = std::max(log_theta[k] - step / 2, log_theta.front());
    const double to = std::min(log_theta[k] + step / 2, log_theta.back());
    return std::exp(from + (mass > 0 ? (p - before) / mass : 0.5) * (to - from));
  };
  const double tail = (1 - kCredible) / 2;
  size_t i_median = 0, i_low = 0, i_high = 0;
  out.estimate = quantile(0.5, &i_median);
  out.low = quantile(tail, &i_low);
  out.high = quantile(1 - tail, &i_high);
  // An end in the grid's outermost cell: the answers do not bound the threshold there, the range does.
  const bool low_at_bound = i_low <= 1, high_at_bound = i_high + 2 >= size_t(kThetaPoints);
  const double tenth = (std::log(hi) - std::log(lo)) / 10;
  if (low_at_bound && high_at_bound) {
    out.why = "not determined: its 95 % interval spans the whole of " + RangeWords(spec.lo, spec.hi);
  } else if (low_at_bound && std::log(out.estimate) < std::log(lo) + tenth) {
    out.why = "not determined: below " + RangeWords(spec.lo, spec.hi) + " (the answers put it at the lowest levels)";
  } else if (high_at_bound && std::log(out.estimate) > std::log(hi) - tenth) {
    out.why = "not determined: above " + RangeWords(spec.lo, spec.hi) + " (the answers put it at the highest levels)";
  } else if (low_at_bound || high_at_bound) {
    // The answers do not bound it on that side: a number would read as measured, and an interval cut at the range
    // never holds a threshold beyond it (a true 0.41 above a range to 0.35 gave 'determined' tracks at 0.1-0.26).
    out.why = std::string("not determined: its 95 % interval reaches the ") + (low_at_bound ? "lowest" : "highest") +
              " level of " + RangeWords(spec.lo, spec.hi) + " (the answers do not bound it there)";
  } else {
    out.determined = true;
  }
  return out;
}

}  // namespace blurcue::procedure
