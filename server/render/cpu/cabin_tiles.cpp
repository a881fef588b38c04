#include "server/render/cpu/cabin_tiles.hpp"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>
#include <glm/vec2.hpp>

namespace downpour::render {
namespace {

// In front of the eye: the cabin's parts behind it are cut here, as the near plane cuts them.
constexpr double kNearM = 0.005;

}  // namespace

std::vector<std::uint8_t> cabin_tiles(const MeshData& cabin, const Camera& camera, int width,
                                      int height, int tile) {
  const int tiles_x = (std::max(width, 0) + tile - 1) / tile;
  const int tiles_y = (std::max(height, 0) + tile - 1) / tile;
  std::vector<std::uint8_t> hidden(static_cast<std::size_t>(tiles_x) * tiles_y, 0);
  if (tiles_x == 0 || tiles_y == 0 || camera.tan_half_fov_x <= 0.0 || camera.tan_half_fov_y <= 0.0)
    return hidden;
  std::vector<std::uint8_t> covered(static_cast<std::size_t>(width) * height, 0);
  const double sx = 0.5 * width / camera.tan_half_fov_x, sy = 0.5 * height / camera.tan_half_fov_y;
  // A vertex in the camera's frame: forward (the depth), right, up.
  auto to_camera = [&](const glm::vec3& p) {
    const glm::dvec3 d = glm::dvec3(p) - camera.position_vehicle;
    return glm::dvec3(glm::dot(d, camera.axes_vehicle[0]), -glm::dot(d, camera.axes_vehicle[1]),
                      glm::dot(d, camera.axes_vehicle[2]));
  };
  // Fills the texels whose centres lie in the triangle (on the grid, y up).
  auto fill = [&](glm::dvec2 a, glm::dvec2 b, glm::dvec2 c) {
    const double area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
    if (std::abs(area) < 1e-12) return;
    if (area < 0.0) std::swap(b, c);
    const int x0 = std::max(0, static_cast<int>(std::floor(std::min({a.x, b.x, c.x}))));
    const int x1 = std::min(width - 1, static_cast<int>(std::ceil(std::max({a.x, b.x, c.x}))));
    const int y0 = std::max(0, static_cast<int>(std::floor(std::min({a.y, b.y, c.y}))));
    const int y1 = std::min(height - 1, static_cast<int>(std::ceil(std::max({a.y, b.y, c.y}))));
    auto edge = [](glm::dvec2 p, glm::dvec2 q, glm::dvec2 r) {
      return (q.x - p.x) * (r.y - p.y) - (q.y - p.y) * (r.x - p.x);
    };
    for (int y = y0; y <= y1; ++y) {
      for (int x = x0; x <= x1; ++x) {
        const glm::dvec2 p(x + 0.5, y + 0.5);
        if (edge(a, b, p) >= 0.0 && edge(b, c, p) >= 0.0 && edge(c, a, p) >= 0.0)
          covered[static_cast<std::size_t>(y) * width + x] = 1;
      }
    }
  };
  for (std::size_t t = 0; t + 2 < cabin.indices.size(); t += 3) {
    // The triangle cut by the near plane: up to four corners.
    glm::dvec3 in[3], out[4];
    for (int k = 0; k < 3; ++k) in[k] = to_camera(cabin.vertices[cabin.indices[t + k]].position);
    int n = 0;
    for (int k = 0; k < 3; ++k) {
      const glm::dvec3& p = in[k];
      const glm::dvec3& q = in[(k + 1) % 3];
      if (p.x >= kNearM) out[n++] = p;
      if ((p.x >= kNearM) != (q.x >= kNearM))
        out[n++] = p + (q - p) * ((kNearM - p.x) / (q.x - p.x));
    }
    if (n < 3) continue;
    glm::dvec2 screen[4];
    for (int k = 0; k < n; ++k)
      screen[k] = glm::dvec2(0.5 * width + sx * out[k].y / out[k].x,
                             0.5 * height + sy * out[k].z / out[k].x);
    for (int k = 1; k + 1 < n; ++k) fill(screen[0], screen[k], screen[k + 1]);
  }
  auto covered_at = [&](int x, int y) {
    return covered[static_cast<std::size_t>(y) * width + x] != 0;
  };
  for (int ty = 0; ty < tiles_y; ++ty) {
    for (int tx = 0; tx < tiles_x; ++tx) {
      const int x0 = tx * tile, x1 = std::min((tx + 1) * tile, width);
      const int y0 = ty * tile, y1 = std::min((ty + 1) * tile, height);
      bool all = true;
      for (int y = y0; all && y < y1; ++y) {
        for (int x = x0; all && x < x1; ++x) all = covered_at(x, y);
      }
      bool any = false;  // over the tile and a texel around it
      for (int y = std::max(y0 - 1, 0); !any && y < std::min(y1 + 1, height); ++y) {
        for (int x = std::max(x0 - 1, 0); !any && x < std::min(x1 + 1, width); ++x)
          any = covered_at(x, y);
      }
      hidden[static_cast<std::size_t>(ty) * tiles_x + tx] = all   ? kCabinHidden
                                                            : any ? kCabinEdge
                                                                  : kCabinClear;
    }
  }
  return hidden;
}

}  // namespace downpour::render
