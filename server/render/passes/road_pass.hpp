#pragma once

#include "server/render/chunked_mesh.hpp"
#include "server/render/pass.hpp"

namespace downpour::render {

// The road surface: procedural asphalt albedo and micro-relief normals from a height field
// (seed 003, section 3.1), lane markings, a crowned cross-section, a wet sheen in the rain.
class RoadPass final : public Pass {
 public:
  explicit RoadPass(SharedResources& shared);
  const PassDecl& decl() const override { return decl_; }
  void execute(const FrameContext& frame, const FrameResources& resources) override;

 private:
  const PassDecl decl_{"road",
                       {},
                       {Resource::kViewColour, Resource::kViewDepth},
                       {DepthTest::kNearer, true, Blend::kOff}};
  ShaderProgram program_;
  ChunkedMesh chunks_;
};

}  // namespace downpour::render
