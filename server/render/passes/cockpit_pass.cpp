#include "server/render/passes/cockpit_pass.hpp"

#include "server/render/cpu/vehicle_geometry.hpp"

namespace downpour::render {

CockpitPass::CockpitPass(SharedResources&)
    : program_("mesh.vert", "cockpit.frag"),
      u_model_(program_.uniform("u_model")),
      interior_(build_cockpit_interior(built_for_)) {}

void CockpitPass::execute(const FrameContext& frame, const FrameResources&) {
  // The cabin is built around the scene's glass (remade in the rare case that it changes).
  const sim::GlassConfig& glass = frame.scene.glass;
  if (!same_cockpit_interior(glass, built_for_)) {
    built_for_ = glass;
    interior_ = Mesh(build_cockpit_interior(built_for_));
  }
  program_.use();
  u_model_.set(frame.vehicle_to_world);
  interior_.draw();
}

}  // namespace downpour::render
