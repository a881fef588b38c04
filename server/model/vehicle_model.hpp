// A vehicle's shape as the renderer draws it, in the vehicle frame (x forward from the rear axle,
// y left, z up; metres): one mesh whose first triangles never move and whose wheels follow, each
// a range of indices that turns about its own axle. A cabin (the driver's dashboard, pillars,
// mirror, roof) is a model too, with the windshield's outline where its glass lies. Built in
// (default_models.hpp) or read from glTF (gltf_model.hpp). No GL.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "server/model/mesh_data.hpp"
#include "server/sim/windshield.hpp"

namespace downpour::model {

// A trim colour carried in a vertex's uv.y (vehicle.frag and cockpit.frag decode it): 0 none,
// else 1 + 5 bits each of linear red, green and blue.
inline float pack_trim_colour(double r, double g, double b) {
  auto five = [](double c) {
    return static_cast<int>(std::lround(std::clamp(c, 0.0, 1.0) * 31.0));
  };
  return static_cast<float>(1 + (five(r) << 10 | five(g) << 5 | five(b)));
}

// Its inverse (1 + the code): linear red, green and blue; none, glTF's default white.
inline std::array<double, 3> unpack_trim_colour(float code) {
  const int c = static_cast<int>(code + 0.5f) - 1;
  if (c < 0) return {1.0, 1.0, 1.0};
  return {(c >> 10 & 31) / 31.0, (c >> 5 & 31) / 31.0, (c & 31) / 31.0};
}

struct Wheel {
  glm::vec3 centre{0.0f};  // on the axle, at the wheel's middle
  float radius_m = 0.3f;
  std::uint32_t first_index = 0;  // its range of the mesh's indices
  std::uint32_t index_count = 0;
};

// Where a cabin model's windshield lies, read from its glass's triangles: the bottom edge's left
// end, the widths along its bottom and top edges, the height along the glass, its rake from
// vertical and how far it bows out of its plane (the simulated glass is flat).
struct WindshieldOutline {
  glm::dvec3 bottom_left_m{0.0};
  double bottom_width_mm = 0.0;
  double top_width_mm = 0.0;
  double height_mm = 0.0;
  double rake_deg = 0.0;
  double bow_mm = 0.0;
};

// The simulated glass an outline gives.
inline sim::GlassConfig glass_of(const WindshieldOutline& w) {
  sim::GlassConfig g;
  g.bottom_width_mm = w.bottom_width_mm;
  g.top_width_mm = w.top_width_mm;
  g.height_mm = w.height_mm;
  g.rake_deg = w.rake_deg;
  g.bottom_left_m = w.bottom_left_m;
  return g;
}

// And the outline a glass gives (flat).
inline WindshieldOutline outline_of(const sim::GlassConfig& g) {
  WindshieldOutline w;
  w.bottom_left_m = g.bottom_left_m;
  w.bottom_width_mm = g.bottom_width_mm;
  w.top_width_mm = g.top_width_mm;
  w.height_mm = g.height_mm;
  w.rake_deg = g.rake_deg;
  return w;
}

// A model's base-colour textures, each resampled to one layer of kModelTextureSide squared: RGBA,
// 8 bits, sRGB-encoded, rows from the image's top (glTF's uv (0, 0)). Shared by a model's copies
// (a session's bonnet is its body's, marked for its glass: model::bonnet_for).
inline constexpr int kModelTextureSide = 512;
struct ModelTexture {
  std::shared_ptr<const std::vector<std::uint8_t>> rgba;  // kModelTextureSide^2 * 4
};

struct VehicleModel {
  render::MeshData mesh;  // with texcoords where it has textures
  std::vector<ModelTexture> textures;
  std::uint32_t fixed_index_count = 0;  // [0, this): the parts that do not turn
  // [0, this): of those, the ones drawn from the driver's seat (mark_bonnet, default_models.hpp)
  std::uint32_t bonnet_index_count = 0;
  std::vector<Wheel> wheels;  // after them, in order
  std::optional<WindshieldOutline> windshield;

  std::size_t triangles() const { return mesh.indices.size() / 3; }
  glm::vec3 size() const {
    return mesh.vertices.empty() ? glm::vec3(0.0f) : mesh.bounds_max - mesh.bounds_min;
  }
};

}  // namespace downpour::model
