#pragma once

#include "server/render/pass.hpp"

namespace downpour::render {

// Sky dome: gradient from horizon to zenith, sun and glow, a cloud layer that thickens and greys
// with cloudiness and rain. Drawn last, at depth 0 (infinitely far), where nothing else is.
class SkyPass final : public Pass {
 public:
  explicit SkyPass(SharedResources& shared);
  const PassDecl& decl() const override { return decl_; }
  void execute(const FrameContext& frame, const FrameResources& resources) override;

 private:
  const PassDecl decl_{"sky",
                       {},
                       {Resource::kViewColour, Resource::kViewDepth},
                       {DepthTest::kNearerOrEqual, false, Blend::kOff}};
  SharedResources& shared_;
  ShaderProgram program_;
};

}  // namespace downpour::render
