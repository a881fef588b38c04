// The lamps' light on the ground, drawn each frame into two rings of a texture array around the
// camera (the design choice: light and relief). A shader that loops over every lamp per
// pixel costs on llvmpipe about what its arithmetic does on every pixel: 40 lamps, even binned
// into screen tiles (light_set.hpp: 36 a tile with 64 lamps, 22 with depth slices), are far over
// a 3 ms budget at 640 x 360. The ground, most of a driving view, is lit by lamps whose light
// changes slowly across it, so the loop runs once per cell of a small world-space map instead:
// 2 x 128 x 128 cells, a fine ring (0.5 m) over the 64 m around and ahead of the camera and a
// coarse one (2 m) over 256 m, each lamp drawn over its footprint alone (in the night benchmark,
// a loop over all 41 lamps at every cell took 7.8 ms). The road and the terrain read it with two
// fetches. What needs a
// sharper light per pixel (the ego car's beams on the cars ahead) loops over the ego car's
// headlights alone (common.glsl).
#pragma once

#include <array>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "server/render/gl/gl_objects.hpp"

namespace downpour::render {

struct LampRings {
  static constexpr int kRings = 2;
  static constexpr int kCells = 128;
  static constexpr float kCellM[kRings] = {0.5f, 2.0f};
  // The camera sits this far along each ring from its back edge, towards where it looks.
  static constexpr float kCameraAt = 0.2f;
  glm::mat4 windows{0.0f};  // the frame block's lamp_rings
};

// The rings' windows for a camera at `camera` looking along `forward`: each ahead of it, its
// corner on whole cells (so that a cell's light does not swim as the camera moves).
LampRings place_lamp_rings(const glm::vec3& camera, const glm::vec3& forward);

class LampMap {
 public:
  LampMap();
  // Draws the lamps' light into the rings, each lamp over its box on the ground (x0, y0, x1, y1;
  // PackedLamps::ground_boxes), added up (its pass's state: lamp_map_pass.hpp); the frame block
  // (lamp_map, lamp_rings) and the lamp block must be uploaded. Binds the map to its texture unit.
  void draw(const std::vector<glm::vec4>& ground_boxes);
  GLuint texture() const { return texture_.id(); }

 private:
  ShaderProgram program_;
  Uniform u_ring_, u_boxes_;
  VertexArray vao_;
  Texture texture_;
  std::array<Framebuffer, LampRings::kRings> fbo_;
};

}  // namespace downpour::render
