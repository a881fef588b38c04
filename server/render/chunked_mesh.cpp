#include "server/render/chunked_mesh.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <stdexcept>

#include <glm/common.hpp>
#include <glm/geometric.hpp>

#include "server/render/frame_context.hpp"

namespace downpour::render {

namespace {

// Appends `part` to `all`, its indices moved past the vertices already there.
void append(MeshData& all, const MeshData& part) {
  const bool first = all.vertices.empty();
  if (!first && (all.curvature.empty() != part.curvature.empty() ||
                 all.lanes.empty() != part.lanes.empty())) {
    throw std::logic_error("a chunked mesh's parts differ in their attributes");
  }
  const auto base = static_cast<std::uint32_t>(all.vertices.size());
  all.vertices.insert(all.vertices.end(), part.vertices.begin(), part.vertices.end());
  all.curvature.insert(all.curvature.end(), part.curvature.begin(), part.curvature.end());
  all.lanes.insert(all.lanes.end(), part.lanes.begin(), part.lanes.end());
  for (const std::uint32_t i : part.indices) all.indices.push_back(base + i);
  all.bounds_min = glm::min(all.bounds_min, part.bounds_min);
  all.bounds_max = glm::max(all.bounds_max, part.bounds_max);
}

}  // namespace

ChunkedMesh::ChunkedMesh(const std::vector<std::vector<MeshData>>& chunks,
                         std::vector<float> level_distances_m, float max_distance_m)
    : level_distances_m_(std::move(level_distances_m)), max_distance_m_(max_distance_m) {
  build(chunks, nullptr);
}

ChunkedMesh::ChunkedMesh(const SkirtedChunks& chunks, std::vector<float> level_distances_m,
                         float max_distance_m)
    : level_distances_m_(std::move(level_distances_m)), max_distance_m_(max_distance_m) {
  if (chunks.skirts.size() != chunks.levels.size() ||
      chunks.across.size() != chunks.levels.size()) {
    throw std::logic_error("skirted chunks without a skirt and a neighbour list each");
  }
  for (const std::array<int, 4>& across : chunks.across) {
    for (const int n : across) {
      if (n < -1 || n >= static_cast<int>(chunks.levels.size()))
        throw std::logic_error("a chunk's neighbour is not one of the chunks");
    }
  }
  build(chunks.levels, &chunks);
}

void ChunkedMesh::build(const std::vector<std::vector<MeshData>>& chunks,
                        const SkirtedChunks* skirted) {
  // Level by level, each level's chunks in their order: neighbours drawn at one level are one
  // range of indices, and draw_visible() joins them into one draw. The skirts follow, apart.
  std::size_t levels = 0;
  chunks_.resize(chunks.size());
  for (std::size_t c = 0; c < chunks.size(); ++c) {
    levels = std::max(levels, chunks[c].size());
    chunks_[c].levels.resize(chunks[c].size());
    chunks_[c].bounds_min = glm::vec3(1e30f);
    chunks_[c].bounds_max = glm::vec3(-1e30f);
  }
  // Every part's room made at once (reserving each part's as it came copied all the buffer each
  // time: the terrain's 5,120 parts took seconds under ASan).
  MeshData all;
  std::size_t vertices = 0, indices = 0;
  auto count = [&](const MeshData& part) {
    vertices += part.vertices.size();
    indices += part.indices.size();
  };
  for (const std::vector<MeshData>& chunk : chunks)
    std::for_each(chunk.begin(), chunk.end(), count);
  if (skirted) {
    for (const auto& levels : skirted->skirts) {
      for (const std::array<MeshData, 4>& edges : levels)
        std::for_each(edges.begin(), edges.end(), count);
    }
  }
  all.vertices.reserve(vertices);
  all.indices.reserve(indices);
  auto put = [&all](const MeshData& part) {
    const Range r{static_cast<std::uint32_t>(all.indices.size()),
                  static_cast<std::uint32_t>(part.indices.size())};
    append(all, part);
    return r;
  };
  for (std::size_t l = 0; l < levels; ++l) {
    for (std::size_t c = 0; c < chunks.size(); ++c) {
      if (l >= chunks[c].size()) continue;
      const MeshData& level = chunks[c][l];
      Chunk& chunk = chunks_[c];
      chunk.levels[l] = put(level);
      chunk.bounds_min = glm::min(chunk.bounds_min, level.bounds_min);
      chunk.bounds_max = glm::max(chunk.bounds_max, level.bounds_max);
    }
  }
  if (skirted) {
    for (std::size_t c = 0; c < chunks.size(); ++c) {
      Chunk& chunk = chunks_[c];
      chunk.across = skirted->across[c];
      for (const std::array<MeshData, 4>& edges : skirted->skirts[c]) {
        std::array<Range, 4>& ranges = chunk.skirts.emplace_back();
        for (int e = 0; e < 4; ++e) {
          ranges[e] = put(edges[e]);
          chunk.bounds_min = glm::min(chunk.bounds_min, edges[e].bounds_min);
          chunk.bounds_max = glm::max(chunk.bounds_max, edges[e].bounds_max);
        }
      }
      if (chunk.skirts.size() != chunk.levels.size())
        throw std::logic_error("a chunk's skirts and levels differ in number");
    }
  }
  if (!all.indices.empty()) mesh_ = Mesh(all);
  level_drawn_.resize(chunks_.size());
  ranges_.reserve(chunks_.size());
  counts_.reserve(chunks_.size());
  offsets_.reserve(chunks_.size());
}

int ChunkedMesh::level_for(const Chunk& chunk, const glm::mat4& view_proj, const glm::vec3& camera,
                           float distance_scale, float from_m, float to_m,
                           float level_from_m) const {
  if (chunk.levels.empty() || !box_visible(view_proj, chunk.bounds_min, chunk.bounds_max))
    return -1;
  const float nearest =
      glm::length(glm::clamp(camera, chunk.bounds_min, chunk.bounds_max) - camera);
  if (nearest >= to_m) return -1;
  if (from_m > 0.0f && glm::length(glm::max(glm::abs(camera - chunk.bounds_min),
                                            glm::abs(camera - chunk.bounds_max))) < from_m)
    return -1;
  // (llvmpipe sets up every triangle that reaches the view, however little of it is drawn: the
  // chunk under a 640x360 ROAD camera, drawn from 17 m at its finest level, was 1,540 of the far
  // road's 3,920 triangles.)
  const float distance = std::max(nearest, level_from_m) * distance_scale;
  if (distance >= max_distance_m_) return -1;
  std::size_t level = 0;
  while (level < level_distances_m_.size() && level + 1 < chunk.levels.size() &&
         distance >= level_distances_m_[level]) {
    ++level;
  }
  return static_cast<int>(level);
}

template <typename Fn>
void ChunkedMesh::for_each_drawn(const glm::mat4& view_proj, const glm::vec3& camera,
                                 float distance_scale, float from_m, float to_m, float level_from_m,
                                 Fn&& fn) const {
  // Each chunk's level, or -1 where it is not drawn.
  for (std::size_t c = 0; c < chunks_.size(); ++c) {
    level_drawn_[c] =
        level_for(chunks_[c], view_proj, camera, distance_scale, from_m, to_m, level_from_m);
  }
  for (std::size_t c = 0; c < chunks_.size(); ++c) {
    const int level = level_drawn_[c];
    if (level < 0) continue;
    const Chunk& chunk = chunks_[c];
    fn(chunk.levels[level]);
    if (chunk.skirts.empty()) continue;
    for (int e = 0; e < 4; ++e) {
      const int n = chunk.across[e];
      if (n >= 0 && level_drawn_[n] >= 0 && level_drawn_[n] != level) fn(chunk.skirts[level][e]);
    }
  }
}

void ChunkedMesh::draw_visible(const glm::mat4& view_proj, const glm::vec3& camera,
                               float distance_scale, float from_m, float to_m,
                               float level_from_m) const {
  ranges_.clear();
  for_each_drawn(view_proj, camera, distance_scale, from_m, to_m, level_from_m,
                 [this](const Range& r) {
                   if (r.count != 0) ranges_.push_back(r);
                 });
  // Ranges that meet in the buffer become one.
  std::sort(ranges_.begin(), ranges_.end(),
            [](const Range& a, const Range& b) { return a.first_index < b.first_index; });
  counts_.clear();
  offsets_.clear();
  std::uint32_t end = 0;
  for (const Range& r : ranges_) {
    if (!counts_.empty() && r.first_index == end) {
      counts_.back() += static_cast<GLsizei>(r.count);
    } else {
      counts_.push_back(static_cast<GLsizei>(r.count));
      offsets_.push_back(
          reinterpret_cast<const void*>(static_cast<std::uintptr_t>(r.first_index) * 4u));
    }
    end = r.first_index + r.count;
  }
  mesh_.multi_draw(counts_.data(), offsets_.data(), static_cast<GLsizei>(counts_.size()));
}

std::size_t ChunkedMesh::visible_triangles(const glm::mat4& view_proj, const glm::vec3& camera,
                                           float distance_scale, float from_m, float to_m,
                                           float level_from_m) const {
  std::size_t triangles = 0;
  for_each_drawn(view_proj, camera, distance_scale, from_m, to_m, level_from_m,
                 [&](const Range& r) { triangles += r.count / 3; });
  return triangles;
}

}  // namespace downpour::render
