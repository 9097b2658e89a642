#pragma once
// Small summaries of measured samples shared by the benchmarks and the display check.
#include <algorithm>
#include <vector>

namespace blurcue {

// The q-quantile (0..1) of `values` by nearest rank (0 for no values): 0.5 the median, 0.99 the 99th percentile.
inline double Percentile(std::vector<double> values, double q) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  return values[std::min(values.size() - 1, static_cast<size_t>(q * static_cast<double>(values.size() - 1) + 0.5))];
}

}  // namespace blurcue
