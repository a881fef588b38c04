#include "server/render/passes/windshield_pass.hpp"

#include <glm/geometric.hpp>

#include "server/render/vehicle_geometry.hpp"

namespace downpour::render {

WindshieldPass::WindshieldPass(SharedResources& shared)
    : shared_(shared), program_("fullscreen.vert", "windshield.frag") {
  const WindshieldCorners g;
  const float bottom = glm::length(g.bottom_left - g.bottom_right);
  const float top = glm::length(g.top_left - g.top_right);
  const float height =
      glm::length(0.5f * (g.top_left + g.top_right) - 0.5f * (g.bottom_left + g.bottom_right));
  // The glass as a trapezoid in its own plane, in metres; the view fits it with a margin.
  program_.set("u_glass", glm::vec3(bottom, top, height));
}

void WindshieldPass::draw(const FrameContext& frame) {
  glDisable(GL_DEPTH_TEST);
  program_.use();
  program_.set("u_aspect",
               static_cast<float>(frame.spec.width) / static_cast<float>(frame.spec.height));
  shared_.fullscreen.draw();
}

}  // namespace downpour::render
