// Fuzz target: OpenDRIVE text -> parse_opendrive. A bad file is refused with ParseError (naming
// the element and line); one that parses must be usable: every road's reference line, lanes and
// surface finite wherever they are evaluated.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <string_view>

#include "server/road/opendrive.hpp"

namespace {

void require(bool ok) {
  if (!ok) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace downpour::road;
  Limits limits;
  limits.max_bytes = 1 << 20;
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
  return 0;
}
