#include "server/render/passes/road_reflection_pass.hpp"

#include <algorithm>
#include <utility>

namespace downpour::render {

RoadReflectionPass::RoadReflectionPass(FrameBlockBuffer& block, std::vector<Reflected> reflected)
    : decl_{"road_reflection", {}, {Resource::kRoadReflection}, {}},
      block_(block),
      reflected_(std::move(reflected)) {
  for (const Reflected& r : reflected_) {
    for (Resource read : r.pass->decl().reads) {
      if (std::find(decl_.reads.begin(), decl_.reads.end(), read) == decl_.reads.end())
        decl_.reads.push_back(read);
    }
  }
}

void RoadReflectionPass::execute(const FrameContext& f, const FrameResources& r) {
  const Mirror& mirror = block_.view_water().mirror;
  Camera mirrored = f.camera;
  mirrored.view = f.camera.view * mirror.matrix;
  mirrored.position = glm::vec3(mirror.matrix * glm::vec4(f.camera.position, 1.0f));
  FrameContext mf{f.scene, f.spec, mirrored, f.atmosphere, f.vehicle_to_world, f.glass, f.stepped};
  // At a quarter of the view's size it needs a quarter of the detail.
  mf.detail_distance_scale = f.detail_distance_scale * static_cast<float>(kRoadReflectionScale);
  mf.world = f.world;
  mf.lights = f.lights;  // (the lamp block holds them: the mirror's passes light with them too)
  block_.upload(mf, WaterBlock{});
  for (const Reflected& pass : reflected_) {
    glm::vec4 plane = mirror.plane;
    plane.w -= pass.clearance_m;
    block_.set_clip_plane(plane);
    RenderState state = pass.pass->decl().state;
    state.clip_distances |= 1;
    apply(state);
    pass.pass->execute(mf, r);
  }
  block_.restore_view();
}

}  // namespace downpour::render
