#pragma once

#include <memory>

#include "server/render/pass.hpp"
#include "server/render/passes/glass_quad.hpp"

namespace downpour::render {

class GlassWaterPass;

// Where the glass layer's optics may meet water, marked in the layer's depth (cleared to the
// nearest): the farthest depth there. For the optics' pair of samples, the pixels where a cell
// under one of the two lists a body (glass_water_mask_pair.frag: the cells the pair's search
// walks, two fetches); for their grids of 4 or 16, the pixels whose footprint touches such a cell
// (glass_water_mask.frag, five). GlassWaterPass, depth-tested nearer,
// then runs only there: llvmpipe skips a block of pixels that all fail the depth test, where it
// cannot skip a branch (on a wiped glass most of the layer is dry). Colour is left alone.
class GlassWaterMaskPass final : public Pass {
 public:
  // `optics`: the pass it masks, which says which samples a layer scale takes.
  GlassWaterMaskPass(SharedResources& shared, const GlassWaterPass& optics);
  const PassDecl& decl() const override { return decl_; }
  bool wanted(const FrameContext& frame) const override;
  void execute(const FrameContext& frame, const FrameResources& resources) override;

 private:
  const PassDecl decl_{"glass_water_mask",
                       {Resource::kGlassSurface},
                       {Resource::kGlassLayer},
                       {DepthTest::kAlways, true, Blend::kOff, false},
                       true};
  struct Mask {
    explicit Mask(const char* fragment_file);
    std::unique_ptr<ShaderProgram> program;  // (where the quad's uniforms point)
    GlassQuad quad;
    GlassSurfaceGrid grid;
  };
  const GlassWaterPass& optics_;
  Mask footprint_, pair_;
};

}  // namespace downpour::render
