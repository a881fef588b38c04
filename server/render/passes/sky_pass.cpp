#include "server/render/passes/sky_pass.hpp"

namespace downpour::render {

SkyPass::SkyPass(SharedResources& shared)
    : shared_(shared), program_("fullscreen_ray.vert", "sky.frag") {}

void SkyPass::execute(const FrameContext&, const FrameResources&) {
  program_.use();
  shared_.fullscreen.draw();
}

}  // namespace downpour::render
