#pragma once

#include "server/render/frame_context.hpp"

namespace downpour::render {

// Cars as simple shapes: the ego vehicle in outside views (its hood alone from the cockpit) and
// the traffic the simulator reports.
class VehiclePass {
 public:
  explicit VehiclePass(SharedResources& shared);
  void draw(const FrameContext& frame);

 private:
  void draw_car(const glm::mat4& model, const glm::vec3& colour, bool hull_only);

  ShaderProgram program_;
  Mesh hull_;
  Mesh upper_;
};

}  // namespace downpour::render
