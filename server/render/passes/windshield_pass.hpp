#pragma once

#include "server/render/frame_context.hpp"
#include "server/render/passes/windshield_water_pass.hpp"

namespace downpour::render {

// The WINDSHIELD view: the glass alone in glass space (u across, v up the glass) fitted to the
// view, as ground truth for perception tests. Dry glass is black, water grey by its compressed
// height (brighter where it is thicker), the glass's outline faint grey, the wiper blades blue.
// Reads: the water map of WindshieldWaterPass (made for this view), the blade poses.
class WindshieldPass {
 public:
  explicit WindshieldPass(SharedResources& shared);
  void draw(const FrameContext& frame, const WindshieldWaterPass& water);

 private:
  SharedResources& shared_;
  ShaderProgram program_;
};

}  // namespace downpour::render
