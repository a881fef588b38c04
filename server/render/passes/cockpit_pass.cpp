#include "server/render/passes/cockpit_pass.hpp"

#include "server/model/default_models.hpp"

namespace downpour::render {

CockpitPass::CockpitPass(SharedResources&)
    : program_("mesh.vert", "cockpit.frag"),
      u_model_(program_.uniform("u_model")),
      interior_(model::default_cabin(built_for_).mesh) {}

void CockpitPass::execute(const FrameContext& frame, const FrameResources&) {
  // The cabin is built around the scene's glass (remade in the rare case that it changes).
  const sim::GlassConfig& glass = frame.scene.glass;
  if (!model::same_cabin(glass, built_for_)) {
    built_for_ = glass;
    interior_ = Mesh(model::default_cabin(built_for_).mesh);
  }
  program_.use();
  named_.prune();
  if (const sim::ModelPtr& cabin = frame.scene.ego.cabin_model) {
    named_.get(cabin).draw(u_model_, frame.vehicle_to_world, 0.0, false);
    return;
  }
  u_model_.set(frame.vehicle_to_world);
  interior_.draw();
}

}  // namespace downpour::render
