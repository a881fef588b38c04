#include "server/render/passes/glass_background_pass.hpp"

#include "server/render/glass_quad.hpp"

namespace downpour::render {

GlassBackgroundPass::GlassBackgroundPass(SharedResources& shared)
    : shared_(shared),
      program_("fullscreen.vert", "glass_background.frag"),
      u_texel_(program_.uniform("u_texel")),
      u_glass_depth_(program_.uniform("u_glass_depth")) {}

bool GlassBackgroundPass::wanted(const FrameContext& frame) const {
  return glass_has_water_or_blades(frame.water());
}

void GlassBackgroundPass::execute(const FrameContext& frame, const FrameResources& resources) {
  program_.use();
  u_texel_.set(1.0f / glm::vec2(resources.view_colour.width, resources.view_colour.height));
  u_glass_depth_.set(frame.glass.depth_over_image());
  shared_.fullscreen.draw();
}

}  // namespace downpour::render
