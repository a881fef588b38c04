#include "server/render/passes/glass_water_mask_pass.hpp"

namespace downpour::render {

GlassWaterMaskPass::GlassWaterMaskPass(SharedResources&)
    : program_("glass.vert", "glass_water_mask.frag"), quad_(program_), grid_(program_) {}

bool GlassWaterMaskPass::wanted(const FrameContext& frame) const {
  return glass_has_water_or_blades(frame.water());  // as GlassWaterPass
}

void GlassWaterMaskPass::execute(const FrameContext& frame, const FrameResources&) {
  program_.use();
  grid_.set(frame.water());
  quad_.draw(frame);
}

}  // namespace downpour::render
