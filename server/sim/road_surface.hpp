// The road's surface as a height field in world coordinates, for the water on it (seed 003's
// ground): the roads' cross-sections (crown, superelevation) and their rises and dips, the wheel
// paths' ruts a few millimetres deep, and shallow depressions placed from the session's seed. The
// paved width ends in the shoulders, whose outer edge is where water leaves the road (the water
// model drains it there). A pure function of the roads, the seed and the position: the same place
// has the same relief whenever it is asked for, so water stays where it is in the world. No GL.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <glm/vec2.hpp>

#include "server/sim/road_network.hpp"

namespace downpour::sim {

class RandomStream;

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

  // The built-in track's surface (the track must outlive it).
  RoadSurface(const Track& track, std::uint64_t seed);
  // A network's: each lane section's relief its own, from the seed, in the order of the roads.
  RoadSurface(std::shared_ptr<const RoadNetwork> roads, std::uint64_t seed);

  const RoadNetwork& roads() const { return *roads_; }
  const std::shared_ptr<const RoadNetwork>& roads_shared() const { return roads_; }

  // Ground height (world z, m) at a horizontal world position: the road's section plus the relief.
  // Off the paved width the relief is 0 (the verge, as the road's section has it).
  double height(glm::dvec2 xy) const;
  // The same at a place on the roads.
  double height_at(const RoadPlace& place) const;
  // The relief below the road's section there (m, <= 0): ruts and depressions.
  double relief(const RoadPlace& place) const;
  // On the built-in track (road 0; s wraps, lateral left positive).
  double height_at(double s, double lateral) const { return height_at({0, s, lateral}); }
  double relief(double s, double lateral) const { return relief({0, s, lateral}); }
  RoadPlace project_near(glm::dvec2 xy, const RoadPlace& guess) const {
    return roads_->project_near(xy, guess);
  }
  // Whether a place is on the paved width (lanes and shoulders).
  bool paved(const RoadPlace& place) const;

 private:
  struct Depression {
    double s = 0.0, lateral = 0.0, radius = 0.0, depth = 0.0;
  };
  // A lane section's relief: its wheel paths at fixed offsets (its lanes' centres at its middle)
  // and its bowls, by bucket of kDepressionSpacingM along it.
  struct Piece {
    double s0 = 0.0, s1 = 0.0;
    PavedSpan span;                   // at its middle
    bool span_varies = false;         // its lanes' widths change along it: ask the roads
    std::vector<double> wheel_paths;  // lateral offsets of every wheel path, both directions
    int knots = 0;                    // rut depth knots along it
    std::vector<double> rut_depths;   // [path * knots + knot]
    int buckets = 0;
    std::vector<std::vector<Depression>> depressions;
  };
  void add_piece(int road, double s0, double s1, RandomStream& random);
  const Piece& piece_at(int road, double s) const;
  double rut_depth(const Piece& piece, bool loops, int path, double s) const;

  std::shared_ptr<const RoadNetwork> roads_;
  std::vector<std::vector<Piece>> pieces_;  // by road, in order along it
};

}  // namespace downpour::sim
