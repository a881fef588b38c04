#include "server/render/passes/sky_pass.hpp"

namespace downpour::render {

SkyPass::SkyPass(SharedResources& shared)
    : shared_(shared), program_("fullscreen.vert", "sky.frag") {}

void SkyPass::draw(const FrameContext&) {
  // At depth 0 (infinitely far, reversed-Z): drawn only where nothing else was.
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_GEQUAL);
  glDepthMask(GL_FALSE);
  program_.use();
  shared_.fullscreen.draw();
  glDepthMask(GL_TRUE);
  glDepthFunc(GL_GREATER);
}

}  // namespace downpour::render
