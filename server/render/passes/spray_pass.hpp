#pragma once

#include <memory>
#include <vector>

#include <glm/vec4.hpp>

#include "server/render/cpu/spray_smoothing.hpp"
#include "server/render/cpu/spray_splat.hpp"
#include "server/render/gl/gl_objects.hpp"
#include "server/render/pass.hpp"
#include "server/sim/worker_thread.hpp"

namespace downpour::render {

// The spray (sim/spray.hpp) as seed 001's screen-space liquid, into the spray layer at half the
// view's size:
// - the liquid parcels (body or spray by neighbour count, from the simulation) into four depth
//   maps (front and back of each): on a GPU as squares that ray-cast their spheres, on llvmpipe by
//   the CPU (spray_splat.hpp: each small square cost llvmpipe about a microsecond);
// - the body's front depth smoothed (SpraySmoothing), over the tiles the body covers only;
// - the liquid's colour where a sphere was hit (a depth mask): normals from the depths, the chain
//   of at most four refractions found with the secant method, Schlick reflections of the sky,
//   Beer-Lambert absorption, the scene hiding what lies behind it (spray_shade.frag);
// - every parcel's cloud of droplets as haze over it: optical depth summed at a quarter of the
//   view's size, lit by the light around it, softly hidden by the scene.
class SprayPass final : public Pass {
 public:
  explicit SprayPass(SharedResources& shared);
  const PassDecl& decl() const override { return decl_; }
  bool wanted(const FrameContext& frame) const override;
  void execute(const FrameContext& frame, const FrameResources& resources) override;

  static constexpr int kScale = kSprayLayerScale;  // the layer's size: the view's over this
  static constexpr int kHazeScale = 2;             // the haze's: the layer's over this
  static constexpr int kTile = 8;                  // the layer's tiles, pixels

  // Makes the targets and CPU buffers a view of this size will need.
  void prepare(int view_width, int view_height);
  void set_smoothing(SpraySmoothing smoothing) { smoothing_ = smoothing; }
  SpraySmoothing smoothing() const { return smoothing_; }
  // Whether the CPU draws the parcels (llvmpipe) or the GPU; DOWNPOUR_SPRAY_SPLAT=cpu|gpu
  // overrides the choice by renderer.
  bool cpu_splat() const { return cpu_splat_; }
  void set_cpu_splat(bool cpu) { cpu_splat_ = cpu; }
  // The tiles with spray of the last frame drawn (uv runs over the view), for the composite.
  const std::vector<glm::vec4>& runs() const { return all_runs_; }
  struct Drawn {
    std::uint32_t body = 0, spray = 0, haze = 0;  // parcels drawn
  };
  const Drawn& drawn() const { return drawn_; }
  // Tests: the body's front distances (width x height, rows from the bottom; kSprayFar where
  // none) smoothed as the pass smooths them, with the current smoothing.
  std::vector<float> smooth_body_depth(int width, int height, glm::vec2 tan,
                                       const std::vector<float>& front);

 private:
  // Its steps: the depth maps (a sphere's hit passes greater-or-equal, so that MIN blending keeps
  // the nearest front and the farthest back), the smoothing and the shading (each only where the
  // mask holds a hit: kFarther at a depth under the mask's), the haze's optical depth (added up),
  // and the haze over the layer.
  enum Step : std::size_t { kMaps, kSmooth, kShade, kHaze, kHazeOver };
  const PassDecl decl_{"spray",
                       {Resource::kViewColour, Resource::kViewDepth},
                       {Resource::kSprayLayer},
                       {DepthTest::kOff, false, Blend::kOff},
                       false,
                       {{"maps", {DepthTest::kNearerOrEqual, true, Blend::kMin}},
                        {"smooth", {DepthTest::kFarther, false, Blend::kOff}},
                        {"shade", {DepthTest::kFarther, false, Blend::kOff}},
                        {"haze", {DepthTest::kOff, false, Blend::kAdd}},
                        {"haze over", {DepthTest::kOff, false, Blend::kPremultiplied}}}};
  struct Targets {
    int width = 0, height = 0;
    Texture depth;  // RGBA32F, the four maps
    Texture mask;   // D32F: where a sphere was hit (> 0), so that shading skips the rest
    Framebuffer depth_fbo;
    Texture smooth[2];  // R32F, ping-pong
    Framebuffer smooth_fbo[2];
    int haze_width = 0, haze_height = 0;
    Texture haze;  // RG32F: optical depth, and times distance
    Framebuffer haze_fbo;
    // The layer (a transient of the renderer's) with the mask, to shade only where hit.
    Framebuffer shade_fbo;
  };
  Targets& targets(int width, int height);
  // execute's parts, in order (spray_pass.cpp).
  void cull(const FrameContext& frame, int width, int height, int tiles_x, int tiles_y);
  void splat_on_cpu(const Targets& t, int width, int height, int tiles_x, glm::vec2 tan);
  void shade_liquid(const FrameContext& frame, const FrameResources& resources, Targets& t,
                    glm::vec2 tan);
  void haze_over(const FrameContext& frame, const FrameResources& resources, Targets& t);
  void upload(Buffer& buffer, const void* data, std::size_t bytes);
  void draw_runs(const std::vector<glm::vec4>& runs);
  void depth_maps(const FrameContext& frame, Targets& t);
  void haze_map(const FrameContext& frame, Targets& t);
  // The body's front distance smoothed over `runs` (uv); the texture that holds it.
  GLuint smooth(Targets& t, const std::vector<glm::vec4>& runs, glm::vec2 tan);

  ShaderProgram depth_program_, plane_program_, bilateral_program_, shade_program_, haze_program_,
      haze_composite_program_;
  Uniform u_depth_projection_, u_depth_spray_, u_depth_near_;
  Uniform u_plane_size_, u_plane_tan_, u_plane_sigma_, u_plane_shift_;
  Uniform u_bilateral_size_, u_bilateral_sigma_px_, u_bilateral_sigma_z_;
  Uniform u_shade_size_, u_shade_tan_, u_shade_to_world_, u_shade_near_, u_shade_scale_,
      u_shade_absorption_;
  Uniform u_haze_projection_;
  Uniform u_haze_light_, u_haze_near_, u_haze_soft_;
  VertexArray vao_;
  Buffer parcels_, haze_, runs_buffer_;
  std::vector<std::unique_ptr<Targets>> targets_;
  SpraySmoothing smoothing_ = SpraySmoothing::kPlaneFit;
  bool cpu_splat_ = false;
  // This frame's parcels in view space: the body's, the spray's, the clouds.
  std::vector<SprayBall> body_, spray_;
  std::vector<SprayHazeBall> clouds_;
  std::vector<glm::vec4> packed_;
  SprayDepthMaps maps_;
  std::vector<glm::vec2> haze_pixels_;
  std::vector<glm::vec4> liquid_runs_, body_runs_, all_runs_;
  std::vector<std::uint8_t> liquid_tiles_, body_tiles_, all_tiles_;
  Drawn drawn_;
  sim::WorkerThread helper_;  // draws the haze beside the liquid's maps (CPU)
};

// The spray layer over the view, over the spray pass's tiles.
class SprayCompositePass final : public Pass {
 public:
  SprayCompositePass(SharedResources& shared, const SprayPass& spray);
  const PassDecl& decl() const override { return decl_; }
  bool wanted(const FrameContext& frame) const override { return spray_.wanted(frame); }
  void execute(const FrameContext& frame, const FrameResources& resources) override;

 private:
  const PassDecl decl_{"spray_composite",
                       {Resource::kSprayLayer},
                       {Resource::kViewColour},
                       {DepthTest::kOff, false, Blend::kPremultiplied}};
  const SprayPass& spray_;
  ShaderProgram program_;
  VertexArray vao_;
  Buffer runs_buffer_;
};

}  // namespace downpour::render
