#include "server/render/passes/cockpit_pass.hpp"

#include "server/render/vehicle_geometry.hpp"

namespace downpour::render {

CockpitPass::CockpitPass(SharedResources&)
    : program_("mesh.vert", "cockpit.frag"),
      interior_(build_cockpit_interior(WindshieldCorners{})) {}

void CockpitPass::draw(const FrameContext& frame) {
  program_.use();
  program_.set("u_model", frame.vehicle_to_world);
  interior_.draw();
}

}  // namespace downpour::render
