#pragma once

#include "server/render/pass.hpp"

namespace downpour::render {

// COCKPIT, after the scene: the refraction background for the water on the glass (seed 000,
// section 1.5 step 5). The view so far at an eighth of its size (one pass, no mip levels to make),
// with the cabin's pixels replaced by the horizon's colour (the water is outside the glass; the
// cabin is not seen through it). The paper used a 64 x 64 copy for the same blur.
class GlassBackgroundPass final : public Pass {
 public:
  explicit GlassBackgroundPass(SharedResources& shared);
  const PassDecl& decl() const override { return decl_; }
  bool wanted(const FrameContext& frame) const override;
  void execute(const FrameContext& frame, const FrameResources& resources) override;

 private:
  const PassDecl decl_{"glass_background",
                       {Resource::kViewColour, Resource::kViewDepth},
                       {Resource::kSceneBlur},
                       {},
                       true};
  SharedResources& shared_;
  ShaderProgram program_;
  Uniform u_texel_, u_glass_depth_;
};

}  // namespace downpour::render
