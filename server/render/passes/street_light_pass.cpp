#include "server/render/passes/street_light_pass.hpp"

#include "server/render/world.hpp"

namespace downpour::render {
StreetLightPass::StreetLightPass(SharedResources&)
    : programs_{ShaderProgram("mesh.vert", "vehicle.frag", kLampBuilds[0]),
                ShaderProgram("mesh.vert", "vehicle.frag", kLampBuilds[1])} {
  for (std::size_t b = 0; b < programs_.size(); ++b) {
    programs_[b].uniform("u_model").set(glm::mat4(1.0f));
    programs_[b].uniform("u_body_colour").set(glm::vec3(0.3f, 0.31f, 0.32f));
    programs_[b].uniform("u_lamps").set(glm::vec4(0.0f));
    u_head_[b] = programs_[b].uniform("u_head");
  }
}

void StreetLightPass::execute(const FrameContext& frame, const FrameResources&) {
  const int build = lamps_build(frame);
  programs_[build].use();
  u_head_[build].set(sim::street_lights_on(frame.scene.weather) ? 1.0f : 0.0f);
  frame.world->street_light_poles.draw_visible(frame.camera.projection * frame.camera.view,
                                               frame.camera.position, frame.detail_distance_scale);
}

}  // namespace downpour::render
