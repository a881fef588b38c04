#include "server/render/passes/glass_water_pass.hpp"

#include <algorithm>
#include <cmath>

#include "server/render/light_set.hpp"
#include "server/render/passes/lamp_glow_pass.hpp"

namespace downpour::render {

GlassWaterPass::GlassWaterPass(SharedResources&, GlassWaterConfig config)
    : config_(config),
      program_("glass.vert", "glass_water.frag"),
      quad_(program_),
      u_map_size_mm_(program_.uniform("u_map_size_mm")),
      u_taps_(program_.uniform("u_taps")),
      u_inv_target_(program_.uniform("u_inv_target")),
      u_screen_axes_(program_.uniform("u_screen_axes")),
      u_refraction_(program_.uniform("u_refraction")),
      u_lamp_count_(program_.uniform("u_lamp_count")),
      u_lamps_(program_.uniform("u_lamps")) {
  program_.uniform("u_water_ior").set(config_.water_ior);
  program_.uniform("u_fresnel_r0").set(config_.fresnel_r0);
  program_.uniform("u_rim_darkening").set(config_.rim_darkening);
  program_.uniform("u_rim_lean").set(glm::vec2(config_.rim_lean[0], config_.rim_lean[1]));
  program_.uniform("u_glint").set(config_.sun_glint);
  program_.uniform("u_lamp_spread")
      .set(glm::vec2(std::cos(config_.lamp_spread_rad[0]), std::cos(config_.lamp_spread_rad[1])));
  lamps_.reserve(2 * kGlassLamps + 2);  // an insertion before the list is cut back
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
  // The strongest glares (by insertion: kGlassLamps is small), each as a direction from the eye
  // towards the lamp and the radiance its drops show.
  lamps_.clear();
  if (frame.lights) {
    constexpr float kLeast = 0.002f;  // under 1% of white through a drop
    for (const Light& l : *frame.lights) {
      glm::vec3 to_camera;
      const float glare = lamp_glare(l, frame.camera.position, frame.atmosphere.lux_exposure,
                                     frame.atmosphere.fog_density, &to_camera);
      if (glare < kLeast) continue;
      const glm::vec4 lamp(-to_camera, glare * config_.lamp_scatter);
      const float peak = std::max({l.intensity_cd.r, l.intensity_cd.g, l.intensity_cd.b});
      const glm::vec4 colour(l.intensity_cd / peak, 0.0f);
      std::size_t at = lamps_.size();
      while (at > 0 && lamps_[at - 2].w < lamp.w) at -= 2;
      if (at >= 2 * kGlassLamps) continue;
      lamps_.insert(lamps_.begin() + static_cast<std::ptrdiff_t>(at), {lamp, colour});
      if (lamps_.size() > 2 * kGlassLamps) lamps_.resize(2 * kGlassLamps);
    }
  }
  u_lamp_count_.set(static_cast<int>(lamps_.size() / 2));
  if (!lamps_.empty()) u_lamps_.set(lamps_.data(), static_cast<int>(lamps_.size()));
  quad_.draw(frame);  // also the glass's axes, for the refracted rays
}

}  // namespace downpour::render
