#include "server/render/passes/road_pass.hpp"

#include "server/render/scene_geometry.hpp"

namespace downpour::render {

RoadPass::RoadPass(SharedResources& shared)
    : program_("mesh.vert", "road.frag"),
      chunks_(build_road_chunks(shared.track), {150.0f, 500.0f}) {
  const sim::CrossSection& section = shared.track.cross_section();
  program_.uniform("u_model").set(glm::mat4(1.0f));
  program_.uniform("u_lane_width").set(static_cast<float>(section.lane_width_m));
  program_.uniform("u_lanes_each_way").set(section.lanes_each_way);
  program_.uniform("u_paved_half_width").set(static_cast<float>(shared.track.paved_half_width()));
}

void RoadPass::execute(const FrameContext& frame, const FrameResources&) {
  program_.use();
  chunks_.draw_visible(frame.camera.projection * frame.camera.view, frame.camera.position);
}

}  // namespace downpour::render
