// The scene mirrored in the road's plane (Resource::kRoadReflection: a quarter of the view, with
// its depth), for the wet road's film to show. A frame pass: drawn before the view's passes where
// the view's road reads it and the road is wet. It draws the passes it is given from the view's
// camera mirrored in the road's plane under the car (the view's frame block's mirror), each clipped
// to above the plane (gl_ClipDistance[0]) by its own clearance, in its own state.
#pragma once

#include <vector>

#include "server/render/frame_block.hpp"
#include "server/render/pass.hpp"

namespace downpour::render {

class RoadReflectionPass final : public Pass {
 public:
  struct Reflected {
    Pass* pass = nullptr;
    // The clip plane's height over the mirror: vehicles from 2 cm under it (what touches the road
    // stays whole), the ground from well over it (the ground beside the road lies in the plane:
    // mirrored, it would be a floor over everything the mirror shows).
    float clearance_m = 0.0f;
  };
  RoadReflectionPass(FrameBlockBuffer& block, std::vector<Reflected> reflected);
  const PassDecl& decl() const override { return decl_; }
  bool wanted(const FrameContext& frame) const override { return road_reflects(frame); }
  void execute(const FrameContext& frame, const FrameResources& resources) override;

 private:
  PassDecl decl_;  // reads what the reflected passes read
  FrameBlockBuffer& block_;
  std::vector<Reflected> reflected_;
};

}  // namespace downpour::render
