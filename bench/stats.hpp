// The benchmarks' order statistics: one definition, so that every tool's medians and percentiles
// are the same kind of figure.
#pragma once

#include <algorithm>
#include <cstddef>
#include <vector>

namespace downpour::bench {

// The sample nearest to the p-th quantile of v (p in [0, 1]), on ranks 0..n-1; 0 for none.
inline double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const double rank = std::clamp(p, 0.0, 1.0) * static_cast<double>(v.size() - 1);
  return v[std::min(v.size() - 1, static_cast<std::size_t>(rank + 0.5))];
}

inline double median(std::vector<double> v) { return percentile(std::move(v), 0.5); }

}  // namespace downpour::bench
