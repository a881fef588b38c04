#pragma once

#include <array>
#include <memory>
#include <vector>

#include "server/render/chunked_mesh.hpp"
#include "server/render/pass.hpp"

namespace downpour::render {

// The road surface: procedural asphalt albedo and micro-relief normals from a height field
// (seed 003, section 3.1), lane markings, a crowned cross-section, and the water on it (seed 003's
// states, the road reflection, ripples in puddles: road_surface.glsl), and the shadows of the
// asphalt's and the shoulder's relief where the sun reaches the road (seed 002, relief.hpp).
class RoadPass final : public Pass {
 public:
  explicit RoadPass(SharedResources& shared);
  const PassDecl& decl() const override { return decl_; }
  void execute(const FrameContext& frame, const FrameResources& resources) override;
  // Relief shadows on (the default) or off, for comparisons; off by themselves wherever direct
  // sunlight is too faint to cast them (night, a heavy overcast).
  void set_relief_shadows(bool on) { relief_ = on; }
  bool relief_shadows() const { return relief_; }
  // Whether the last frame drew them.
  bool drew_relief() const { return drew_relief_; }
  // How far from the camera a pixel can still resolve the relief's shadows (m).
  static float relief_reach_m(const FrameContext& frame);

 private:
  // (gl_ClipDistance[1]: the split between the near road, drawn with relief shadows, and the rest;
  // mesh_vertex.glsl.)
  const PassDecl decl_{"road",
                       {Resource::kRoadWater, Resource::kRoadReflection, Resource::kLampMap},
                       {Resource::kViewColour, Resource::kViewDepth},
                       {DepthTest::kNearer, true, Blend::kOff, true, false, 0b10}};
  // road.frag, road_mirror.frag, road_ripples.frag, then the same with relief shadows
  // (road_surface.glsl): llvmpipe pays for both sides of a branch on every pixel, so the mirror,
  // the ripples and the shadows are programs of their own. Each in both lamps_build()s: the
  // variants with lamps, then those without.
  static constexpr std::size_t kVariants = 6;
  std::vector<ShaderProgram> programs_;
  // Each program's per-frame uniforms, looked up once.
  std::array<Uniform, 2 * kVariants> mean_lit_;
  std::array<Uniform, 2 * kVariants> near_split_;
  std::shared_ptr<const relief::RoadReliefs> reliefs_;
  bool relief_ = true;
  bool drew_relief_ = false;
};

}  // namespace downpour::render
