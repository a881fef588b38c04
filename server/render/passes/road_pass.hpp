#pragma once

#include <vector>

#include "server/render/frame_context.hpp"

namespace downpour::render {

// The road surface: procedural asphalt albedo and micro-relief normals from a height field
// (seed 003, section 3.1), lane markings, a crowned cross-section, a wet sheen in the rain.
class RoadPass {
 public:
  explicit RoadPass(SharedResources& shared);
  void draw(const FrameContext& frame);

 private:
  ShaderProgram program_;
  std::vector<Mesh> chunks_;
};

}  // namespace downpour::render
