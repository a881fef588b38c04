// The benchmarks' order statistics: one definition, so that every tool's medians and percentiles
// are the same kind of figure.
#pragma once

#include <algorithm>
#include <chrono>
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

// What one thing adds to whole frames: `frames` pairs of frames, one with it (with(), wall time)
// and one without (without()), drawn in turn after `warm_up` pairs, which first alternating, so
// that a machine whose speed drifts, or a frame that slows the next, affects both alike. The median
// of the pairs' differences, and of the frames with it.
struct Added {
  double added_ms = 0.0;
  double frame_ms = 0.0;
};
template <typename With, typename Without>
Added added_to_frames(int frames, int warm_up, With&& with, Without&& without) {
  std::vector<double> added, whole;
  for (int i = 0; i < frames + warm_up; ++i) {
    double ms[2];
    for (int j = 0; j < 2; ++j) {
      const int k = (i + j) % 2;  // which goes first alternates: a frame after the other's
      const auto t0 = std::chrono::steady_clock::now();
      if (k == 0) {
        with();
      } else {
        without();
      }
      ms[k] =
          std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    }
    if (i < warm_up) continue;
    added.push_back(ms[0] - ms[1]);
    whole.push_back(ms[0]);
  }
  return {median(added), median(whole)};
}

}  // namespace downpour::bench
