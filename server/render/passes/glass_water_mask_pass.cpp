#include "server/render/passes/glass_water_mask_pass.hpp"

#include "server/render/passes/glass_water_pass.hpp"

namespace downpour::render {

GlassWaterMaskPass::Mask::Mask(const char* fragment_file)
    : program(std::make_unique<ShaderProgram>("glass.vert", fragment_file)),
      quad(*program),
      grid(*program) {}

GlassWaterMaskPass::GlassWaterMaskPass(SharedResources&, const GlassWaterPass& optics)
    : optics_(optics), footprint_("glass_water_mask.frag"), pair_("glass_water_mask_pair.frag") {}

bool GlassWaterMaskPass::wanted(const FrameContext& frame) const {
  return glass_has_water_or_blades(frame.water());  // as GlassWaterPass
}

void GlassWaterMaskPass::execute(const FrameContext& frame, const FrameResources&) {
  const Mask& m = optics_.pair(frame.glass.layer_scale()) ? pair_ : footprint_;
  m.program->use();
  m.grid.set(frame.water());
  m.quad.draw(frame);
}

}  // namespace downpour::render
