#include "server/sim/road_surface.hpp"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "server/sim/random.hpp"

namespace downpour::sim {

namespace {

constexpr double kPi = 3.14159265358979323846;
// The seed's stream for the road's relief (random.hpp: each effect has its own).
constexpr std::uint64_t kReliefStream = 5;

double smoothstep(double t) { return t * t * (3.0 - 2.0 * t); }

}  // namespace

RoadSurface::RoadSurface(const Track& track, std::uint64_t seed)
    : track_(track), paved_half_width_(track.paved_half_width()) {
  const CrossSection& section = track.cross_section();
  for (int lane = 0; lane < section.lanes_each_way; ++lane) {
    const double centre = track.lane_centre(lane);  // right of the centreline
    for (const double side : {-1.0, 1.0}) {         // both directions of travel
      wheel_paths_.push_back(side * centre - kWheelPathOffsetM);
      wheel_paths_.push_back(side * centre + kWheelPathOffsetM);
    }
  }
  std::sort(wheel_paths_.begin(), wheel_paths_.end());
  RandomStream random(seed, kReliefStream);
  const double length = track.length();
  knots_ = std::max(1, static_cast<int>(std::ceil(length / kRutKnotM)));
  rut_depths_.resize(wheel_paths_.size() * knots_);
  for (double& depth : rut_depths_) depth = random.uniform(kRutMinDepthM, kRutMaxDepthM);
  // Traffic settles a road where its wheels run and where its edge has least support, not on the
  // crown's top: most bowls lie across a wheel path, the rest near the paved edge.
  buckets_ = std::max(1, static_cast<int>(std::ceil(length / kDepressionSpacingM)));
  depressions_.resize(buckets_);
  const double bucket_m = length / buckets_;
  for (int b = 0; b < buckets_; ++b) {
    const std::uint32_t count = random.poisson(1.0);
    for (std::uint32_t k = 0; k < count; ++k) {
      Depression d;
      d.s = (b + random.uniform()) * bucket_m;
      d.radius = random.uniform(kDepressionMinRadiusM, kDepressionMaxRadiusM);
      d.depth = random.uniform(kDepressionMinDepthM, kDepressionMaxDepthM);
      if (random.uniform() < 0.7) {
        const auto path = std::min(static_cast<std::size_t>(random.uniform() * wheel_paths_.size()),
                                   wheel_paths_.size() - 1);
        d.lateral = wheel_paths_[path] + random.uniform(-0.6, 0.6);
      } else {
        const double side = random.uniform() < 0.5 ? -1.0 : 1.0;
        d.lateral = side * (paved_half_width_ - random.uniform(0.0, 1.5));
      }
      // Clear of the crown's top by kCrownClearM, and its centre on the paved width.
      const double side = d.lateral < 0.0 ? -1.0 : 1.0;
      d.lateral =
          side * std::clamp(std::abs(d.lateral), d.radius + kCrownClearM, paved_half_width_);
      depressions_[b].push_back(d);
    }
  }
}

bool RoadSurface::paved(double lateral) const { return std::abs(lateral) <= paved_half_width_; }

double RoadSurface::rut_depth(int path, double s) const {
  const double u = s / track_.length() * knots_;  // s in [0, length)
  const int k0 = std::min(static_cast<int>(u), knots_ - 1);
  const int k1 = (k0 + 1) % knots_;
  const double t = smoothstep(std::clamp(u - k0, 0.0, 1.0));
  const double* depths = &rut_depths_[static_cast<std::size_t>(path) * knots_];
  return depths[k0] + (depths[k1] - depths[k0]) * t;
}

double RoadSurface::relief(double s, double lateral) const {
  if (!paved(lateral)) return 0.0;
  const double length = track_.length();
  s = std::fmod(s, length);
  if (s < 0.0) s += length;
  double depth = 0.0;
  // Ruts: a cos^2 profile across each wheel path (they do not overlap: paths are > 1.4 m apart).
  for (std::size_t p = 0; p < wheel_paths_.size(); ++p) {
    const double u = (lateral - wheel_paths_[p]) / kRutHalfWidthM;
    if (std::abs(u) >= 1.0) continue;
    const double c = std::cos(0.5 * kPi * u);
    depth += rut_depth(static_cast<int>(p), s) * c * c;
  }
  // Bowls: depth (1 - r^2)^2, smooth at the rim; those of this bucket and the two beside it
  // (a bowl is smaller than a bucket).
  const int bucket = std::min(static_cast<int>(s / length * buckets_), buckets_ - 1);
  for (int db = -1; db <= 1; ++db) {
    for (const Depression& d : depressions_[(bucket + db + buckets_) % buckets_]) {
      double ds = s - d.s;
      if (ds > 0.5 * length) ds -= length;  // across the loop's start
      if (ds < -0.5 * length) ds += length;
      const double dl = lateral - d.lateral;
      const double r2 = (ds * ds + dl * dl) / (d.radius * d.radius);
      if (r2 >= 1.0) continue;
      depth += d.depth * (1.0 - r2) * (1.0 - r2);
    }
  }
  return -depth;
}

double RoadSurface::height_at(double s, double lateral) const {
  return track_.surface_height(s, lateral) + relief(s, lateral);
}

double RoadSurface::height(glm::dvec2 xy) const {
  const Track::Projection p = track_.project(xy, paved_half_width_ + 1.0);
  return height_at(p.s, p.lateral);
}

}  // namespace downpour::sim
