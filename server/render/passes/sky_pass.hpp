#pragma once

#include "server/render/frame_context.hpp"

namespace downpour::render {

// Sky dome: gradient from horizon to zenith, sun and glow, a cloud layer that thickens and greys
// with cloudiness and rain. Drawn last, where nothing else is.
class SkyPass {
 public:
  explicit SkyPass(SharedResources& shared);
  void draw(const FrameContext& frame);

 private:
  SharedResources& shared_;
  ShaderProgram program_;
};

}  // namespace downpour::render
