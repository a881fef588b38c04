// Static geometry in chunks, each with levels of detail, culled against the view and drawn at the
// level its distance from the camera calls for: the road surface, the terrain and the street
// lights' poles share it.
//
// Every chunk's every level lives in one vertex and one index buffer, and the visible ones go in
// one multi-draw. On llvmpipe each draw call costs about 11 us before its first triangle; the
// terrain's 112 visible chunks drawn one by one cost 1.2 ms of a 640x360 frame in calls alone.
#pragma once

#include <cstdint>
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
  // Draws the chunks whose bounds meet the view's frustum, and reach from `from_m` to `to_m` of the
  // camera, with the bound program, each at the level for its distance times distance_scale, in
  // one call.
  void draw_visible(const glm::mat4& view_proj, const glm::vec3& camera,
                    float distance_scale = 1.0f, float from_m = 0.0f, float to_m = 1e30f) const;
  // The triangles draw_visible() would draw (for tests and benchmarks).
  std::size_t visible_triangles(const glm::mat4& view_proj, const glm::vec3& camera) const;

 private:
  struct Range {
    std::uint32_t first_index = 0;
    std::uint32_t count = 0;
  };
  template <typename Fn>
  void for_each_visible(const glm::mat4& view_proj, const glm::vec3& camera, float distance_scale,
                        float from_m, float to_m, Fn&& fn) const;

  struct Chunk {
    std::vector<Range> levels;
    glm::vec3 bounds_min{0.0f};
    glm::vec3 bounds_max{0.0f};
  };
  Mesh mesh_;  // every chunk's levels, one after another
  std::vector<Chunk> chunks_;
  std::vector<float> level_distances_m_;
  float max_distance_m_ = 1e30f;
  // A frame's draws (kept to spare an allocation each frame).
  mutable std::vector<Range> ranges_;
  mutable std::vector<GLsizei> counts_;
  mutable std::vector<const void*> offsets_;
};

}  // namespace downpour::render
