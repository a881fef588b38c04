#include "server/render/passes/road_pass.hpp"

#include "server/render/scene_geometry.hpp"

namespace downpour::render {

namespace {

// Standing water (mm) from which road_surface.glsl draws a puddle, and so ripples.
constexpr float kPuddleFromMm = 0.6f;

}  // namespace

RoadPass::RoadPass(SharedResources& shared)
    : programs_{ShaderProgram("mesh.vert", "road.frag"),
                ShaderProgram("mesh.vert", "road_mirror.frag"),
                ShaderProgram("mesh.vert", "road_ripples.frag")},
      chunks_(build_road_chunks(shared.track), {150.0f, 500.0f}) {
  const sim::CrossSection& section = shared.track.cross_section();
  for (const ShaderProgram& program : programs_) {
    program.uniform("u_model").set(glm::mat4(1.0f));
    program.uniform("u_lane_width").set(static_cast<float>(section.lane_width_m));
    program.uniform("u_lanes_each_way").set(section.lanes_each_way);
    program.uniform("u_paved_half_width").set(static_cast<float>(shared.track.paved_half_width()));
  }
}

void RoadPass::execute(const FrameContext& frame, const FrameResources& resources) {
  // The mirror where the renderer drew the reflection (a film stands somewhere); ripples where,
  // besides, it rains on a puddle.
  const bool mirror = resources.road_reflection.texture != 0;
  const sim::RoadWaterImage* water = frame.scene.road_water.get();
  const bool ripples = mirror && frame.scene.weather.rain_rate_mm_h > 0.0 && water &&
                       water->max_standing_mm > kPuddleFromMm;
  programs_[ripples ? 2 : mirror ? 1 : 0].use();
  chunks_.draw_visible(frame.camera.projection * frame.camera.view, frame.camera.position);
}

}  // namespace downpour::render
