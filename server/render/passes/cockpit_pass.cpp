#include "server/render/passes/cockpit_pass.hpp"

#include "server/model/default_models.hpp"

namespace downpour::render {

CockpitPass::CockpitPass(SharedResources&)
    : program_("model.vert", "cockpit.frag"),
      uniforms_(program_),
      interior_(model::default_cabin(built_for_)) {}

void CockpitPass::execute(const FrameContext& frame, const FrameResources&) {
  // The cabin is built around the scene's glass (remade in the rare case that it changes).
  const sim::GlassConfig& glass = frame.scene.glass;
  if (!model::same_cabin(glass, built_for_)) {
    built_for_ = glass;
    interior_ = ModelMesh(model::default_cabin(built_for_));
  }
  program_.use();
  named_.prune();
  const sim::ModelPtr& cabin = frame.scene.ego.cabin_model;
  (cabin ? named_.get(cabin) : interior_).draw(uniforms_, frame.vehicle_to_world, 0.0, false);
}

}  // namespace downpour::render
