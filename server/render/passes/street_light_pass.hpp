#pragma once

#include <array>

#include "server/render/chunked_mesh.hpp"
#include "server/render/pass.hpp"

namespace downpour::render {

// The roads' street lights (sim/lights.hpp; their meshes built in scene_geometry.hpp, kept in
// world.hpp): a pole on the verge, an arm over the road and a lamp at its end, whose lens glows
// when the lights are on (their light on the ground is the lamp map's). Static geometry in chunks
// of four poles, culled against the view and beyond kStreetLightsDrawnWithin_m (world.hpp) over
// the frame's detail distance scale (the road's mirror, at a quarter of the size, stops at a
// quarter of its view's); mirrored in the wet road with the cars.
class StreetLightPass final : public Pass {
 public:
  explicit StreetLightPass(SharedResources& shared);
  const PassDecl& decl() const override { return decl_; }
  void execute(const FrameContext& frame, const FrameResources& resources) override;

 private:
  const PassDecl decl_{"street_lights",
                       {},
                       {Resource::kViewColour, Resource::kViewDepth},
                       {DepthTest::kNearer, true, Blend::kOff}};
  std::array<ShaderProgram, 2> programs_;  // by lamps_build()
  std::array<Uniform, 2> u_head_;
};

}  // namespace downpour::render
