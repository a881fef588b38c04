#include "server/sim/pose.hpp"

#include <cmath>

#include <glm/trigonometric.hpp>

namespace downpour::sim {

glm::dmat3 rotation_matrix(const Rotation& rotation) {
  const double cy = std::cos(glm::radians(rotation.yaw_deg));
  const double sy = std::sin(glm::radians(rotation.yaw_deg));
  const double cp = std::cos(glm::radians(rotation.pitch_deg));
  const double sp = std::sin(glm::radians(rotation.pitch_deg));
  const double cr = std::cos(glm::radians(rotation.roll_deg));
  const double sr = std::sin(glm::radians(rotation.roll_deg));
  // glm is column-major: each glm::dvec3 below is one column.
  const glm::dmat3 rz(glm::dvec3(cy, sy, 0), glm::dvec3(-sy, cy, 0), glm::dvec3(0, 0, 1));
  const glm::dmat3 ry(glm::dvec3(cp, 0, -sp), glm::dvec3(0, 1, 0), glm::dvec3(sp, 0, cp));
  const glm::dmat3 rx(glm::dvec3(1, 0, 0), glm::dvec3(0, cr, sr), glm::dvec3(0, -sr, cr));
  return rz * ry * rx;
}

glm::dmat4 vehicle_to_world(const VehicleState& vehicle) {
  glm::dmat4 m(rotation_matrix(vehicle.rotation));
  m[3] = glm::dvec4(vehicle.position_m, 1.0);
  return m;
}

}  // namespace downpour::sim
