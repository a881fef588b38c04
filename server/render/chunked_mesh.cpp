#include "server/render/chunked_mesh.hpp"

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "server/render/frame_context.hpp"

namespace downpour::render {

ChunkedMesh::ChunkedMesh(const std::vector<std::vector<MeshData>>& chunks,
                         std::vector<float> level_distances_m, float max_distance_m)
    : level_distances_m_(std::move(level_distances_m)), max_distance_m_(max_distance_m) {
  chunks_.reserve(chunks.size());
  for (const std::vector<MeshData>& levels : chunks) {
    Chunk c;
    c.bounds_min = glm::vec3(1e30f);
    c.bounds_max = glm::vec3(-1e30f);
    for (const MeshData& level : levels) {
      c.levels.emplace_back(level);
      c.bounds_min = glm::min(c.bounds_min, level.bounds_min);
      c.bounds_max = glm::max(c.bounds_max, level.bounds_max);
    }
    chunks_.push_back(std::move(c));
  }
}

template <typename Fn>
void ChunkedMesh::for_each_visible(const glm::mat4& view_proj, const glm::vec3& camera,
                                   float distance_scale, Fn&& fn) const {
  for (const Chunk& chunk : chunks_) {
    if (chunk.levels.empty() || !box_visible(view_proj, chunk.bounds_min, chunk.bounds_max))
      continue;
    const float distance =
        glm::length(glm::clamp(camera, chunk.bounds_min, chunk.bounds_max) - camera) *
        distance_scale;
    if (distance >= max_distance_m_) continue;
    std::size_t level = 0;
    while (level < level_distances_m_.size() && level + 1 < chunk.levels.size() &&
           distance >= level_distances_m_[level]) {
      ++level;
    }
    fn(chunk.levels[level]);
  }
}

void ChunkedMesh::draw_visible(const glm::mat4& view_proj, const glm::vec3& camera,
                               float distance_scale) const {
  for_each_visible(view_proj, camera, distance_scale, [](const Mesh& mesh) { mesh.draw(); });
}

std::size_t ChunkedMesh::visible_triangles(const glm::mat4& view_proj,
                                           const glm::vec3& camera) const {
  std::size_t triangles = 0;
  for_each_visible(view_proj, camera, 1.0f,
                   [&](const Mesh& mesh) { triangles += mesh.triangles(); });
  return triangles;
}

}  // namespace downpour::render
