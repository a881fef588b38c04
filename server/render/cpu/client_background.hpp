// A view whose background is the client's picture (sim::ClientImage): the camera it was taken
// from, where a direction falls in it, and the depth behind each of the view's pixels: the
// picture's own, or without one the ground under the car (the sky beyond its horizon). No GL.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "server/render/cpu/camera.hpp"
#include "server/sim/types.hpp"

namespace downpour::render {

// The camera a picture was taken from, in the world: its unit axes and the tangents of its half
// fields of view. A direction d falls at x = (d.right / d.forward) / tan_x, y likewise, each in
// [-1, 1] across the picture (y up).
struct PictureCamera {
  glm::vec3 right{1.0f, 0.0f, 0.0f};
  glm::vec3 up{0.0f, 1.0f, 0.0f};
  glm::vec3 forward{0.0f, 0.0f, -1.0f};
  float tan_x = 1.0f;
  float tan_y = 1.0f;
};
PictureCamera picture_camera(const Camera& camera);

// The ground under the car (its wheels' plane): its unit normal in the world and the camera's
// height above it.
struct GroundPlane {
  glm::vec3 normal{0.0f, 0.0f, 1.0f};
  float camera_height_m = 1.0f;
};
GroundPlane ground_plane(const Camera& camera, const sim::VehicleState& vehicle);

// The distance along the view's axis (m) behind the point at x, y (each in [-1, 1] across the view,
// y up) by the ground alone: 0 (the sky) where the ray does not meet it.
float ground_depth_m(const PictureCamera& camera, const GroundPlane& ground, float x, float y);

// The depth behind each texel of a width x height layer over the view (rows bottom-up), in whole
// centimetres along the view's axis, `far_cm` for the sky: the picture's depth where it has one
// (the nearest of the pixels under the texel that is not the sky), else the ground's.
void picture_layer_depth_cm(const sim::ClientImage* image, const PictureCamera& camera,
                            const GroundPlane& ground, int width, int height, std::uint16_t far_cm,
                            std::vector<std::uint16_t>& out);

}  // namespace downpour::render
