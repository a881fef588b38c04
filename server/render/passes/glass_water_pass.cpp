#include "server/render/passes/glass_water_pass.hpp"

#include <algorithm>
#include <cmath>

#include "server/render/cpu/atmosphere.hpp"
#include "server/sim/glass_water_surface.hpp"

namespace downpour::render {

glm::vec3 cabin_radiance(const Atmosphere& atmosphere, const GlassWaterConfig& config) {
  return atmosphere.ambient * config.cabin_per_ambient;
}

GlassWaterPass::Optics::Optics(const char* fragment_file, bool sharp,
                               const GlassWaterConfig& config)
    : program(std::make_unique<ShaderProgram>("glass.vert", fragment_file)),
      quad(*program),
      grid(*program),
      env_per_rad(program->uniform("u_env_per_rad")),
      env_max_lod(program->uniform("u_env_max_lod")),
      env_from_world(program->uniform("u_env_from_world")),
      cabin(program->uniform("u_cabin")),

      view_pixel_rad(program->uniform("u_view_pixel_rad")),
      inv_target(program->uniform("u_inv_target")),
      samples(program->uniform("u_samples")) {
  // The view's own image, and so the glass plane's depth that tells the cabin from it, is the
  // sharp program's alone.
  if (sharp) glass_depth = program->uniform("u_glass_depth");
  program->uniform("u_water_ior").set(config.water_ior);
}

GlassWaterPass::GlassWaterPass(SharedResources&, GlassWaterConfig config)
    : config_(config),
      sharp_("glass_water.frag", true, config_),
      blurred_("glass_water_blurred.frag", false, config_),
      pair_("glass_water_pair.frag", false, config_) {}

bool GlassWaterPass::wanted(const FrameContext& frame) const {
  // (The blades alone still need the glass layer, which this pass makes: the composite draws them.)
  return glass_has_water_or_blades(frame.water());
}

int GlassWaterPass::samples(int layer_scale) const {
  const int wanted = config_.samples_by_scale[std::clamp(layer_scale, 1, 4) - 1];
  return wanted >= 16 ? 16 : wanted >= 4 ? 4 : 2;
}

void GlassWaterPass::execute(const FrameContext& frame, const FrameResources& resources) {
  const int scale = frame.glass.layer_scale();  // 1 to 4
  const int samples = this->samples(scale);
  const Optics& o = scale == 1 ? sharp_ : pair(scale) ? pair_ : blurred_;
  o.program->use();
  o.grid.set(frame.water());
  const int face = std::max(resources.environment.width, 1);
  o.env_per_rad.set(0.5f * static_cast<float>(face));
  // No coarser than 8 x 8 texels a face (11 degrees each): a ray's light comes from around its own
  // direction, not from a whole face (the sun behind the car would light every grazing ray).
  o.env_max_lod.set(std::max(std::log2(static_cast<float>(face)) - 3.0f, 0.0f));
  o.env_from_world.set(glm::mat4(resources.environment_from_world));
  o.cabin.set(cabin_radiance(frame.atmosphere, config_));
  if (&o == &sharp_) o.glass_depth.set(frame.glass.depth_over_image());
  o.view_pixel_rad.set(2.0f * static_cast<float>(frame.camera.tan_half_fov_y) /
                       static_cast<float>(std::max(frame.spec.height, 1)));
  o.samples.set(samples);
  const TargetTexture& layer = resources.transient(Resource::kGlassLayer).colour;
  o.inv_target.set(1.0f / glm::vec2(layer.width, layer.height));
  o.quad.draw(frame);  // also the glass's axes, for the rays' frame
}

}  // namespace downpour::render
