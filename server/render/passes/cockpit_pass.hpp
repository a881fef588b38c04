#pragma once

#include "server/render/model_meshes.hpp"
#include "server/render/pass.hpp"

namespace downpour::render {

// The cabin around the driver's eye: dashboard edge, A-pillars, roof liner and mirror, dark
// silhouettes framing the view through the windshield, built around the glass of the scene; or
// the cabin model the session names.
class CockpitPass final : public Pass {
 public:
  explicit CockpitPass(SharedResources& shared);
  const PassDecl& decl() const override { return decl_; }
  void execute(const FrameContext& frame, const FrameResources& resources) override;

 private:
  const PassDecl decl_{"cockpit",
                       {},
                       {Resource::kViewColour, Resource::kViewDepth},
                       {DepthTest::kNearer, true, Blend::kOff}};
  ShaderProgram program_;
  ModelUniforms uniforms_;
  sim::GlassConfig built_for_;
  ModelMesh interior_;  // the built-in cabin round the glass
  ModelMeshes named_;   // the cabin models sessions name
};

}  // namespace downpour::render
