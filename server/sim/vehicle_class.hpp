// The traffic's vehicle classes: each one's shape at its usual size, in the vehicle frame (x
// forward from the ground point under the rear axle, y left, z up). A vehicle of another size is
// this shape scaled to it; its lamps move with it.
#pragma once

#include <glm/vec3.hpp>

#include "server/sim/types.hpp"

namespace downpour::sim {

struct VehicleLayout {
  glm::dvec3 size_m;       // length, width, height
  double rear_m;           // the rear bumper's x (negative: behind the rear axle)
  glm::dvec3 headlamp_m;   // the left headlamp's centre (a motorbike: its one lamp, y = 0)
  glm::dvec3 tail_lamp_m;  // the left tail lamp's centre (likewise)
  double wheel_radius_m;
};

const VehicleLayout& vehicle_layout(VehicleClass c);
// A vehicle's size against its class's: what its shape is scaled by.
glm::dvec3 layout_scale(const TrafficVehicle& v);

}  // namespace downpour::sim
