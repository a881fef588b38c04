#pragma once

#include "server/render/pass.hpp"
#include "server/render/passes/glass_quad.hpp"
#include "server/render/passes/wiper_blades.hpp"

namespace downpour::render {

// The WINDSHIELD view: the glass alone in glass space (u across, v up the glass) fitted to the
// view, as ground truth for perception tests. Dry glass is black, water grey by its height over
// the glass (the surface the COCKPIT view traces: brighter where it is thicker), the glass's
// outline faint grey, the wiper blades blue.
class WindshieldPass final : public Pass {
 public:
  explicit WindshieldPass(SharedResources& shared);
  const PassDecl& decl() const override { return decl_; }
  void execute(const FrameContext& frame, const FrameResources& resources) override;

 private:
  const PassDecl decl_{"windshield", {Resource::kGlassSurface}, {Resource::kViewColour}, {}, true};
  SharedResources& shared_;
  ShaderProgram program_;
  WiperBladeUniforms blades_;
  GlassSurfaceGrid grid_;
  Uniform u_aspect_, u_glass_mm_;
};

}  // namespace downpour::render
