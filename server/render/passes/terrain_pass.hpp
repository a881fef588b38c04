#pragma once

#include <vector>

#include "server/render/frame_context.hpp"

namespace downpour::render {

// The ground around the road: hills in chunks culled against the view, grass and soil shaded by
// sun and sky, fogged with distance.
class TerrainPass {
 public:
  explicit TerrainPass(SharedResources& shared);
  void draw(const FrameContext& frame);

 private:
  ShaderProgram program_;
  std::vector<Mesh> chunks_;
};

}  // namespace downpour::render
