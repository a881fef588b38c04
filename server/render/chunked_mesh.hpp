// Static geometry in chunks, each with levels of detail, culled against the view and drawn at the
// level its distance from the camera calls for: the road surface, the terrain and the street
// lights' poles share it.
//
// Every chunk's every level lives in one vertex and one index buffer, and the visible ones go in
// one multi-draw. On llvmpipe each draw call costs about 11 us before its first triangle; the
// terrain's 112 visible chunks drawn one by one cost 1.2 ms of a 640x360 frame in calls alone.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>

#include "server/model/mesh_data.hpp"
#include "server/render/gl/gl_objects.hpp"

namespace downpour::render {

class ChunkedMesh {
 public:
  // chunks[c][level]: level 0 the finest. A chunk is drawn at level k when its nearest point (or
  // draw_visible's level_from_m, where that is further) times the distance scale is at least
  // level_distances_m[k - 1] from the camera, and not at all from max_distance_m on.
  ChunkedMesh() = default;
  ChunkedMesh(const std::vector<std::vector<MeshData>>& chunks,
              std::vector<float> level_distances_m, float max_distance_m = 1e30f);
  // Chunks of a grid with skirts (mesh_data.hpp): a skirt is drawn where the chunk across its edge
  // is drawn too, at another level. (On llvmpipe a triangle costs some 0.4 us however small: the
  // terrain's skirts, drawn along every edge, were half its triangles and 4% of a 640x360 view's
  // CPU.)
  ChunkedMesh(const SkirtedChunks& chunks, std::vector<float> level_distances_m,
              float max_distance_m = 1e30f);
  // Draws the chunks whose bounds meet the view's frustum, and reach from `from_m` to `to_m` of the
  // camera, with the bound program, each at the level for its distance times distance_scale, in
  // one call. A chunk outside [from_m, to_m) counts as not drawn for its neighbours' skirts.
  // level_from_m: where a chunk's nearest point is nearer, its level is that distance's. A part of
  // the mesh drawn only from some distance on (the road's far part) gives it, so that the chunk
  // under the camera is not drawn at its finest level for what lies beyond; draws that must meet
  // the same surface (the road's relief and plain draws of one part, its layer and composite)
  // give the same.
  void draw_visible(const glm::mat4& view_proj, const glm::vec3& camera,
                    float distance_scale = 1.0f, float from_m = 0.0f, float to_m = 1e30f,
                    float level_from_m = 0.0f) const;
  // The triangles draw_visible() would draw (for tests and benchmarks).
  std::size_t visible_triangles(const glm::mat4& view_proj, const glm::vec3& camera,
                                float distance_scale = 1.0f, float from_m = 0.0f,
                                float to_m = 1e30f, float level_from_m = 0.0f) const;

 private:
  struct Range {
    std::uint32_t first_index = 0;
    std::uint32_t count = 0;
  };
  void build(const std::vector<std::vector<MeshData>>& chunks, const SkirtedChunks* skirted);
  struct Chunk;
  // The level a chunk is drawn at, as draw_visible() says, or -1.
  int level_for(const Chunk& chunk, const glm::mat4& view_proj, const glm::vec3& camera,
                float distance_scale, float from_m, float to_m, float level_from_m) const;
  // Calls fn with each range of indices to draw: the visible chunks' surfaces at their levels,
  // and the skirts between two of them drawn at different levels.
  template <typename Fn>
  void for_each_drawn(const glm::mat4& view_proj, const glm::vec3& camera, float distance_scale,
                      float from_m, float to_m, float level_from_m, Fn&& fn) const;

  struct Chunk {
    std::vector<Range> levels;
    std::vector<std::array<Range, 4>> skirts;  // [level][edge], or none
    std::array<int, 4> across{-1, -1, -1, -1};
    glm::vec3 bounds_min{0.0f};
    glm::vec3 bounds_max{0.0f};
  };
  Mesh mesh_;  // every chunk's levels, one after another
  std::vector<Chunk> chunks_;
  std::vector<float> level_distances_m_;
  float max_distance_m_ = 1e30f;
  // A frame's draws (kept to spare an allocation each frame).
  mutable std::vector<int> level_drawn_;  // per chunk, -1 where not drawn
  mutable std::vector<Range> ranges_;
  mutable std::vector<GLsizei> counts_;
  mutable std::vector<const void*> offsets_;
};

}  // namespace downpour::render
