#include "server/render/passes/terrain_pass.hpp"

#include "server/render/world.hpp"

namespace downpour::render {

TerrainPass::TerrainPass(SharedResources&) : program_("mesh.vert", "terrain.frag") {
  program_.uniform("u_model").set(glm::mat4(1.0f));
}

void TerrainPass::execute(const FrameContext& frame, const FrameResources&) {
  program_.use();
  frame.world->terrain.draw_visible(frame.camera.projection * frame.camera.view,
                                    frame.camera.position, frame.detail_distance_scale);
}

}  // namespace downpour::render
