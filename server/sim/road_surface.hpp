// The road's surface as a height field in world coordinates, for the water on it (seed 003's
// ground): the track's crowned cross-section and its rises and dips, the wheel paths' ruts a few
// millimetres deep, and shallow depressions placed from the session's seed. The paved width ends in
// the shoulders, whose outer edge is where water leaves the road (the water model drains it there).
// A pure function of the track, the seed and the position: the same place has the same relief
// whenever it is asked for, so water stays where it is in the world. No GL.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec2.hpp>

#include "server/sim/track.hpp"

namespace downpour::sim {

class RoadSurface {
 public:
  // Wheel paths: two per lane, this far either side of the lane's centre (a car's track is about
  // 1.6 m), each a rut of this half-width whose depth varies along the road between these (a worn
  // road's ruts: 6-13 mm is "low severity"; a rut holds water across the crown's 2% where its side
  // is steeper, past about 4.5 mm).
  static constexpr double kWheelPathOffsetM = 0.8;
  static constexpr double kRutHalfWidthM = 0.35;
  static constexpr double kRutMinDepthM = 0.003;
  static constexpr double kRutMaxDepthM = 0.010;
  static constexpr double kRutKnotM = 30.0;  // the depth's knots along the road, eased between
  // Depressions: bowls about one per kDepressionSpacingM of road, of these radii and depths
  // (settled patches of asphalt: 13-25 mm is a "moderate" depression). On the crown's slope a bowl
  // holds water only where its side is steeper than the slope, depth over radius past about 0.013.
  static constexpr double kDepressionSpacingM = 12.0;
  static constexpr double kDepressionMinRadiusM = 0.5;
  static constexpr double kDepressionMaxRadiusM = 2.0;
  static constexpr double kDepressionMinDepthM = 0.005;
  static constexpr double kDepressionMaxDepthM = 0.025;
  // No bowl reaches within this of the crown's top (it lies across wheel paths or near the edge).
  static constexpr double kCrownClearM = 0.5;

  RoadSurface(const Track& track, std::uint64_t seed);

  const Track& track() const { return track_; }

  // Ground height (world z, m) at a horizontal world position: the track's section plus the relief.
  // Off the paved width the relief is 0 (the verge, as the track's section has it).
  double height(glm::dvec2 xy) const;
  // The same in the track's coordinates: s along the centreline (wraps), lateral left positive.
  double height_at(double s, double lateral) const;
  // The relief below the track's section there (m, <= 0): ruts and depressions.
  double relief(double s, double lateral) const;
  Track::Projection project_near(glm::dvec2 xy, double s_guess) const {
    return track_.project_near(xy, s_guess);
  }
  // Whether a lateral offset is on the paved width (lanes and shoulders).
  bool paved(double lateral) const;

 private:
  struct Depression {
    double s = 0.0, lateral = 0.0, radius = 0.0, depth = 0.0;
  };
  double rut_depth(int path, double s) const;

  const Track& track_;
  double paved_half_width_ = 0.0;
  std::vector<double> wheel_paths_;  // lateral offsets of every wheel path, both directions
  int knots_ = 0;                    // rut depth knots along the loop
  std::vector<double> rut_depths_;   // [path * knots_ + knot]
  // Bowls by bucket of kDepressionSpacingM along the loop (each bowl in the bucket of its centre).
  int buckets_ = 0;
  std::vector<std::vector<Depression>> depressions_;
};

}  // namespace downpour::sim
