#pragma once

#include <vector>

#include "server/model/vehicle_model.hpp"
#include "server/render/pass.hpp"

namespace downpour::render {

// Vehicles as their models (model/default_models.hpp): the ego car in outside views (its bonnet
// alone from the cockpit) and the traffic the simulator reports, each in its class's model (car,
// truck, bus, motorbike) scaled to its size, their wheels turned by how far they have rolled.
class VehiclePass final : public Pass {
 public:
  explicit VehiclePass(SharedResources& shared);
  const PassDecl& decl() const override { return decl_; }
  void execute(const FrameContext& frame, const FrameResources& resources) override;

 private:
  // Sets a vehicle's colour and lamps for the meshes drawn next.
  void prepare(const glm::vec3& colour, const sim::VehicleLights& lights, bool flash_on);

  const PassDecl decl_{"vehicles",
                       {Resource::kLampMap},
                       {Resource::kViewColour, Resource::kViewDepth},
                       {DepthTest::kNearer, true, Blend::kOff}};
  // A model on the GPU: its mesh, and where its parts lie in it.
  struct Drawn {
    explicit Drawn(const model::VehicleModel& m);
    Mesh mesh;
    std::uint32_t fixed = 0, bonnet = 0;
    std::vector<model::Wheel> wheels;
  };
  // The fixed parts (or the bonnet alone) and each wheel turned by rolled_m / its radius.
  void draw(const Drawn& d, const glm::mat4& model, double rolled_m, bool bonnet_only);

  ShaderProgram program_;
  Uniform u_model_, u_body_colour_, u_lamps_, u_head_;
  // Each class's model in full and for the distance (default_models.hpp's Detail): by class.
  std::vector<Drawn> near_, far_;
};

}  // namespace downpour::render
