#include "server/render/passes/street_light_pass.hpp"

#include "server/render/world.hpp"

namespace downpour::render {
StreetLightPass::StreetLightPass(SharedResources&)
    : program_("mesh.vert", "vehicle.frag"), u_head_(program_.uniform("u_head")) {
  program_.uniform("u_model").set(glm::mat4(1.0f));
  program_.uniform("u_body_colour").set(glm::vec3(0.3f, 0.31f, 0.32f));
  program_.uniform("u_lamps").set(glm::vec4(0.0f));
}

void StreetLightPass::execute(const FrameContext& frame, const FrameResources&) {
  program_.use();
  u_head_.set(sim::street_lights_on(frame.scene.weather) ? 1.0f : 0.0f);
  frame.world->street_light_poles.draw_visible(frame.camera.projection * frame.camera.view,
                                               frame.camera.position, frame.detail_distance_scale);
}

}  // namespace downpour::render
