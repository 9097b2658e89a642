#pragma once
// Small summaries of measured samples shared by the benchmarks and the display check.
#include <algorithm>
#include <cmath>
#include <vector>

namespace blurcue {

// The q-quantile (0..1) of `values` by nearest rank (0 for no values): 0.5 the median, 0.99 the 99th percentile.
inline double Percentile(std::vector<double> values, double q) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  return values[std::min(values.size() - 1, static_cast<size_t>(q * static_cast<double>(values.size() - 1) + 0.5))];
}

// The standard normal's density and distribution function.
inline double StdNormalPdf(double z) { return 0.3989422804014327 * std::exp(-0.5 * z * z); }
inline double StdNormalCdf(double z) { return 0.5 * std::erfc(-z * 0.7071067811865476); }

}  // namespace blurcue
