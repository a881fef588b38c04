#include "server/render/cpu/client_background.hpp"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/matrix.hpp>

#include "server/sim/pose.hpp"

namespace downpour::render {

PictureCamera picture_camera(const Camera& camera) {
  const glm::mat4 to_world = glm::inverse(camera.view);
  PictureCamera c;
  c.right = glm::normalize(glm::vec3(to_world[0]));
  c.up = glm::normalize(glm::vec3(to_world[1]));
  c.forward = -glm::normalize(glm::vec3(to_world[2]));
  c.tan_x = static_cast<float>(camera.tan_half_fov_x);
  c.tan_y = static_cast<float>(camera.tan_half_fov_y);
  return c;
}

GroundPlane ground_plane(const Camera& camera, const sim::VehicleState& vehicle) {
  const glm::dmat4 to_world = sim::vehicle_to_world(vehicle);
  const glm::dvec3 normal = glm::normalize(glm::dvec3(to_world[2]));
  const glm::dvec3 under = glm::dvec3(to_world[3]);
  GroundPlane g;
  g.normal = glm::vec3(normal);
  g.camera_height_m = static_cast<float>(glm::dot(normal, glm::dvec3(camera.position) - under));
  return g;
}

float ground_depth_m(const PictureCamera& c, const GroundPlane& g, float x, float y) {
  // A ray of unit length along the view's axis: the distance it runs to the ground is the depth.
  const glm::vec3 ray = c.forward + (x * c.tan_x) * c.right + (y * c.tan_y) * c.up;
  const float down = -glm::dot(g.normal, ray);
  return down > 1e-6f && g.camera_height_m > 0.0f ? g.camera_height_m / down : 0.0f;
}

void picture_layer_depth_cm(const sim::ClientImage* image, const PictureCamera& camera,
                            const GroundPlane& ground, int width, int height, std::uint16_t far_cm,
                            std::vector<std::uint16_t>& out) {
  out.assign(static_cast<std::size_t>(width) * height, far_cm);
  auto to_cm = [far_cm](float m) {
    return m > 0.0f ? static_cast<std::uint16_t>(std::min(m * 100.0f + 0.5f, float(far_cm)))
                    : far_cm;
  };
  if (image && !image->depth_m.empty() && width > 0 && height > 0) {
    const int w = image->width, h = image->height;
    for (int j = 0; j < height; ++j) {
      // Rows bottom-up, in the layer and the picture.
      const int y0 = j * h / height, y1 = std::max(y0 + 1, (j + 1) * h / height);
      for (int i = 0; i < width; ++i) {
        const int x0 = i * w / width, x1 = std::max(x0 + 1, (i + 1) * w / width);
        float nearest = 0.0f;
        for (int y = y0; y < std::min(y1, h); ++y) {
          const float* row = &image->depth_m[static_cast<std::size_t>(y) * w];
          for (int x = x0; x < std::min(x1, w); ++x) {
            if (row[x] > 0.0f && (nearest == 0.0f || row[x] < nearest)) nearest = row[x];
          }
        }
        out[static_cast<std::size_t>(j) * width + i] = to_cm(nearest);
      }
    }
    return;
  }
  for (int j = 0; j < height; ++j) {
    const float y = 2.0f * (j + 0.5f) / height - 1.0f;
    for (int i = 0; i < width; ++i) {
      const float x = 2.0f * (i + 0.5f) / width - 1.0f;
      out[static_cast<std::size_t>(j) * width + i] = to_cm(ground_depth_m(camera, ground, x, y));
    }
  }
}

}  // namespace downpour::render
