#include "server/render/passes/windshield_pass.hpp"

#include "server/render/wiper_blades.hpp"

namespace downpour::render {

WindshieldPass::WindshieldPass(SharedResources& shared)
    : shared_(shared), program_("fullscreen.vert", "windshield.frag") {}

void WindshieldPass::draw(const FrameContext& frame, const WindshieldWaterPass& water) {
  const sim::GlassConfig& glass = frame.scene.glass;
  glDisable(GL_DEPTH_TEST);
  program_.use();
  program_.set("u_aspect",
               static_cast<float>(frame.spec.width) / static_cast<float>(frame.spec.height));
  program_.set("u_glass_mm", glm::vec3(glass.bottom_width_mm, glass.top_width_mm, glass.height_mm));
  program_.set("u_map_origin_mm", water.layout().origin_mm);
  program_.set("u_map_extent_mm", water.layout().extent_mm);
  program_.set("u_threshold", water.config().compression.threshold);
  set_wiper_blade_uniforms(program_, frame.scene.windshield.blades);
  glBindTextureUnit(binding::kWaterMap, water.water_map());
  shared_.fullscreen.draw();
}

}  // namespace downpour::render
