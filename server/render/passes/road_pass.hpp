#pragma once

#include <array>

#include "server/render/chunked_mesh.hpp"
#include "server/render/pass.hpp"

namespace downpour::render {

// The road surface: procedural asphalt albedo and micro-relief normals from a height field
// (seed 003, section 3.1), lane markings, a crowned cross-section, and the water on it (seed 003's
// states, the road reflection, ripples in puddles: road_surface.glsl).
class RoadPass final : public Pass {
 public:
  explicit RoadPass(SharedResources& shared);
  const PassDecl& decl() const override { return decl_; }
  void execute(const FrameContext& frame, const FrameResources& resources) override;

 private:
  const PassDecl decl_{"road",
                       {Resource::kRoadWater, Resource::kRoadReflection},
                       {Resource::kViewColour, Resource::kViewDepth},
                       {DepthTest::kNearer, true, Blend::kOff}};
  // road.frag, road_mirror.frag, road_ripples.frag (road_surface.glsl): llvmpipe pays for both
  // sides of a branch on every pixel, so the mirror and the ripples are programs of their own.
  std::array<ShaderProgram, 3> programs_;
  ChunkedMesh chunks_;
};

}  // namespace downpour::render
