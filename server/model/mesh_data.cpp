#include "server/model/mesh_data.hpp"

#include <algorithm>
#include <cmath>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

namespace downpour::render {

float pack_lane_mark(int kind, bool yellow, double width_m, double offset_m, double spacing_m) {
  auto cm = [](double m, int lo, int hi) {
    return std::clamp(static_cast<int>(std::lround(m * 100.0)), lo, hi);
  };
  const int code = std::clamp(kind, 0, 7) | (yellow ? 8 : 0) | cm(width_m, 0, 63) << 4 |
                   (cm(offset_m, -64, 63) + 64) << 10 | cm(spacing_m, 0, 127) << 17;
  return static_cast<float>(code);
}

std::uint32_t MeshData::add_vertex(const glm::vec3& p, const glm::vec3& n, const glm::vec2& uv) {
  vertices.push_back({p, n, uv});
  bounds_min = glm::min(bounds_min, p);
  bounds_max = glm::max(bounds_max, p);
  return static_cast<std::uint32_t>(vertices.size() - 1);
}

void MeshData::add_face(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c,
                        const glm::vec3& d, float material) {
  const glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
  const glm::vec2 uv(material, 0.0f);
  add_quad(add_vertex(a, n, uv), add_vertex(b, n, uv), add_vertex(c, n, uv), add_vertex(d, n, uv));
}

void MeshData::add_box(const glm::vec3& lo, const glm::vec3& hi, float material) {
  add_frustum(lo, hi, glm::vec2(lo), glm::vec2(hi), material);
}

void MeshData::add_frustum(const glm::vec3& lo, const glm::vec3& hi, const glm::vec2& top_lo,
                           const glm::vec2& top_hi, float material) {
  // Bottom corners b0..b3 and top corners t0..t3, counter-clockwise seen from above.
  const glm::vec3 b0(lo.x, lo.y, lo.z), b1(hi.x, lo.y, lo.z), b2(hi.x, hi.y, lo.z),
      b3(lo.x, hi.y, lo.z);
  const glm::vec3 t0(top_lo.x, top_lo.y, hi.z), t1(top_hi.x, top_lo.y, hi.z),
      t2(top_hi.x, top_hi.y, hi.z), t3(top_lo.x, top_hi.y, hi.z);
  add_face(t0, t1, t2, t3, material);  // top
  add_face(b0, b3, b2, b1, material);  // bottom
  add_face(b0, b1, t1, t0, material);  // right side (-y)
  add_face(b1, b2, t2, t1, material);  // front (+x)
  add_face(b2, b3, t3, t2, material);  // left side (+y)
  add_face(b3, b0, t0, t3, material);  // back (-x)
}

}  // namespace downpour::render
