// ChunkedMesh's screen bounds: where on the screen the chunks it would draw may cover, for the
// road's composite's scissor (road_pass.hpp).
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
  glm::vec2 ndc(const glm::vec3& p) const {
    const glm::vec4 c = view_proj * glm::vec4(p, 1.0f);
    return glm::vec2(c) / c.w;
  }
};

TEST_F(ChunkedMeshTest, ScreenBoundsOfAChunkAheadAreItsCornersRectangle) {
  const ChunkedMesh mesh({{ground(20.0f, 30.0f, -2.0f, 2.0f)}}, {1e30f});
  const glm::vec4 b = mesh.screen_bounds(view_proj, camera);
  // Nearest corners lowest and widest: (20, +-2) on the screen's left and right, (30, 0) highest.
  EXPECT_NEAR(b.x, ndc({20.0f, 2.0f, 0.0f}).x, 1e-5f);
  EXPECT_NEAR(b.z, ndc({20.0f, -2.0f, 0.0f}).x, 1e-5f);
  EXPECT_NEAR(b.y, ndc({20.0f, 0.0f, 0.0f}).y, 1e-5f);
  EXPECT_NEAR(b.w, ndc({30.0f, 0.0f, 0.0f}).y, 1e-5f);
  EXPECT_LT(b.w, 0.0f);  // below the horizon
}

TEST_F(ChunkedMeshTest, AChunkUnderTheCameraReachesTheScreensBottomAndEdges) {
  // From 5 m behind the camera to 10 m ahead: its near part projects to beyond the screen's
  // bottom and sides, clamped to them; its top is its far edge.
  const ChunkedMesh mesh({{ground(-5.0f, 10.0f, -20.0f, 20.0f)}}, {1e30f});
  const glm::vec4 b = mesh.screen_bounds(view_proj, camera);
  EXPECT_EQ(b.x, -1.0f);
  EXPECT_EQ(b.y, -1.0f);
  EXPECT_EQ(b.z, 1.0f);
  EXPECT_NEAR(b.w, ndc({10.0f, 0.0f, 0.0f}).y, 1e-5f);
}

TEST_F(ChunkedMeshTest, UpToADepthTheBoundsEndThere) {
  // The chunk ahead up to 25 m of the view's depth: its top is the ground 25 m ahead.
  const ChunkedMesh mesh({{ground(20.0f, 30.0f, -2.0f, 2.0f)}}, {1e30f});
  const glm::vec4 b = mesh.screen_bounds(view_proj, camera, 1.0f, 0.0f, 1e30f, 25.0f);
  EXPECT_NEAR(b.y, ndc({20.0f, 0.0f, 0.0f}).y, 1e-5f);
  EXPECT_NEAR(b.w, ndc({25.0f, 0.0f, 0.0f}).y, 1e-5f);
  // Nearer than all of it: none.
  const glm::vec4 none = mesh.screen_bounds(view_proj, camera, 1.0f, 0.0f, 1e30f, 15.0f);
  EXPECT_LT(none.w, none.y);
}

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
  EXPECT_EQ(mesh.visible_triangles(view_proj, camera, 1.0f, 10.0f), 32u);
  // From 30 m on, only its part beyond 30 m is drawn: the coarse level.
  EXPECT_EQ(mesh.visible_triangles(view_proj, camera, 1.0f, 30.0f), 2u);
  // And from 10 m at twice the distances.
  EXPECT_EQ(mesh.visible_triangles(view_proj, camera, 2.0f, 10.0f), 2u);
}

TEST_F(ChunkedMeshTest, NoChunkInViewHasNoBounds) {
  const ChunkedMesh mesh({{ground(-30.0f, -20.0f, -2.0f, 2.0f)}}, {1e30f});
  const glm::vec4 b = mesh.screen_bounds(view_proj, camera);
  EXPECT_LT(b.z, b.x);
  EXPECT_LT(b.w, b.y);
}

}  // namespace
}  // namespace downpour::render
