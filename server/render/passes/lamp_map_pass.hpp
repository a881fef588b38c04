// The lamps' light on the ground (lamp_map.hpp) as a frame pass: drawn before the view's passes,
// where the frame has lamps and the view shows the ground (FrameLamps::map).
#pragma once

#include "server/render/frame_lamps.hpp"
#include "server/render/lamp_map.hpp"
#include "server/render/pass.hpp"

namespace downpour::render {

class LampMapPass final : public Pass {
 public:
  explicit LampMapPass(const FrameLamps& lamps) : lamps_(lamps) {}
  const PassDecl& decl() const override { return decl_; }
  bool wanted(const FrameContext&) const override { return lamps_.map(); }
  void execute(const FrameContext&, const FrameResources&) override {
    map_.draw(lamps_.ground_boxes());
  }
  GLuint texture() const { return map_.texture(); }

 private:
  // Each lamp's light added up (premultiplied blending of a colour whose alpha is 0), into the
  // map's own two rings.
  const PassDecl decl_{
      "lamp_map", {}, {Resource::kLampMap}, {DepthTest::kOff, false, Blend::kPremultiplied}};
  const FrameLamps& lamps_;
  LampMap map_;
};

}  // namespace downpour::render
