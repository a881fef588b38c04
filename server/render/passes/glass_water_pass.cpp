#include "server/render/passes/glass_water_pass.hpp"

#include <algorithm>
#include <cmath>

namespace downpour::render {

GlassWaterPass::GlassWaterPass(SharedResources&, GlassWaterConfig config)
    : config_(config),
      program_("glass.vert", "glass_water.frag"),
      quad_(program_),
      u_map_size_mm_(program_.uniform("u_map_size_mm")),
      u_taps_(program_.uniform("u_taps")),
      u_inv_target_(program_.uniform("u_inv_target")),
      u_screen_axes_(program_.uniform("u_screen_axes")),
      u_refraction_(program_.uniform("u_refraction")) {
  program_.uniform("u_water_ior").set(config_.water_ior);
  program_.uniform("u_fresnel_r0").set(config_.fresnel_r0);
  program_.uniform("u_rim_darkening").set(config_.rim_darkening);
  program_.uniform("u_rim_lean").set(glm::vec2(config_.rim_lean[0], config_.rim_lean[1]));
  program_.uniform("u_glint").set(config_.sun_glint);
}

bool GlassWaterPass::wanted(const FrameContext& frame) const {
  return glass_has_water_or_blades(frame.water());
}

void GlassWaterPass::execute(const FrameContext& frame, const FrameResources& resources) {
  const sim::GlassWaterMap& map = frame.water().map;
  program_.use();
  u_map_size_mm_.set(map_size_mm(map, frame.scene.glass));
  u_taps_.set(frame.glass.layer_scale() > 1 ? 4 : 1);
  u_inv_target_.set(1.0f / glm::vec2(resources.glass_layer.width, resources.glass_layer.height));
  u_screen_axes_.set(frame.glass.screen_axes());
  // Screen offset of the lookup per unit of the deflection angle's tangent: the focal length in
  // uv units of the view (the image's size and field of view).
  const float focal = frame.camera.projection[1][1];
  const float aspect = static_cast<float>(frame.spec.width) / static_cast<float>(frame.spec.height);
  u_refraction_.set(0.5f * glm::vec2(focal / aspect, focal));
  quad_.draw(frame);  // also the glass's axes, for the refracted rays
}

}  // namespace downpour::render
