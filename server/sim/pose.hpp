// Rotations and frames: world right-handed z up, vehicle x forward, y left, z up (ISO 8855).
#pragma once

#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>

#include "server/sim/types.hpp"

namespace downpour::sim {

// R = Rz(yaw) * Ry(pitch) * Rx(roll); columns are the rotated frame's axes in the parent frame.
glm::dmat3 rotation_matrix(const Rotation& rotation);

// Vehicle frame -> world frame.
glm::dmat4 vehicle_to_world(const VehicleState& vehicle);

}  // namespace downpour::sim
