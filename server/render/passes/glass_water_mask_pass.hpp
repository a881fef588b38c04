#pragma once

#include "server/render/glass_quad.hpp"
#include "server/render/pass.hpp"

namespace downpour::render {

// Where the glass layer's optics may meet water: the layer's pixels whose footprint touches a
// cell of the surface's grid that lists a body (glass_water_mask.frag), marked in the layer's
// depth (cleared to the nearest): the farthest depth there. GlassWaterPass, depth-tested nearer,
// then runs only there: llvmpipe skips a block of pixels that all fail the depth test, where it
// cannot skip a branch (on a wiped glass most of the layer is dry). Colour is left alone.
class GlassWaterMaskPass final : public Pass {
 public:
  explicit GlassWaterMaskPass(SharedResources& shared);
  const PassDecl& decl() const override { return decl_; }
  bool wanted(const FrameContext& frame) const override;
  void execute(const FrameContext& frame, const FrameResources& resources) override;

 private:
  const PassDecl decl_{"glass_water_mask",
                       {Resource::kGlassSurface},
                       {Resource::kGlassLayer},
                       {DepthTest::kAlways, true, Blend::kOff, false},
                       true};
  ShaderProgram program_;
  GlassQuad quad_;
  GlassSurfaceGrid grid_;
};

}  // namespace downpour::render
