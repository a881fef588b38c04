#include "server/sim/road_network.hpp"

#include <algorithm>

#include <glm/common.hpp>

namespace downpour::sim {

LaneLayout TrackRoads::lanes(int, double) const {
  // Lanes each way, a shoulder beyond them; a double centre line, dashed lane lines, and an edge
  // line on each shoulder 0.2 m out from the last lane.
  const CrossSection& c = track_.cross_section();
  LaneLayout out;
  const double half = track_.paved_half_width();
  out.borders.push_back(-half);
  for (int k = c.lanes_each_way; k >= 1; --k) out.borders.push_back(-k * c.lane_width_m);
  out.centre = static_cast<int>(out.borders.size());
  out.borders.push_back(0.0);
  for (int k = 1; k <= c.lanes_each_way; ++k) out.borders.push_back(k * c.lane_width_m);
  out.borders.push_back(half);
  const auto n = static_cast<int>(out.borders.size());
  out.marks.resize(n);
  out.driving.assign(n - 1, 1);
  out.driving.front() = out.driving.back() = 0;  // the shoulders
  for (int i = 0; i < n; ++i) {
    const int from_centre = std::abs(i - out.centre);
    LaneMark& m = out.marks[i];
    if (from_centre == 0) {
      m = {LaneMark::Kind::kSolidSolid, 0.14, 0.0, 0.4, false};
    } else if (from_centre < c.lanes_each_way) {
      m = {LaneMark::Kind::kBroken, 0.15, 0.0, 0.3, false};
    } else if (from_centre == c.lanes_each_way) {
      m = {LaneMark::Kind::kSolid, 0.2, 0.2, 0.3, false};
    }
  }
  return out;
}

RoadPlace TrackRoads::project(glm::dvec2 xy, double fine_within_m) const {
  const Track::Projection p = track_.project(xy, fine_within_m);
  return {0, p.s, p.lateral};
}

RoadPlace TrackRoads::project_near(glm::dvec2 xy, const RoadPlace& guess) const {
  const Track::Projection p = track_.project_near(xy, guess.s);
  return {0, p.s, p.lateral};
}

TrackRoads::TrackRoads(const Track& track) : track_(track) {
  glm::dvec2& lo = lo_;
  glm::dvec2& hi = hi_;
  lo = glm::dvec2(1e300), hi = glm::dvec2(-1e300);
  const double half = track_.paved_half_width();
  for (double s = 0.0; s < track_.length(); s += 5.0) {
    const TrackFrame f = track_.at(s);
    for (const double side : {-half, half}) {
      const glm::dvec2 p = glm::dvec2(f.position) + f.left * side;
      lo = glm::min(lo, p), hi = glm::max(hi, p);
    }
  }
}

EgoPlace ego_place(const RoadNetwork& roads, glm::dvec2 xy) {
  const RoadPlace p = roads.project(xy, 30.0);
  EgoPlace out;
  out.road = roads.road_id(p.road);
  out.s_m = p.s;
  out.t_m = p.t;
  const LaneLayout layout = roads.lanes(p.road, p.s);
  out.on_road = roads.paved(p.road, p.s).contains(p.t);
  if (layout.borders.size() < 2) return out;
  // The lane holding t (beyond the edges, the outermost).
  std::size_t i = 0;
  while (i + 2 < layout.borders.size() && p.t > layout.borders[i + 1]) ++i;
  const auto index = static_cast<int>(i);
  out.lane = index >= layout.centre ? index - layout.centre + 1 : index - layout.centre;
  out.lane_offset_m = p.t - 0.5 * (layout.borders[i] + layout.borders[i + 1]);
  return out;
}

const std::shared_ptr<const RoadNetwork>& built_in_roads() {
  static const std::shared_ptr<const RoadNetwork> roads =
      std::make_shared<const TrackRoads>(Track::built_in());
  return roads;
}

}  // namespace downpour::sim
