#pragma once

#include "server/render/pass.hpp"

namespace downpour::render {

// Cars as simple shapes: the ego vehicle in outside views (its hood alone from the cockpit) and
// the traffic the simulator reports.
class VehiclePass final : public Pass {
 public:
  explicit VehiclePass(SharedResources& shared);
  const PassDecl& decl() const override { return decl_; }
  void execute(const FrameContext& frame, const FrameResources& resources) override;

 private:
  void draw_car(const glm::mat4& model, const glm::vec3& colour, const sim::VehicleLights& lights,
                bool flash_on, bool hull_only);

  const PassDecl decl_{"vehicles",
                       {},
                       {Resource::kViewColour, Resource::kViewDepth},
                       {DepthTest::kNearer, true, Blend::kOff}};
  ShaderProgram program_;
  Uniform u_model_, u_body_colour_, u_lamps_, u_head_;
  Mesh hull_;
  Mesh upper_;
};

}  // namespace downpour::render
