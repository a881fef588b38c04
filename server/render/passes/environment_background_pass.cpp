#include "server/render/passes/environment_background_pass.hpp"

namespace downpour::render {

EnvironmentBackgroundPass::EnvironmentBackgroundPass(SharedResources& shared)
    : shared_(shared),
      program_("fullscreen_ray.vert", "environment_background.frag"),
      u_env_from_world_(program_.uniform("u_env_from_world")) {}

void EnvironmentBackgroundPass::execute(const FrameContext&, const FrameResources& resources) {
  program_.use();
  u_env_from_world_.set(glm::mat4(resources.environment_from_world));
  shared_.fullscreen.draw();
}

}  // namespace downpour::render
