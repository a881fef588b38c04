#include "server/render/passes/terrain_pass.hpp"

#include "server/render/scene_geometry.hpp"

namespace downpour::render {

TerrainPass::TerrainPass(SharedResources& shared) : program_("mesh.vert", "terrain.frag") {
  for (const MeshData& chunk : build_terrain_chunks(shared.track)) chunks_.emplace_back(chunk);
  program_.set("u_model", glm::mat4(1.0f));
}

void TerrainPass::draw(const FrameContext& frame) {
  program_.use();
  const glm::mat4 view_proj = frame.camera.projection * frame.camera.view;
  for (const Mesh& chunk : chunks_) {
    if (box_visible(view_proj, chunk.bounds_min, chunk.bounds_max)) chunk.draw();
  }
}

}  // namespace downpour::render
