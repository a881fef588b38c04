#pragma once

#include "server/render/pass.hpp"

namespace downpour::render {

// Vehicles as simple shapes: the ego car in outside views (its hood alone from the cockpit) and
// the traffic the simulator reports, each in its class's shape (car, truck, bus, motorbike)
// scaled to its size.
class VehiclePass final : public Pass {
 public:
  explicit VehiclePass(SharedResources& shared);
  const PassDecl& decl() const override { return decl_; }
  void execute(const FrameContext& frame, const FrameResources& resources) override;

 private:
  // Sets a vehicle's model matrix, colour and lamps for the meshes drawn next.
  void prepare(const glm::mat4& model, const glm::vec3& colour, const sim::VehicleLights& lights,
               bool flash_on);

  const PassDecl decl_{"vehicles",
                       {Resource::kLampMap},
                       {Resource::kViewColour, Resource::kViewDepth},
                       {DepthTest::kNearer, true, Blend::kOff}};
  ShaderProgram program_;
  Uniform u_model_, u_body_colour_, u_lamps_, u_head_;
  Mesh hull_;
  Mesh upper_;
  Mesh truck_, bus_, motorbike_;
};

}  // namespace downpour::render
