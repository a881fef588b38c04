#pragma once

#include "server/render/pass.hpp"

namespace downpour::render {

// A view whose background is the client's (sim::Background::kClient): its latest picture copied
// into the view's colour, and its depth (the view's reversed-Z) into the view's depth, so that the
// passes after it (the spray, the glass) are hidden by what the picture shows nearer. A copy, not a
// draw: on llvmpipe a pass over every pixel at 1280 x 720 costs some 6 ms, the copy well under
// one. Without a depth the view's stays at the far plane; the rain's CPU layer takes the ground
// under the car instead (rain_pass.cpp).
class ClientBackgroundPass final : public Pass {
 public:
  explicit ClientBackgroundPass(SharedResources&) {}
  const PassDecl& decl() const override { return decl_; }
  void execute(const FrameContext& frame, const FrameResources& resources) override;

 private:
  const PassDecl decl_{"client_background",
                       {Resource::kClientImage},
                       {Resource::kViewColour, Resource::kViewDepth},
                       {}};
};

// The server's haze over a client's picture (ViewSpec::haze): each pixel's light scattered in and
// lost on its way, by its distance in the picture's depth, or without one by the ground under the
// car; the picture's sky is left as it is. A pass over every pixel, so off unless a view asks.
class ClientHazePass final : public Pass {
 public:
  explicit ClientHazePass(SharedResources& shared);
  const PassDecl& decl() const override { return decl_; }
  bool wanted(const FrameContext& frame) const override;
  void execute(const FrameContext& frame, const FrameResources& resources) override;

 private:
  const PassDecl decl_{"client_haze",
                       {Resource::kClientImage},
                       {Resource::kViewColour},
                       {DepthTest::kOff, false, Blend::kOff}};
  SharedResources& shared_;
  ShaderProgram program_;
  Uniform u_forward_, u_ground_, u_has_depth_, u_near_;
};

// An environment probe's face (environment_probe.hpp) from a client-background view's picture:
// each direction where the picture shows it, the picture's edges extended beyond it (a lens on
// the glass turns rays to where the camera does not look); the sky where its depth says so, or
// above the ground's horizon without one (the probe adds the sun there). Where the picture's depth
// shows its own cabin (nearer than the windshield's plane), the world outside nearest to it
// towards the picture's centre stands in: a drop looks out, not back into the car.
class ClientEnvironmentPass final : public Pass {
 public:
  explicit ClientEnvironmentPass(SharedResources& shared);
  const PassDecl& decl() const override { return decl_; }
  void execute(const FrameContext& frame, const FrameResources& resources) override;

 private:
  const PassDecl decl_{"client_environment",
                       {Resource::kClientImage},
                       {Resource::kViewColour, Resource::kViewDepth},
                       {DepthTest::kAlways, true, Blend::kOff}};
  SharedResources& shared_;
  ShaderProgram program_;
  Uniform u_forward_, u_right_, u_up_, u_tan_, u_ground_, u_has_depth_, u_glass_depth_, u_near_;
};

}  // namespace downpour::render
