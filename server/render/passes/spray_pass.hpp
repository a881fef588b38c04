// The spray (sim/spray.hpp) as seed 001's screen-space liquid, into the spray layer at a third of
// the view's size, in six declared passes whose targets are the renderer's transients
// (resource.hpp):
// - spray_maps (spray_pass.cpp): the parcels culled to the view (body or spray by neighbour count,
// from
//   the simulation, and every parcel's cloud), and the liquid into four depth maps (front and back
//   of each) with a mask of what was hit (kSprayMaps): on a GPU as squares that ray-cast their
//   spheres, on llvmpipe by the CPU (cpu/spray_splat.hpp: each small square cost llvmpipe about a
//   microsecond), which draws the clouds' haze beside them on a helper thread;
// - spray_smooth (spray_smooth_pass.cpp): the body's front depth smoothed (SpraySmoothing), over
//   the tiles the body covers only (kSprayBodyFront);
// - spray_shade (spray_shade_pass.cpp): the liquid's colour where a sphere was hit: normals from
//   the depths, the chain of at most four refractions found with the secant method, Schlick
//   reflections of the sky, Beer-Lambert absorption, the scene hiding what lies behind it;
// - spray_haze: the clouds' optical depth summed at half the layer's size (kSprayHaze);
// - spray_haze_over: that haze over the layer, lit by the light around it, softly hidden by the
//   scene;
// - spray_composite: the layer over the view, over the tiles with spray.
#pragma once

#include <cstdint>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec4.hpp>

#include "server/render/cpu/spray_smoothing.hpp"
#include "server/render/cpu/spray_splat.hpp"
#include "server/render/gl/gl_objects.hpp"
#include "server/render/pass.hpp"
#include "server/sim/spray.hpp"
#include "server/sim/worker_thread.hpp"

namespace downpour::render {

// Runs of tiles (uv rectangles over a layer) drawn as quads by spray_runs.vert.
class TileRuns {
 public:
  TileRuns();
  void draw(const std::vector<glm::vec4>& runs);

 private:
  VertexArray vao_;
  Buffer buffer_;
};

// A parcel's cloud of droplets at view-space v, drawn into a haze map whose pixel spans
// haze_pixel_m there: false where it is too thin to draw. (The view's spray and its mirror.)
bool spray_cloud(const sim::SprayImage::Point& p, const glm::vec3& v, float haze_pixel_m,
                 SprayHazeBall& out);

class SprayPass final : public Pass {
 public:
  explicit SprayPass(SharedResources& shared);
  const PassDecl& decl() const override { return decl_; }
  bool wanted(const FrameContext& frame) const override;
  void execute(const FrameContext& frame, const FrameResources& resources) override;
  // The CPU's maps are uploaded whole where there is liquid (without it, nothing reads them).
  bool overwrites_target(const FrameContext&) const override { return cpu_splat_; }

  static constexpr int kScale = kSprayLayerScale;         // the layer: the view's over this
  static constexpr int kHazeScale = kSprayHazeOverLayer;  // the haze: the layer's over this
  static constexpr int kTile = 8;                         // the layer's tiles, pixels

  // Makes the CPU buffers a view of this size will need.
  void prepare(int view_width, int view_height);
  // Whether the CPU draws the parcels (llvmpipe) or the GPU; DOWNPOUR_SPRAY_SPLAT=cpu|gpu
  // overrides the choice by renderer.
  bool cpu_splat() const { return cpu_splat_; }
  void set_cpu_splat(bool cpu) { cpu_splat_ = cpu; }
  struct Drawn {
    std::uint32_t body = 0, spray = 0, haze = 0;  // parcels drawn
  };
  const Drawn& drawn() const { return drawn_; }

  // This frame's parcels in view space, for the passes after: the body's, the lone spray's, the
  // clouds; and the tiles (uv runs over the layer) with liquid, with the body, with anything.
  const std::vector<SprayBall>& body() const { return body_; }
  const std::vector<SprayBall>& spray() const { return spray_; }
  const std::vector<SprayHazeBall>& clouds() const { return clouds_; }
  bool has_liquid() const { return !body_.empty() || !spray_.empty(); }
  const std::vector<glm::vec4>& liquid_runs() const { return liquid_runs_; }
  const std::vector<glm::vec4>& body_runs() const { return body_runs_; }
  const std::vector<glm::vec4>& runs() const { return all_runs_; }
  // The haze the CPU drew (cpu_splat), at kSprayHaze's size.
  const std::vector<glm::vec2>& haze_pixels() const { return haze_pixels_; }

 private:
  // A sphere's hit passes greater-or-equal, so that MIN blending keeps the nearest front and the
  // farthest back.
  const PassDecl decl_{
      "spray_maps", {}, {Resource::kSprayMaps}, {DepthTest::kNearerOrEqual, true, Blend::kMin}};
  // execute's parts, in order.
  void cull(const FrameContext& frame, int width, int height, int tiles_x, int tiles_y);
  void splat_on_cpu(const FrameTarget& maps, int haze_width, int haze_height, int tiles_x,
                    glm::vec2 tan);
  void draw_maps(const FrameContext& frame);

  ShaderProgram depth_program_;
  Uniform u_depth_projection_, u_depth_spray_, u_depth_near_;
  VertexArray vao_;
  Buffer parcels_;
  bool cpu_splat_ = false;
  std::vector<SprayBall> body_, spray_;
  std::vector<SprayHazeBall> clouds_;
  std::vector<glm::vec4> packed_;
  SprayDepthMaps maps_;
  std::vector<glm::vec2> haze_pixels_;
  std::vector<glm::vec4> liquid_runs_, body_runs_, all_runs_;
  std::vector<std::uint8_t> liquid_tiles_, body_tiles_, all_tiles_;
  Drawn drawn_;
  sim::WorkerThread helper_{"dp-spray"};  // draws the haze beside the liquid's maps (CPU)
};

class SpraySmoothPass final : public Pass {
 public:
  SpraySmoothPass(SharedResources& shared, const SprayPass& spray);
  const PassDecl& decl() const override { return decl_; }
  bool wanted(const FrameContext& frame) const override {
    return spray_.wanted(frame) && spray_.has_liquid();
  }
  void execute(const FrameContext& frame, const FrameResources& resources) override;
  void set_smoothing(SpraySmoothing smoothing) { smoothing_ = smoothing; }
  SpraySmoothing smoothing() const { return smoothing_; }
  // The body's front distance in `maps` smoothed into `out` over `runs` (uv), its mask the depth
  // of both: execute's, and the tests' (Renderer::smooth_spray_body).
  void smooth(const FrameTarget& maps, const FrameTarget& out, const std::vector<glm::vec4>& runs,
              glm::vec2 tan);

 private:
  // Only where the mask holds the body: the runs at a depth between the spray's mark and the
  // body's (llvmpipe rejects the rest before shading).
  const PassDecl decl_{"spray_smooth",
                       {Resource::kSprayMaps},
                       {Resource::kSprayBodyFront},
                       {DepthTest::kFarther, false, Blend::kOff}};
  // The second of the ping-pong pair (the first is kSprayBodyFront), by size.
  struct Scratch {
    int width = 0, height = 0;
    Texture texture;
    Framebuffer fbo;
  };
  Scratch& scratch(int width, int height);

  const SprayPass& spray_;
  ShaderProgram plane_program_, bilateral_program_;
  Uniform u_plane_size_, u_plane_tan_, u_plane_sigma_, u_plane_shift_;
  Uniform u_bilateral_size_, u_bilateral_sigma_px_, u_bilateral_sigma_z_;
  TileRuns runs_;
  std::vector<Scratch> scratch_;
  SpraySmoothing smoothing_ = SpraySmoothing::kPlaneFit;
};

class SprayShadePass final : public Pass {
 public:
  SprayShadePass(SharedResources& shared, const SprayPass& spray);
  const PassDecl& decl() const override { return decl_; }
  bool wanted(const FrameContext& frame) const override {
    return spray_.wanted(frame) && spray_.has_liquid();
  }
  void execute(const FrameContext& frame, const FrameResources& resources) override;

 private:
  // The runs at depth 0 pass only where a hit left more in the mask (the layer's depth).
  const PassDecl decl_{"spray_shade",
                       {Resource::kViewColour, Resource::kViewDepth, Resource::kSprayMaps,
                        Resource::kSprayBodyFront},
                       {Resource::kSprayLayer},
                       {DepthTest::kFarther, false, Blend::kOff}};
  const SprayPass& spray_;
  ShaderProgram program_;
  Uniform u_size_, u_tan_, u_to_world_, u_near_, u_scale_, u_absorption_;
  TileRuns runs_;
};

class SprayHazePass final : public Pass {
 public:
  SprayHazePass(SharedResources& shared, const SprayPass& spray);
  const PassDecl& decl() const override { return decl_; }
  bool wanted(const FrameContext& frame) const override {
    return spray_.wanted(frame) && !spray_.clouds().empty();
  }
  void execute(const FrameContext& frame, const FrameResources& resources) override;
  // The CPU's haze is uploaded whole.
  bool overwrites_target(const FrameContext&) const override { return spray_.cpu_splat(); }

 private:
  // The clouds' optical depth added up.
  const PassDecl decl_{
      "spray_haze", {}, {Resource::kSprayHaze}, {DepthTest::kOff, false, Blend::kAdd}};
  const SprayPass& spray_;
  ShaderProgram program_;
  Uniform u_projection_;
  VertexArray vao_;
  Buffer clouds_;
  std::vector<glm::vec4> packed_;
};

// The light the spray's droplets scatter from the sky and the scene (its haze, and its mirror's).
glm::vec3 spray_haze_light(const Atmosphere& atm);

class SprayHazeOverPass final : public Pass {
 public:
  SprayHazeOverPass(SharedResources& shared, const SprayPass& spray);
  const PassDecl& decl() const override { return decl_; }
  bool wanted(const FrameContext& frame) const override {
    return spray_.wanted(frame) && !spray_.clouds().empty();
  }
  void execute(const FrameContext& frame, const FrameResources& resources) override;

 private:
  const PassDecl decl_{"spray_haze_over",
                       {Resource::kViewDepth, Resource::kSprayHaze},
                       {Resource::kSprayLayer},
                       {DepthTest::kOff, false, Blend::kPremultiplied}};
  const SprayPass& spray_;
  ShaderProgram program_;
  Uniform u_light_, u_near_, u_soft_;
  TileRuns runs_;
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
  TileRuns runs_;
};

}  // namespace downpour::render
