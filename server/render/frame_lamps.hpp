// The frame's lamps (cpu/light_set.hpp): made from the scene each frame, packed into the lamp block
// (binding kLampBlockBinding) for the shaders, with what the frame block and the lamp map need of
// them.
#pragma once

#include <vector>

#include <glm/vec4.hpp>

#include "server/render/cpu/light_set.hpp"
#include "server/render/cpu/shader_interface.hpp"
#include "server/render/frame_block.hpp"
#include "server/render/frame_context.hpp"
#include "server/render/gl/gl_objects.hpp"

namespace downpour::render {

class FrameLamps {
 public:
  FrameLamps();
  // The lamps of `f`'s scene, for its camera, into the lamp block, and f.lights pointed at them:
  // none by day, or where `on` is false. `map`: whether the view has a lamp map drawn (it shows
  // the ground).
  void prepare(FrameContext& f, bool on, bool map);
  const LampFields& fields() const { return fields_; }
  // Whether this frame's lamp map is to be drawn, and each lamp's box on the ground.
  bool map() const { return fields_.params.x > 0.0f; }
  const std::vector<glm::vec4>& ground_boxes() const { return packed_.ground_boxes; }

 private:
  Buffer ubo_;
  LampBlock block_;
  std::vector<Light> lights_;
  PackedLamps packed_;
  LampFields fields_;
};

}  // namespace downpour::render
