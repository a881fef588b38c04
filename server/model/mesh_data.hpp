// Geometry built on the CPU (no GL): vertices and indices with their bounds, ready for upload.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace downpour::render {

struct MeshVertex {
  glm::vec3 position;
  glm::vec3 normal;
  glm::vec2 uv;
};

// Principal curvatures and directions at a vertex (mesh_curvature.hpp), a second vertex stream
// for the surfaces with relief shadows: attribute 3 (k1, k2), attribute 4 (v1, v2).
struct VertexCurvature {
  float k1 = 0.0f;  // 1/m, convex (falling away from the normal) positive; k1 >= k2
  float k2 = 0.0f;
  glm::vec2 v1{1.0f, 0.0f};  // the principal directions in the texture's (u, v) plane, unit
  glm::vec2 v2{0.0f, 1.0f};
};

// Where a road vertex lies among its road's lanes (scene_geometry.hpp), a third vertex stream:
// attribute 5, flat (from each triangle's provoking vertex). The road's vertices stand in columns
// along it, at every lane border and across the verges; a column's attributes describe the strip
// between it and the next column to its left.
struct VertexLane {
  float t = 0.0f;  // the column's lateral offset on its road (m, left positive)
  // The strip's width (m), + 100 on a lane cars drive in; on a verge -1000 right of the road,
  // 1000 left of it, and `t` the paved edge's.
  float width = 1.0f;
  // The marks on the strip's right and left borders, packed (pack_lane_mark).
  float mark_right = 0.0f;
  float mark_left = 0.0f;
};

// A lane mark in one float, an integer below 2^24 (road_surface.glsl unpacks it): bits 0-2 the
// kind (sim::LaneMark::Kind), 3 yellow, 4-9 one line's width (cm), 10-16 its centre's offset from
// the border (cm, + 64; left positive), 17-23 a double line's spacing (cm).
float pack_lane_mark(int kind, bool yellow, double width_m, double offset_m, double spacing_m);

// Where a model's vertex reads its texture (vehicle_model.hpp's textures), a fourth vertex stream:
// attribute 6. Layer -1: none (the material's own colour alone).
struct VertexTexture {
  glm::vec2 uv{0.0f};  // glTF's: (0, 0) the image's top left
  float layer = -1.0f;
};

struct MeshData {
  std::vector<MeshVertex> vertices;
  std::vector<VertexCurvature> curvature;  // empty, or one a vertex
  std::vector<VertexLane> lanes;           // empty, or one a vertex
  std::vector<VertexTexture> texcoords;    // empty, or one a vertex
  std::vector<std::uint32_t> indices;
  glm::vec3 bounds_min{1e30f};
  glm::vec3 bounds_max{-1e30f};

  std::uint32_t add_vertex(const glm::vec3& p, const glm::vec3& n, const glm::vec2& uv);
  void add_triangle(std::uint32_t a, std::uint32_t b, std::uint32_t c) {
    indices.insert(indices.end(), {a, b, c});
  }
  void add_quad(std::uint32_t a, std::uint32_t b, std::uint32_t c, std::uint32_t d) {
    add_triangle(a, b, c);
    add_triangle(a, c, d);
  }
  // A flat-shaded convex quad face (corners counter-clockwise seen from outside); uv.x carries a
  // material id for the shader.
  void add_face(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c, const glm::vec3& d,
                float material);
  // An axis-aligned box.
  void add_box(const glm::vec3& lo, const glm::vec3& hi, float material);
  // A box whose top face is narrower/shorter: bottom rectangle lo..hi at z = lo.z, top rectangle
  // top_lo..top_hi (x, y) at z = hi.z.
  void add_frustum(const glm::vec3& lo, const glm::vec3& hi, const glm::vec2& top_lo,
                   const glm::vec2& top_hi, float material);
};

// Chunks that tile a surface as a grid, each at levels of detail (levels[c][k], k = 0 the finest;
// chunked_mesh.hpp draws them), with skirts apart: at each level, a strip hanging from each of the
// chunk's edges, south, north, west and east (skirts[c][k][edge]). Two chunks drawn at one level
// share their edge's vertices; only where the chunk across an edge (across[c][edge], -1 at the
// surface's border) is drawn at another level do the edges differ and a crack open, and only there
// is the skirt drawn.
struct SkirtedChunks {
  std::vector<std::vector<MeshData>> levels;
  std::vector<std::vector<std::array<MeshData, 4>>> skirts;
  std::vector<std::array<int, 4>> across;
};

}  // namespace downpour::render
