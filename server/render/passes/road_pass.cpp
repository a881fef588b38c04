#include "server/render/passes/road_pass.hpp"

#include "server/render/scene_geometry.hpp"

namespace downpour::render {

RoadPass::RoadPass(SharedResources& shared) : program_("mesh.vert", "road.frag") {
  for (const MeshData& chunk : build_road_chunks(shared.track)) chunks_.emplace_back(chunk);
  const sim::CrossSection& section = shared.track.cross_section();
  program_.set("u_model", glm::mat4(1.0f));
  program_.set("u_lane_width", static_cast<float>(section.lane_width_m));
  program_.set("u_lanes_each_way", section.lanes_each_way);
  program_.set("u_paved_half_width", static_cast<float>(shared.track.paved_half_width()));
}

void RoadPass::draw(const FrameContext& frame) {
  program_.use();
  const glm::mat4 view_proj = frame.camera.projection * frame.camera.view;
  for (const Mesh& chunk : chunks_) {
    if (box_visible(view_proj, chunk.bounds_min, chunk.bounds_max)) chunk.draw();
  }
}

}  // namespace downpour::render
