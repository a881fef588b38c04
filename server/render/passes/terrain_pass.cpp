#include "server/render/passes/terrain_pass.hpp"

#include "server/render/world.hpp"

namespace downpour::render {

TerrainPass::TerrainPass(SharedResources&)
    : programs_{ShaderProgram("mesh.vert", "terrain.frag", kLampBuilds[0]),
                ShaderProgram("mesh.vert", "terrain.frag", kLampBuilds[1])} {
  for (const ShaderProgram& program : programs_) program.uniform("u_model").set(glm::mat4(1.0f));
}

void TerrainPass::execute(const FrameContext& frame, const FrameResources&) {
  programs_[lamps_build(frame)].use();
  frame.world->terrain.draw_visible(frame.camera.projection * frame.camera.view,
                                    frame.camera.position, frame.detail_distance_scale);
}

}  // namespace downpour::render
