// The frame block (shader_interface.hpp's FrameBlock) filled from a frame: its camera, sky,
// weather, the road's water window, the mirror the road reflection is drawn in, and the lamps'
// fields. And that mirror: the road's plane under the car.
#pragma once

#include <limits>
#include <memory>

#include <glm/mat4x4.hpp>
#include <glm/vec4.hpp>

#include "server/render/frame_context.hpp"

namespace downpour::render {

struct FrameBlock;

// The plane the road reflection mirrors the scene in: the road's surface under the car (its grade
// and height; the crown is left to the shader's own normal), as a plane and a reflection matrix.
struct Mirror {
  glm::vec4 plane{0.0f, 0.0f, 1.0f, 0.0f};  // n.p + w = 0
  glm::mat4 matrix{1.0f};
};

// The mirror in the plane n.p + w = 0 (n unit): x' = x - 2 (n.x + w) n.
Mirror mirror_in(const glm::dvec4& plane);
// The mirror in the road's surface under the vehicle.
Mirror mirror_under(const sim::RoadNetwork& roads, const sim::VehicleState& vehicle);

// Whether the road's water shows a mirror anywhere: a film standing on it (road.frag's film),
// or, without the simulation's water, heavy enough rain for the weather's film.
bool road_reflects(const FrameContext& f);

// The frame's water and mirror: the window's place, the reflection's matrix and plane.
struct WaterBlock {
  Mirror mirror;
  glm::vec4 clip_plane{0.0f, 0.0f, 0.0f, 1.0f};
  glm::vec4 road_water{0.0f};
  glm::mat4 road_water_rings{0.0f};
  glm::vec4 road_water_reach{std::numeric_limits<float>::max()};
  glm::vec4 road_water_state{0.5f, 0.0f, 0.0f, 0.0f};
};
// `reflection`: whether the view's road reads the road reflection this frame.
WaterBlock water_block(const FrameContext& f, const Mirror& mirror, bool reflection);

// The lamps' fields of the frame block (the renderer's, once it has packed the frame's lamps).
struct LampFields {
  glm::vec4 params{0.0f};  // rings of the lamp map (0: none), exposure, ego lamps, lamps
  glm::mat4 rings{0.0f};   // LampRings::windows
};

// The frame block's buffer, bound at kFrameBlockBinding for the renderer's life. A view's passes
// read the view's block; a pass that draws from another camera (the road reflection, the
// environment probe's faces) uploads its own and then restores the view's.
class FrameBlockBuffer {
 public:
  FrameBlockBuffer();
  // The view's block: uploaded, and kept for restore_view().
  void upload_view(const FrameContext& f, const WaterBlock& water);
  // Another camera's block (the view's stays kept).
  void upload(const FrameContext& f, const WaterBlock& water);
  void restore_view();
  // The water block of the view's (its mirror: the road reflection's).
  const WaterBlock& view_water() const { return view_water_; }
  // Only the clip plane (the road reflection's, per reflected pass).
  void set_clip_plane(const glm::vec4& plane);
  // The frame's lamps' fields, for the blocks uploaded after.
  void set_lamps(const LampFields& lamps) { lamps_ = lamps; }
  const LampFields& lamps() const { return lamps_; }

 private:
  Buffer ubo_;
  LampFields lamps_;
  std::unique_ptr<FrameBlock> view_;
  WaterBlock view_water_;
};

}  // namespace downpour::render
