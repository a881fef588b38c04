// The spray's clouds in the road's mirror (road_reflection_pass.hpp draws it among the scene's
// passes, from the view's camera mirrored in the road's plane): the parcels' haze, drawn by the CPU
// (cpu/spray_splat.hpp) at half the mirror's size from the mirrored camera, then over the mirror
// lit as the view's haze is (spray_haze_composite.frag), each pixel at its clouds' mean distance
// so that what the mirror shows nearer hides it. The liquid's spheres are left out: at a quarter
// of the view's size and under the water's Fresnel they would not show. Not where the view's clean
// frame is asked for (it is taken after the road, which shows the mirror).
#pragma once

#include <vector>

#include <glm/vec2.hpp>

#include "server/render/cpu/spray_splat.hpp"
#include "server/render/gl/gl_objects.hpp"
#include "server/render/pass.hpp"

namespace downpour::render {

class SprayMirrorPass final : public Pass {
 public:
  explicit SprayMirrorPass(SharedResources& shared);
  const PassDecl& decl() const override { return decl_; }
  bool wanted(const FrameContext& frame) const override;
  void execute(const FrameContext& frame, const FrameResources& resources) override;
  void set_on(bool on) { on_ = on; }  // (tests and benchmarks: without it)

 private:
  // Over the mirror where the clouds lie nearer than what it holds (reversed-Z: greater).
  const PassDecl decl_{"spray_mirror",
                       {},
                       {Resource::kRoadReflection},
                       {DepthTest::kNearer, false, Blend::kPremultiplied}};
  ShaderProgram program_;
  Uniform u_light_, u_near_;
  VertexArray vao_;
  Texture haze_;
  int width_ = 0, height_ = 0;
  bool on_ = true;
  std::vector<SprayHazeBall> clouds_;
  std::vector<glm::vec2> pixels_;
};

}  // namespace downpour::render
