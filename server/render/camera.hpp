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
// A forward (dash) camera for the COCKPIT view: on the centre line just behind the glass, in front
// of the mirror, looking ahead a little down.
sim::CameraPose dash_camera_pose();

// The view's camera: ViewSpec::camera where given (ROAD: an outside camera; COCKPIT: a camera in
// the cabin, e.g. dash_camera_pose(), instead of the driver's eye), else the view's default.
Camera make_camera(const sim::ViewSpec& spec, const sim::VehicleState& vehicle);

}  // namespace downpour::render
