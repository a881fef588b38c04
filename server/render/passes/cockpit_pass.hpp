#pragma once

#include "server/render/frame_context.hpp"

namespace downpour::render {

// The cabin around the driver's eye: dashboard edge, A-pillars, roof liner and mirror, dark
// silhouettes framing the view through the windshield.
class CockpitPass {
 public:
  explicit CockpitPass(SharedResources& shared);
  void draw(const FrameContext& frame);

 private:
  ShaderProgram program_;
  Mesh interior_;
};

}  // namespace downpour::render
