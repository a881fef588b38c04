#pragma once

#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include "server/render/chunked_mesh.hpp"
#include "server/render/pass.hpp"

namespace downpour::render {

// The road surface: procedural asphalt albedo and micro-relief normals from a height field
// (seed 003, section 3.1), lane markings, a crowned cross-section, and the water on it (seed 003's
// states, the road reflection, ripples in puddles: road_surface.glsl), and the shadows of the
// asphalt's and the shoulder's relief where the sun reaches the road (seed 002, relief.hpp).
//
// Whole, or in two parts (RoadPart): the near road into the road's layer at half the view's size
// (Resource::kRoadLayer, "road_layer"), which RoadCompositePass brings into the view, and the far
// road into the view ("road_far"). On llvmpipe the road's shading is most of a chase view's cost
// (ROAD, 640x360, a wet road with puddles: 8.3 ms drawn whole, 1.5 ms of it with a shader that
// does nothing), and most of the road's pixels are near: beyond where a layer's texel is
// kLayerTexelM across (17.3 m in a 640x360 ROAD) lies a tenth of its road. The near road's
// detail is what the layer's texels resolve (the shader's footprints, fwidth, are the layer's);
// the far road's thin markings and edges, which a layer's texel would break into steps and beads,
// keep the view's pixels.
enum class RoadPart : std::uint8_t { kWhole, kNearInLayer, kFar };

class RoadPass final : public Pass {
 public:
  explicit RoadPass(SharedResources& shared, RoadPart part = RoadPart::kWhole);
  // Where the near part ends: the view's depth (m) at which a layer's texel spans kLayerTexelM.
  static float layer_split_m(const FrameContext& frame);
  // How far from the camera the near part's chunks reach (m): to its end on the view's depth,
  // kLayerOverlapM beyond the split, at the view's corners. The composite draws the same.
  static float near_reach_m(const FrameContext& frame);
  static constexpr float kLayerTexelM = 0.1f;
  // The near part reaches this much further, for the composite's bilinear texels at its end.
  static constexpr float kLayerOverlapM = 2.0f;
  // The parts' geometry at the coarser levels from this many times nearer (ChunkedMesh).
  static constexpr float kPartsDetailScale = 4.0f;
  const PassDecl& decl() const override { return decl_; }
  void execute(const FrameContext& frame, const FrameResources& resources) override;
  // Relief shadows on (the default) or off, for comparisons; off by themselves wherever direct
  // sunlight is too faint to cast them (night, a heavy overcast).
  void set_relief_shadows(bool on) { relief_ = on; }
  bool relief_shadows() const { return relief_; }
  // Whether the last frame drew them.
  bool drew_relief() const { return drew_relief_; }
  // How far from the camera a pixel can still resolve the relief's shadows (m), for pixels
  // `scale` times the view's each way.
  static float relief_reach_m(const FrameContext& frame, int scale = 1);

 private:
  // (gl_ClipDistance[1]: the split between the near road, drawn with relief shadows, and the rest;
  // mesh_vertex.glsl.)
  PassDecl decl_;
  RoadPart part_;
  int scale_ = 1;  // the target's pixels over the view's, each way
  // road.frag, road_mirror.frag, road_ripples.frag, then the same with relief shadows
  // (road_surface.glsl): llvmpipe pays for both sides of a branch on every pixel, so the mirror,
  // the ripples and the shadows are programs of their own. Each in both lamps_build()s: the
  // variants with lamps, then those without.
  static constexpr std::size_t kVariants = 6;
  std::vector<ShaderProgram> programs_;
  // Each program's per-frame uniforms, looked up once.
  std::array<Uniform, 2 * kVariants> mean_lit_;
  std::array<Uniform, 2 * kVariants> near_split_;
  std::array<Uniform, 2 * kVariants> depth_clip_;
  std::shared_ptr<const relief::RoadReliefs> reliefs_;
  bool relief_ = true;
  bool drew_relief_ = false;
};

// The road's layer (RoadPass's near part) brought into the view, on the near road's own
// triangles up to the split (RoadPass::layer_split_m): they give each pixel its depth, tested
// against the view's (the cars drawn before it) before any shading, and the road's edges at the
// view's pixels; the layer gives the colour (bilinear over its texels that hold road, so that the
// edges do not darken). A full-screen triangle that took the layer's depth and discarded where it
// held no road cost 13% more in turn in a 640x360 ROAD: on llvmpipe a shader that writes its depth
// is shaded before the depth test, on every pixel of the rectangle it covers.
class RoadCompositePass final : public Pass {
 public:
  RoadCompositePass();
  const PassDecl& decl() const override { return decl_; }
  void execute(const FrameContext& frame, const FrameResources& resources) override;

 private:
  const PassDecl decl_;
  ShaderProgram program_;
  Uniform u_depth_clip_, u_inv_viewport_;
};

}  // namespace downpour::render
