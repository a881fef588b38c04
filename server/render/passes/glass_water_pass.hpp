#pragma once

#include <vector>

#include <glm/vec4.hpp>

#include "server/render/glass_quad.hpp"
#include "server/render/pass.hpp"

namespace downpour::render {

// The optics of the water on the glass (seed 000, section 1.5 step 5, and beyond the paper).
struct GlassWaterConfig {
  float water_ior = 1.33f;
  float fresnel_r0 = 0.02f;  // water
  // Rims: where the surface leans more than rim_lean[0] (up to rim_lean[1]) the refracted rays
  // graze it and see little: darker by this much.
  float rim_darkening = 0.55f;
  float rim_lean[2] = {0.40f, 0.62f};
  float sun_glint = 3.0f;  // the sun seen through a drop, relative to its direct light
  // Lamps through the drops at night. A drop on the glass is a lens with a wide field: its
  // surface leans every way up to its contact angle (some 45 degrees on a windshield), so it
  // bends a lamp's light into the eye from anywhere within some 25 degrees of the lamp, and the
  // lamp's illuminance at the glass spreads over that cone. Seen from the driver's seat, every
  // drop around a bright lamp holds a bright point of it: the lamps bloom through the wet glass
  // (a flat film does not: only curved water does this). The share of the lamp's glare a drop
  // shows at lamp_spread_rad from the lamp: full out to the first angle, none past the second
  // (some 0.25 sr in all); lamp_scatter: the radiance per glare within it (pi / 0.25 sr, less the
  // surfaces' reflections).
  float lamp_scatter = 11.0f;
  float lamp_spread_rad[2] = {0.10f, 0.44f};
};

// At most this many lamps light the drops: the strongest glares, above a least one (eight cost the
// glass water pass 0.25 ms in the lights benchmark's rain, four 0.1, and the brightest few make
// the bloom).
inline constexpr int kGlassLamps = 4;

// COCKPIT: the water on the glass as the view sees it, into the glass layer at 1 / layer_scale of
// the view's size (GlassView: its pixels as wide as the lens's blur of the glass). Each drop is a
// lens showing the world behind it turned over, with the cabin reflected inside its surface, dark
// rims, the sun glinting through it and at night the lamps around it (glass_water.frag). A blurred
// view evaluates the optics at 2 x 2 points of each layer pixel and averages them: the lens blurs
// what is seen through the water, not the water's shape (averaged normals would make a flat,
// invisible drop).
class GlassWaterPass final : public Pass {
 public:
  explicit GlassWaterPass(SharedResources& shared, GlassWaterConfig config = {});
  const PassDecl& decl() const override { return decl_; }
  bool wanted(const FrameContext& frame) const override;
  void execute(const FrameContext& frame, const FrameResources& resources) override;

 private:
  const PassDecl decl_{"glass_water",
                       {Resource::kGlassWater, Resource::kSceneBlur},
                       {Resource::kGlassLayer},
                       {},
                       true};
  GlassWaterConfig config_;
  ShaderProgram program_;
  GlassQuad quad_;
  Uniform u_map_size_mm_, u_taps_, u_inv_target_, u_screen_axes_, u_refraction_;
  Uniform u_lamp_count_, u_lamps_;
  std::vector<glm::vec4> lamps_;  // per lamp: direction towards it, glare; colour
};

}  // namespace downpour::render
