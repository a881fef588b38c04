// Seeded random streams for the simulation: the same seed gives the same numbers on every
// platform and standard library (std:: distributions do not promise that), so lockstep runs
// reproduce anywhere.
#pragma once

#include <cmath>
#include <cstdint>

namespace downpour::sim {

class RandomStream {
 public:
  // Each effect draws from its own stream, so adding draws to one never shifts another.
  RandomStream(std::uint64_t seed, std::uint64_t stream) : state_(mix(seed ^ mix(stream + 1))) {}

  std::uint64_t next() { return mix(state_ += 0x9e3779b97f4a7c15ull); }
  // Uniform in [0, 1).
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  // Poisson by inversion, split into parts of mean <= 30 so that exp(-mean) stays accurate.
  std::uint32_t poisson(double mean) {
    std::uint32_t total = 0;
    while (mean > 0.0) {
      const double part = mean > 30.0 ? 30.0 : mean;
      mean -= part;
      double p = std::exp(-part), cumulative = p;
      const double u = uniform();
      std::uint32_t k = 0;
      while (u > cumulative && k < 1000) {
        ++k;
        p *= part / k;
        cumulative += p;
      }
      total += k;
    }
    return total;
  }

  // splitmix64's finaliser: a number scrambled, every bit of it on every bit of the result (a
  // stream's state; also a number of its own for each of a set of things, from its index).
  static std::uint64_t mix(std::uint64_t z) {
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ull;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebull;
    return z ^ (z >> 31);
  }

 private:
  std::uint64_t state_;
};

}  // namespace downpour::sim
