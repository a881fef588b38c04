#pragma once

#include "server/render/pass.hpp"
#include "server/render/passes/glass_quad.hpp"
#include "server/render/passes/wiper_blades.hpp"

namespace downpour::render {

// COCKPIT: the glass layer over the view at full size (its bilinear magnification finishes the
// lens's blur), on the glass's own geometry and depth-tested so that the cabin stays in front;
// then the wiper blades and arms as dark strips on the glass, blurred like the water.
class GlassCompositePass final : public Pass {
 public:
  explicit GlassCompositePass(SharedResources& shared);
  const PassDecl& decl() const override { return decl_; }
  bool wanted(const FrameContext& frame) const override;
  void execute(const FrameContext& frame, const FrameResources& resources) override;
  // The blades alone, under the pass's state into the bound target: the clean frame's (ground
  // truth: the glass without its water keeps its blades).
  void draw_blades(const FrameContext& frame);

 private:
  const PassDecl decl_{"glass_composite",
                       {Resource::kGlassLayer},
                       {Resource::kViewColour, Resource::kViewDepth},
                       {DepthTest::kNearer, false, Blend::kPremultiplied},
                       true};
  ShaderProgram program_;
  GlassQuad quad_;
  Uniform u_inv_viewport_;
  ShaderProgram blade_program_;
  WiperBladeUniforms blades_;
  GlassPlacement blade_placement_;
  Uniform u_blur_mm_, u_margin_mm_;
  VertexArray empty_vao_;
};

}  // namespace downpour::render
