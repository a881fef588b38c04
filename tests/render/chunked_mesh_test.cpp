// ChunkedMesh: the level a chunk is drawn at, for the part of it that is drawn.
#include <gtest/gtest.h>

#include <glm/ext/matrix_clip_space.hpp>
#include <glm/ext/matrix_transform.hpp>

#include "server/render/chunked_mesh.hpp"
#include "tests/render/render_fixture.hpp"

namespace downpour::render {
namespace {

class ChunkedMeshTest : public testing::RenderTest {
 protected:
  // A flat quad on the ground (z = 0) over [x0, x1] x [y0, y1], one chunk of one level.
  static MeshData ground(float x0, float x1, float y0, float y1) {
    MeshData m;
    const glm::vec3 up(0.0f, 0.0f, 1.0f);
    m.add_quad(m.add_vertex({x0, y0, 0.0f}, up, {0.0f, 0.0f}),
               m.add_vertex({x1, y0, 0.0f}, up, {1.0f, 0.0f}),
               m.add_vertex({x1, y1, 0.0f}, up, {1.0f, 1.0f}),
               m.add_vertex({x0, y1, 0.0f}, up, {0.0f, 1.0f}));
    return m;
  }
  // A camera 2 m over the ground looking along +x, 60 degrees high, 16:9.
  const glm::vec3 camera{0.0f, 0.0f, 2.0f};
  const glm::mat4 view_proj =
      glm::perspective(glm::radians(60.0f), 16.0f / 9.0f, 0.1f, 1000.0f) *
      glm::lookAt(camera, camera + glm::vec3(1.0f, 0.0f, 0.0f), glm::vec3(0.0f, 0.0f, 1.0f));
};

TEST_F(ChunkedMeshTest, AChunkDrawnFromADistanceTakesTheLevelOfThatDistance) {
  // From 5 m behind the camera to 60 m ahead: level 0 a grid of 4 x 4 quads, level 1 one quad,
  // drawn at level 1 from 20 m.
  MeshData fine;
  for (int i = 0; i < 4; ++i) {
    for (int j = 0; j < 4; ++j) {
      const MeshData q = ground(-5.0f + 16.25f * i, -5.0f + 16.25f * (i + 1), -4.0f + 2.0f * j,
                                -4.0f + 2.0f * (j + 1));
      const auto first = static_cast<std::uint32_t>(fine.vertices.size());
      for (const auto& v : q.vertices) fine.vertices.push_back(v);
      for (const std::uint32_t k : q.indices) fine.indices.push_back(first + k);
    }
  }
  const ChunkedMesh mesh({{fine, ground(-5.0f, 60.0f, -4.0f, 4.0f)}}, {20.0f});
  EXPECT_EQ(mesh.visible_triangles(view_proj, camera), 32u);  // (its nearest point under it)
  EXPECT_EQ(mesh.visible_triangles(view_proj, camera, 1.0f, 10.0f, 1e30f, 10.0f), 32u);
  // Drawn from 30 m on with its levels from there: the coarse level.
  EXPECT_EQ(mesh.visible_triangles(view_proj, camera, 1.0f, 30.0f, 1e30f, 30.0f), 2u);
  // And from 10 m at twice the distances.
  EXPECT_EQ(mesh.visible_triangles(view_proj, camera, 2.0f, 10.0f, 1e30f, 10.0f), 2u);
  // Drawn from 30 m on with its levels from the camera (a draw that must meet one from the
  // camera on the same surface): the fine level.
  EXPECT_EQ(mesh.visible_triangles(view_proj, camera, 1.0f, 30.0f), 32u);
}

}  // namespace
}  // namespace downpour::render
