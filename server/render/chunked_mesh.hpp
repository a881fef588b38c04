// Static geometry in chunks, each with levels of detail, culled against the view and drawn at the
// level its distance from the camera calls for: the road surface and the terrain share it.
#pragma once

#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "server/model/mesh_data.hpp"
#include "server/render/gl/gl_objects.hpp"

namespace downpour::render {

class ChunkedMesh {
 public:
  // chunks[c][level]: level 0 the finest. A chunk is drawn at level k when its nearest point is
  // at least level_distances_m[k - 1] from the camera, and not at all from max_distance_m on.
  ChunkedMesh() = default;
  ChunkedMesh(const std::vector<std::vector<MeshData>>& chunks,
              std::vector<float> level_distances_m, float max_distance_m = 1e30f);
  // Draws the chunks whose bounds meet the view's frustum with the bound program, each at the
  // level for its distance times distance_scale.
  void draw_visible(const glm::mat4& view_proj, const glm::vec3& camera,
                    float distance_scale = 1.0f) const;
  // The triangles draw_visible() would draw (for tests and benchmarks).
  std::size_t visible_triangles(const glm::mat4& view_proj, const glm::vec3& camera) const;

 private:
  template <typename Fn>
  void for_each_visible(const glm::mat4& view_proj, const glm::vec3& camera, float distance_scale,
                        Fn&& fn) const;

  struct Chunk {
    std::vector<Mesh> levels;
    glm::vec3 bounds_min{0.0f};
    glm::vec3 bounds_max{0.0f};
  };
  std::vector<Chunk> chunks_;
  std::vector<float> level_distances_m_;
  float max_distance_m_ = 1e30f;
};

}  // namespace downpour::render
