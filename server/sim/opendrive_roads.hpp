// An OpenDRIVE network (server/road/opendrive.hpp) as the roads a session drives on: every road's
// lanes, heights and marks where the file puts them, and a world position's place found through a
// grid of points sampled along the reference lines.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec2.hpp>

#include "server/road/opendrive.hpp"
#include "server/sim/road_network.hpp"

namespace downpour::sim {

class OpenDriveRoads final : public RoadNetwork {
 public:
  explicit OpenDriveRoads(road::Network network);
  const road::Network& network() const { return network_; }

  int road_count() const override { return static_cast<int>(network_.roads.size()); }
  std::string road_id(int road) const override { return network_.roads[road].id; }
  double road_length(int road) const override { return network_.roads[road].length; }
  bool road_loops(int) const override { return false; }
  bool connecting(int road) const override { return network_.roads[road].junction != "-1"; }
  std::vector<double> section_starts(int road) const override;
  TrackFrame frame(int road, double s) const override;
  double surface_height(const RoadPlace& place) const override;
  PavedSpan paved(int road, double s) const override;
  LaneLayout lanes(int road, double s) const override;
  RoadPlace project(glm::dvec2 xy, double fine_within_m = 1e30) const override;
  RoadPlace project_near(glm::dvec2 xy, const RoadPlace& guess) const override;
  void bounds(glm::dvec2& lo, glm::dvec2& hi) const override { lo = lo_, hi = hi_; }

  // How far a place lies off its road (m): beyond the paved width across, or past the road's ends
  // along it; 0 on it.
  double off_road(glm::dvec2 xy, const RoadPlace& place) const;

 private:
  struct Sample {
    glm::dvec2 xy;
    double s = 0.0;
    int road = 0;
  };
  // The foot of the perpendicular from xy on a road's reference line, from s.
  RoadPlace foot(int road, glm::dvec2 xy, double s) const;
  glm::ivec2 cell_of(glm::dvec2 xy) const;

  road::Network network_;
  std::vector<Sample> samples_;
  // Samples by grid cell (kCellM square from lo_), as index ranges into cell_samples_.
  std::vector<std::uint32_t> cell_start_, cell_samples_;
  std::vector<std::uint32_t> near_;  // by cell: a sample near it (its nearest, or nearly)
  glm::ivec2 cells_{0};
  double cell_m_ = 16.0;
  glm::dvec2 lo_{0.0}, hi_{0.0};
  double widest_m_ = 0.0;  // the largest distance of a paved edge from its reference line
};

}  // namespace downpour::sim
