#pragma once

#include <array>

#include "server/render/pass.hpp"

namespace downpour::render {

// The ground around the road: hills in chunks culled against the view, grass and soil shaded by
// sun and sky, fogged with distance.
class TerrainPass final : public Pass {
 public:
  explicit TerrainPass(SharedResources& shared);
  const PassDecl& decl() const override { return decl_; }
  void execute(const FrameContext& frame, const FrameResources& resources) override;

 private:
  const PassDecl decl_{"terrain",
                       {Resource::kLampMap},
                       {Resource::kViewColour, Resource::kViewDepth},
                       {DepthTest::kNearer, true, Blend::kOff}};
  std::array<ShaderProgram, 2> programs_;  // by lamps_build()
};

}  // namespace downpour::render
