#include "server/render/passes/terrain_pass.hpp"

#include "server/render/scene_geometry.hpp"

namespace downpour::render {

TerrainPass::TerrainPass(SharedResources& shared)
    : program_("mesh.vert", "terrain.frag"),
      chunks_(build_terrain_chunks(shared.track), {200.0f, 500.0f, 1200.0f}) {
  program_.uniform("u_model").set(glm::mat4(1.0f));
}

void TerrainPass::execute(const FrameContext& frame, const FrameResources&) {
  program_.use();
  chunks_.draw_visible(frame.camera.projection * frame.camera.view, frame.camera.position,
                       frame.detail_distance_scale);
}

}  // namespace downpour::render
