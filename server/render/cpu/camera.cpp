#include "server/render/cpu/camera.hpp"

#include <algorithm>
#include <cmath>

#include <glm/trigonometric.hpp>

#include "server/render/cpu/atmosphere.hpp"
#include "server/sim/pose.hpp"

namespace downpour::render {
namespace {

constexpr double kEyeFocusM = 20.0;  // the road ahead
constexpr double kEyePupilMm = 4.0;  // an overcast day, where the weather is not given
constexpr double kCameraFocusM = 3.0;
constexpr double kCameraApertureMm = 2.0;

}  // namespace

sim::CameraPose default_camera_pose(sim::View view, const glm::dvec3& eye_m) {
  switch (view) {
    case sim::View::kRoad:
      return {{-6.5, 0.0, 2.6}, {0.0, 11.0, 0.0}};
    default:
      return {eye_m, {0.0, 2.0, 0.0}};
  }
}

double default_fov_deg(sim::View view) { return view == sim::View::kRoad ? 55.0 : 60.0; }

sim::CameraPose dash_camera_pose() { return {{1.52, 0.0, 1.21}, {0.0, 3.0, 0.0}}; }

double eye_pupil_mm(const sim::Weather& weather) {
  // The scene's luminance: the sky's light on the world, as the frame's exposure shows it (a white
  // card under E lux shows E * lux_exposure; its luminance is E / pi).
  const Atmosphere a = atmosphere_from(weather);
  const double shown = (a.ambient.r + a.ambient.g + a.ambient.b) / 3.0;
  const double luminance = std::max(shown / (M_PI * a.lux_exposure), 1e-6);
  return 4.9 - 3.0 * std::tanh(0.4 * std::log10(luminance));
}

Camera make_camera(const sim::ViewSpec& spec, const sim::VehicleState& vehicle,
                   const sim::Weather* weather) {
  const sim::CameraPose pose =
      spec.camera ? *spec.camera : default_camera_pose(spec.view, spec.eye_m);
  // Camera frame in the vehicle frame, then GL's camera axes (x right, y up, looking down -z).
  glm::dmat4 cam_in_vehicle(sim::rotation_matrix(pose.rotation));
  cam_in_vehicle[3] = glm::dvec4(pose.position_m, 1.0);
  const glm::dmat4 gl_axes(glm::dvec4(0, -1, 0, 0), glm::dvec4(0, 0, 1, 0), glm::dvec4(-1, 0, 0, 0),
                           glm::dvec4(0, 0, 0, 1));
  const glm::dmat4 cam_to_world = sim::vehicle_to_world(vehicle) * cam_in_vehicle * gl_axes;

  Camera c;
  c.fov_y_deg = static_cast<float>(spec.fov_deg > 0.0 ? spec.fov_deg : default_fov_deg(spec.view));
  c.position_vehicle = pose.position_m;
  c.axes_vehicle = sim::rotation_matrix(pose.rotation);
  c.tan_half_fov_y = std::tan(glm::radians(static_cast<double>(c.fov_y_deg)) * 0.5);
  c.tan_half_fov_x = c.tan_half_fov_y * spec.width / std::max(spec.height, 1);
  // The eye focuses on the road through its pupil; a camera of its own sees the glass's water
  // sharper (a small lens focused nearer).
  c.focus_m = spec.focus_distance_m.value_or(spec.camera ? kCameraFocusM : kEyeFocusM);
  c.aperture_mm = spec.aperture_mm.value_or(spec.camera ? kCameraApertureMm
                                            : weather   ? eye_pupil_mm(*weather)
                                                        : kEyePupilMm);
  c.position = glm::vec3(cam_to_world[3]);
  // A camera in the cabin may sit a few centimetres from the raked glass.
  if (spec.view == sim::View::kCockpit || spec.view == sim::View::kRain) c.near_m = 0.01f;
  c.view = glm::mat4(glm::inverse(cam_to_world));
  c.view_vehicle = glm::inverse(cam_in_vehicle * gl_axes);
  // Reversed-Z with an infinite far plane (clip control zero-to-one, depth test GREATER, clear 0):
  // float depth keeps its precision from the dashboard at 0.3 m to hills kilometres away.
  const float f = 1.0f / std::tan(glm::radians(c.fov_y_deg) * 0.5f);
  const float aspect = static_cast<float>(spec.width) / static_cast<float>(spec.height);
  c.projection = glm::mat4(0.0f);
  c.projection[0][0] = f / aspect;
  c.projection[1][1] = f;
  c.projection[2][3] = -1.0f;
  c.projection[3][2] = c.near_m;
  return c;
}

}  // namespace downpour::render
