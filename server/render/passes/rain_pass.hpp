#pragma once

#include <utility>
#include <vector>

#include "server/render/pass.hpp"
#include "server/render/rain_layer.hpp"

namespace downpour::render {

// Rain in the air (seed 004): the simulation's drops near the car as streaks, their motion relative
// to the camera during the exposure, in the light around them and faded with distance. They are
// drawn on the CPU into a layer of half the view's size (rain_layer.hpp), which this pass
// composites with a depth test: none inside the cabin, none in front of a nearer car. In COCKPIT it
// runs before the glass passes, so the water on the glass refracts the scene with the rain in it.
class RainPass final : public Pass {
 public:
  explicit RainPass(SharedResources& shared);
  const PassDecl& decl() const override { return decl_; }
  bool wanted(const FrameContext& frame) const override;
  void execute(const FrameContext& frame, const FrameResources& resources) override;

  // The layer's size: the view's over this, each way.
  static constexpr int kLayerDivisor = 2;
  // What the pass drew since the last call, then nothing (a view without rain draws none).
  struct Drawn {
    std::uint32_t streaks = 0;
    double layer_ms = 0.0;  // the CPU layer's share of the pass
  };
  Drawn take_drawn() { return std::exchange(drawn_, Drawn{}); }

 private:
  const PassDecl decl_{"rain",
                       {},
                       {Resource::kViewColour, Resource::kViewDepth},
                       {DepthTest::kNearer, false, Blend::kPremultiplied},
                       true};
  SharedResources& shared_;
  ShaderProgram program_;
  Uniform u_near_;
  RainLayer layer_;
  std::vector<RainOccluder> occluders_;  // this frame's cars, for the layer
  // A few pairs of layer textures in turn, so that an upload never waits for the GPU to finish
  // drawing with the pair before.
  static constexpr int kTexturePairs = 3;
  Texture colour_[kTexturePairs], depth_[kTexturePairs];
  int next_pair_ = 0;
  int texture_width_ = 0, texture_height_ = 0;
  Drawn drawn_;
};

// RAIN view: the rain layer alone over black. The scene's passes before it leave their depth, so
// that the rain is hidden where the scene is nearer; this clears their colour.
class RainMaskPass final : public Pass {
 public:
  explicit RainMaskPass(SharedResources&) {}
  const PassDecl& decl() const override { return decl_; }
  void execute(const FrameContext& frame, const FrameResources& resources) override;

 private:
  const PassDecl decl_{"rain_mask", {}, {Resource::kViewColour}, {}};
};

}  // namespace downpour::render
