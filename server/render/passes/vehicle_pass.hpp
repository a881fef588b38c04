#pragma once

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "server/render/model_meshes.hpp"
#include "server/render/pass.hpp"

namespace downpour::render {

// Vehicles as their models: the ego car in outside views (its bonnet alone from the cockpit) and
// the traffic the simulator reports, each in the model it names or its class's built-in one (car,
// truck, bus, motorbike: model/default_models.hpp) scaled to its size, their wheels turned by how
// far they have rolled.
class VehiclePass final : public Pass {
 public:
  explicit VehiclePass(SharedResources& shared);
  const PassDecl& decl() const override { return decl_; }
  void execute(const FrameContext& frame, const FrameResources& resources) override;

 private:
  // Sets a vehicle's colour, lamps and how wet the spray made it for the meshes drawn next.
  void prepare(const glm::vec3& colour, const sim::VehicleLights& lights, bool flash_on,
               float body_wet);

  const PassDecl decl_{"vehicles",
                       {Resource::kLampMap},
                       {Resource::kViewColour, Resource::kViewDepth},
                       {DepthTest::kNearer, true, Blend::kOff}};
  // The program in one of its lamps_build()s, and its uniforms.
  struct Build {
    explicit Build(const std::vector<std::string>& defines);
    ShaderProgram program;
    ModelUniforms uniforms;
    Uniform u_body_colour, u_lamps, u_head, u_wet;
  };
  std::array<Build, 2> builds_;
  const Build* build_ = &builds_[0];  // this frame's
  // Each class's built-in model in full and for the distance (default_models.hpp's Detail): by
  // class. The models sessions name, as their scenes hold them.
  std::vector<ModelMesh> near_, far_;
  ModelMeshes named_;
};

}  // namespace downpour::render
