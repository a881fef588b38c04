// Cameras of the views, placed in the vehicle frame: the driver's eye, the chase camera, a dash
// camera; and their lenses.
#pragma once

#include <glm/mat3x3.hpp>
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
  // The rig in the vehicle frame: position (m) and axes (columns: forward, left, up).
  glm::dvec3 position_vehicle{0.0};
  glm::dmat3 axes_vehicle{1.0};
  glm::dmat4 view_vehicle{1.0};  // the view matrix from the vehicle's frame (view's, less the pose)
  double tan_half_fov_x = 0.0;
  double tan_half_fov_y = 0.0;
  // The lens: focus distance (m) and aperture diameter (mm); ViewSpec's or the view's default.
  double focus_m = 20.0;
  double aperture_mm = 4.0;
};

// The depth buffer's value for a point at `distance_m` along the view's axis, with the projection's
// reversed Z and infinite far plane (make_camera): near / distance, 1 at the near plane, 0 at
// infinity; and back. A distance of 0 stands for the sky (depth 0) both ways.
inline float reversed_z(float near_m, float distance_m) {
  return distance_m > 0.0f ? (distance_m > near_m ? near_m / distance_m : 1.0f) : 0.0f;
}
inline float distance_from_reversed_z(float near_m, float depth) {
  return depth > 0.0f ? near_m / depth : 0.0f;
}

// Default poses and fields of view, vehicle frame.
sim::CameraPose default_camera_pose(sim::View view,
                                    const glm::dvec3& eye_m = sim::EgoGeometry{}.eye_m);
double default_fov_deg(sim::View view);
// A forward (dash) camera for the COCKPIT view: on the centre line just behind the glass, in front
// of the mirror, looking ahead a little down.
sim::CameraPose dash_camera_pose();

// The view's camera: ViewSpec::camera where given (ROAD: an outside camera; COCKPIT: a camera in
// the cabin, e.g. dash_camera_pose(), instead of the driver's eye), else the view's default. The
// driver's eye opens its pupil to the light of `weather` (eye_pupil_mm); without it, to an
// overcast day's (4 mm).
Camera make_camera(const sim::ViewSpec& spec, const sim::VehicleState& vehicle,
                   const sim::Weather* weather = nullptr);

// The eye's pupil (mm) adapted to the light of this weather: Moon and Spencer's
// D = 4.9 - 3 tanh(0.4 log10 L), L the scene's luminance (cd/m^2): about 2 mm by day, 6 at night.
double eye_pupil_mm(const sim::Weather& weather);

}  // namespace downpour::render
