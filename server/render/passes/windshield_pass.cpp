#include "server/render/passes/windshield_pass.hpp"

#include "server/render/passes/glass_quad.hpp"

namespace downpour::render {

WindshieldPass::WindshieldPass(SharedResources& shared)
    : shared_(shared),
      program_("fullscreen.vert", "windshield.frag"),
      blades_(program_),
      grid_(program_),
      u_aspect_(program_.uniform("u_aspect")),
      u_glass_mm_(program_.uniform("u_glass_mm")) {}

void WindshieldPass::execute(const FrameContext& frame, const FrameResources&) {
  const sim::GlassConfig& glass = frame.scene.glass;
  const sim::WindshieldState& water = frame.water();
  program_.use();
  u_aspect_.set(static_cast<float>(frame.spec.width) / static_cast<float>(frame.spec.height));
  u_glass_mm_.set(glm::vec3(glass.bottom_width_mm, glass.top_width_mm, glass.height_mm));
  grid_.set(water);
  blades_.set(water.blades);
  shared_.fullscreen.draw();
}

}  // namespace downpour::render
