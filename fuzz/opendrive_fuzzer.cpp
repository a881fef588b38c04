// Fuzz target: OpenDRIVE text -> parse_opendrive. A bad file is refused with ParseError (naming
// the element and line); one that parses must be usable: every road's reference line, lanes and
// surface finite wherever they are evaluated, and as a session's roads (sim/opendrive_roads.hpp)
// positions found on it, lanes across it, its relief and street lights finite.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string_view>

#include "server/road/opendrive.hpp"
#include "server/sim/lights.hpp"
#include "server/sim/opendrive_roads.hpp"
#include "server/sim/road_surface.hpp"

namespace {

void require(bool ok) {
  if (!ok) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace downpour::road;
  Limits limits;
  limits.max_bytes = 1 << 20;
  limits.max_total_length_m = 5000.0;  // a session's network at a fuzzer's pace
  Network net;
  try {
    net = parse_opendrive(std::string_view(reinterpret_cast<const char*>(data), size), limits);
  } catch (const ParseError& e) {
    require(!e.element().empty() && e.line() >= 0);
    return 0;
  }
  for (const Road& road : net.roads) {
    require(road.length > 0.0 && !road.plan_view.empty() && !road.sections.empty());
    for (const double f : {-0.1, 0.0, 0.31, 0.5, 0.99, 1.0, 1.2}) {
      const double s = f * road.length;
      const RefPoint p = road.reference(s);
      require(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.heading));
      for (int lane = -3; lane <= 3; ++lane) require(std::isfinite(road.lane_border(s, lane)));
      require(std::isfinite(road.surface_height(s, 2.0)));
    }
  }
  // As a session's roads.
  using namespace downpour::sim;
  // Refused as a session's roads (lanes reaching too far, a span too wide): the server answers
  // INVALID_ARGUMENT with the reason.
  std::shared_ptr<const OpenDriveRoads> roads;
  try {
    roads = std::make_shared<const OpenDriveRoads>(std::move(net));
  } catch (const std::invalid_argument& e) {
    require(e.what()[0] != '\0');
    return 0;
  }
  const RoadSurface surface(roads, 1);
  glm::dvec2 lo, hi;
  roads->bounds(lo, hi);
  require(std::isfinite(lo.x) && std::isfinite(hi.y) && lo.x <= hi.x && lo.y <= hi.y);
  for (const double fx : {-0.2, 0.0, 0.37, 0.5, 1.0, 1.3}) {
    for (const double fy : {-0.1, 0.25, 0.5, 0.9}) {
      const glm::dvec2 xy = lo + (hi - lo) * glm::dvec2(fx, fy);
      const RoadPlace p = roads->project(xy);
      require(p.road >= 0 && p.road < roads->road_count());
      require(std::isfinite(p.s) && std::isfinite(p.t));
      const RoadPlace q = roads->project_near(xy + 1.0, p);
      require(q.road >= 0 && std::isfinite(q.s) && std::isfinite(q.t));
      require(std::isfinite(surface.height_at(p)) && surface.relief(p) <= 0.0);
      const EgoPlace e = ego_place(*roads, xy);
      require(std::isfinite(e.lane_offset_m));
      const LaneLayout l = roads->lanes(p.road, p.s);
      require(l.marks.size() == l.borders.size());
      require(l.borders.empty() || l.driving.size() + 1 == l.borders.size());
    }
  }
  for (const StreetLight& light : street_lights(*roads)) {
    require(std::isfinite(light.lamp_m.z) && std::isfinite(light.foot_m.x));
  }
  return 0;
}
