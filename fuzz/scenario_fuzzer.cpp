// Fuzz target: scenario files (JSON) -> Scenario::from_json. A bad file is refused with
// std::runtime_error; one that loads must be usable: keyframes sorted, every sample finite, and
// it must survive a round trip through to_json.
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <stdexcept>
#include <string>

#include "server/sim/scenario.hpp"

namespace {

void require(bool ok) {
  if (!ok) std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using downpour::sim::Scenario;
  const std::string text(reinterpret_cast<const char*>(data), size);
  Scenario s;
  try {
    s = Scenario::from_json(text);
  } catch (const std::runtime_error&) {
    return 0;  // refused, with the field named
  }
  for (std::size_t i = 1; i < s.keyframes.size(); ++i)
    require(s.keyframes[i - 1].t <= s.keyframes[i].t);
  require(std::isfinite(s.duration_s) && s.duration_s >= 0.0);
  require(std::isfinite(s.fps) && s.fps > 0.0);
  // Samples inside, at the ends of and outside the timeline.
  const double end = s.keyframes.empty() ? 1.0 : s.keyframes.back().t;
  for (const double t : {-1.0, 0.0, end * 0.37, end, end + 5.0}) {
    const downpour::sim::Update u = s.at(t);
    if (u.vehicle) {
      require(std::isfinite(u.vehicle->position_m.x) && std::isfinite(u.vehicle->position_m.y) &&
              std::isfinite(u.vehicle->position_m.z));
      require(std::isfinite(u.vehicle->rotation.yaw_deg));
    }
    if (u.weather) require(std::isfinite(u.weather->rain_rate_mm_h));
  }
  // What it writes, it reads back.
  const Scenario again = Scenario::from_json(s.to_json());
  require(again.keyframes.size() == s.keyframes.size());
  require(again.views.size() == s.views.size());
  return 0;
}
