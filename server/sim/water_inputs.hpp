// What a step of the windshield's water takes from the rest of the simulation (water.hpp): the
// rain, the air over the glass and the blades. Its own header so that the parts of a step
// (rain_arrival, blade_sweep) read it without the coordinator that includes them.
#pragma once

#include <array>

#include <glm/vec3.hpp>

#include "server/sim/windshield.hpp"

namespace downpour::sim {

struct WaterInputs {
  double rain_rate_mm_h = 0.0;
  // Rain's velocity relative to the glass, vehicle frame, without the fall: wind minus the car's
  // own velocity (m/s). The fall (terminal speed) is added per drop size.
  glm::dvec3 air_velocity_mps{0.0};
  std::array<BladePose, 2> blades_before;  // at the start of the step
  std::array<BladePose, 2> blades_after;   // at its end
};

}  // namespace downpour::sim
