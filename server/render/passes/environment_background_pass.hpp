#pragma once

#include "server/render/pass.hpp"

namespace downpour::render {

// The world as the session's environment probe holds it, as the view's background: for a probe
// that does not come from the world passes (Renderer::set_fixed_environment), so that what the
// view sees past the water and what the water's rays see are one picture.
class EnvironmentBackgroundPass final : public Pass {
 public:
  explicit EnvironmentBackgroundPass(SharedResources& shared);
  const PassDecl& decl() const override { return decl_; }
  void execute(const FrameContext& frame, const FrameResources& resources) override;

 private:
  const PassDecl decl_{
      "environment_background", {Resource::kEnvironment}, {Resource::kViewColour}, {}};
  SharedResources& shared_;
  ShaderProgram program_;
  Uniform u_env_from_world_;
};

}  // namespace downpour::render
