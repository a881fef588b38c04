#pragma once

#include "server/render/frame_context.hpp"

namespace downpour::render {

// The WINDSHIELD view: the glass alone, in glass space (u across, v up the glass), as ground truth
// for perception tests. Water on it comes with the windshield simulation; until then the glass is
// dry: its outline on black.
class WindshieldPass {
 public:
  explicit WindshieldPass(SharedResources& shared);
  void draw(const FrameContext& frame);

 private:
  SharedResources& shared_;
  ShaderProgram program_;
};

}  // namespace downpour::render
