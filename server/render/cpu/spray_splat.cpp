#include "server/render/cpu/spray_splat.hpp"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

namespace downpour::render {
namespace {

// The pixels (inclusive) a view-space ball may cover, from its centre's projection and a bound on
// its radius in pixels; false if off the maps or behind the camera.
bool footprint(const SprayCamera& c, const SprayBall& b, float grow, int& x0, int& x1, int& y0,
               int& y1) {
  const float z = -b.centre.z;
  if (z <= b.radius * 0.5f || z <= 1e-3f) return false;
  const float sx = (b.centre.x / (z * c.tan_half_fov.x) * 0.5f + 0.5f) * c.width;
  const float sy = (b.centre.y / (z * c.tan_half_fov.y) * 0.5f + 0.5f) * c.height;
  // A sphere's outline is wider than radius / z where it is near or off the axis: grow.
  const float reach = grow * b.radius / (z * c.tan_half_fov.y) * 0.5f * c.height + 0.5f;
  x0 = std::max(0, static_cast<int>(std::floor(sx - reach)));
  x1 = std::min(c.width - 1, static_cast<int>(std::floor(sx + reach)));
  y0 = std::max(0, static_cast<int>(std::floor(sy - reach)));
  y1 = std::min(c.height - 1, static_cast<int>(std::floor(sy + reach)));
  return x0 <= x1 && y0 <= y1;
}

}  // namespace

void splat_depth(const SprayCamera& c, const std::vector<SprayBall>& body,
                 const std::vector<SprayBall>& spray, SprayDepthMaps& maps) {
  maps.width = c.width;
  maps.height = c.height;
  const std::size_t n = static_cast<std::size_t>(c.width) * c.height;
  maps.depth.assign(n, glm::vec4(kSprayFar));
  maps.mask.assign(n, 0.0f);
  const float kx = 2.0f * c.tan_half_fov.x / c.width, ky = 2.0f * c.tan_half_fov.y / c.height;
  for (int kind = 0; kind < 2; ++kind) {
    for (const SprayBall& b : kind == 0 ? body : spray) {
      int x0, x1, y0, y1;
      if (!footprint(c, b, 1.3f, x0, x1, y0, y1)) continue;
      const float cc = glm::dot(b.centre, b.centre) - b.radius * b.radius;
      for (int y = y0; y <= y1; ++y) {
        const float ry = (y + 0.5f) * ky - c.tan_half_fov.y;
        for (int x = x0; x <= x1; ++x) {
          // The ray (rx, ry, -1): |d|^2 t^2 - 2 (d.c) t + cc = 0; distance along -z is t.
          const float rx = (x + 0.5f) * kx - c.tan_half_fov.x;
          const float dd = rx * rx + ry * ry + 1.0f;
          const float dc = rx * b.centre.x + ry * b.centre.y - b.centre.z;
          const float disc = dc * dc - dd * cc;
          if (disc <= 0.0f) continue;
          const float s = std::sqrt(disc);
          const float front = (dc - s) / dd, back = (dc + s) / dd;
          if (front <= 0.0f) continue;
          const std::size_t i = static_cast<std::size_t>(y) * c.width + x;
          glm::vec4& d = maps.depth[i];
          if (kind == 0) {
            d.x = std::min(d.x, front);
            d.y = std::min(d.y, -back);
          } else {
            d.z = std::min(d.z, front);
            d.w = std::min(d.w, -back);
          }
          // 1 for spray, 2 for the body: the smoothing passes only where the body is.
          maps.mask[i] = std::max(maps.mask[i], kind == 0 ? kSprayMaskBody : kSprayMaskSpray);
        }
      }
    }
  }
}

void splat_haze(const SprayCamera& c, const std::vector<SprayHazeBall>& clouds,
                std::vector<glm::vec2>& out) {
  out.assign(static_cast<std::size_t>(c.width) * c.height, glm::vec2(0.0f));
  for (const SprayHazeBall& h : clouds) {
    int x0, x1, y0, y1;
    if (!footprint(c, h.ball, 1.0f, x0, x1, y0, y1)) continue;
    const float z = -h.ball.centre.z;
    const float to_px = 0.5f * c.height / (z * c.tan_half_fov.y);
    const float cx = (h.ball.centre.x / (z * c.tan_half_fov.x) * 0.5f + 0.5f) * c.width;
    const float cy = (h.ball.centre.y / (z * c.tan_half_fov.y) * 0.5f + 0.5f) * c.height;
    const float inv_r2 = 1.0f / std::max(h.ball.radius * to_px * h.ball.radius * to_px, 0.25f);
    const float tau0 = 2.0f * h.depth;
    for (int y = y0; y <= y1; ++y) {
      const float dy = y + 0.5f - cy;
      for (int x = x0; x <= x1; ++x) {
        const float dx = x + 0.5f - cx;
        const float b2 = (dx * dx + dy * dy) * inv_r2;
        if (b2 >= 1.0f) continue;
        const float edge = 1.0f - b2;
        const float tau = tau0 * edge * edge;
        glm::vec2& o = out[static_cast<std::size_t>(y) * c.width + x];
        o.x += tau;
        o.y += tau * z;
      }
    }
  }
}

}  // namespace downpour::render
