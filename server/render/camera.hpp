// Cameras of the views, placed in the vehicle frame: the driver's eye, the chase camera.
#pragma once

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "server/sim/types.hpp"

namespace downpour::render {

struct Camera {
  glm::mat4 view{1.0f};
  glm::mat4 projection{1.0f};
  glm::vec3 position{0.0f};  // world
  float fov_y_deg = 60.0f;
  float near_m = 0.05f;
};

// Default poses and fields of view, vehicle frame.
sim::CameraPose default_camera_pose(sim::View view);
double default_fov_deg(sim::View view);

Camera make_camera(const sim::ViewSpec& spec, const sim::VehicleState& vehicle);

}  // namespace downpour::render
