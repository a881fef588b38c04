#pragma once

#include <atomic>
#include <exception>
#include <memory>
#include <utility>
#include <vector>

#include <glm/vec4.hpp>

#include "server/render/cpu/rain_layer.hpp"
#include "server/render/gl/gl_objects.hpp"
#include "server/render/pass.hpp"

namespace downpour::render {

// Whether a view looks from the driver's seat (COCKPIT and RAIN): through the windshield, over the
// bonnet.
bool is_driver_view(sim::View view);

// What the rain layer needs of a frame: the camera, the light and haze, the exposure, what hides
// the rain (the cars' boxes, kept in `occluders`) and the lamps that light it (the ego car's
// headlights, then the strongest others, kept in `lamps`), which the inputs refer to.
RainLayerInputs rain_layer_inputs(const FrameContext& frame, int layer_height,
                                  std::vector<RainOccluder>& occluders,
                                  std::vector<RainLamp>& lamps);

// Rain in the air (seed 004): the simulation's drops near the car as streaks, their motion relative
// to the camera during the exposure, in the light around them and faded with distance. They are
// drawn on the CPU into a layer of half the view's size (rain_layer.hpp), where the cars hide what
// falls behind them. This pass composites it over the scene: one texture fetch per pixel, over the
// layer's tiles with rain only. In the driver's views the cabin settles which tiles
// (cabin_tiles.hpp): those it hides wholly are left out (a fragment the depth test rejects still
// costs), those it reaches into are drawn at the windshield's depth, so that the depth test leaves
// the cabin dry, and the rest without a depth test (a depth per texel, tested per pixel, took a
// second fetch and a depth written per pixel, and made the 10,000-streak pass about 30% dearer on
// llvmpipe). In COCKPIT it runs before the glass passes, so the water on the glass refracts the
// scene with the rain in it.
class RainPass final : public Pass {
 public:
  explicit RainPass(SharedResources& shared);
  const PassDecl& decl() const override { return decl_; }
  bool wanted(const FrameContext& frame) const override;
  void execute(const FrameContext& frame, const FrameResources& resources) override;
  // Starts building the frame's layer (its CPU work, some milliseconds) on threads of the pass's
  // own, so that it runs while the render thread draws the passes before the rain; execute()
  // takes it. Each view of a tick may have a layer being built at once. Nothing where the frame
  // has no rain. The frame's rain state must outlive the build: a frame that ends before its rain
  // pass (a throw) calls finish_build() (the renderer's view frame does, as it is destroyed).
  void start(const FrameContext& frame);
  // Whether the frame's layer is built (or none was started for it).
  bool built(const FrameContext& frame) const;
  // Waits for a build started for the frame and drops it.
  void finish_build(const FrameContext& frame);

  // The layer's size: the view's over this, each way.
  static constexpr int kLayerDivisor = 2;
  // What the pass drew since the last call, then nothing (a view without rain draws none).
  struct Drawn {
    std::uint32_t streaks = 0;
    double layer_ms = 0.0;  // the CPU layer's share of the pass
  };
  Drawn take_drawn() { return std::exchange(drawn_, Drawn{}); }

 private:
  // The tiles clear of the cabin need no depth test: the rain there lies beyond anything drawn
  // nearer than the glass (on llvmpipe the test costs about a quarter of the composite). Those the
  // cabin reaches into are drawn at the windshield's depth, clamped, so that the test leaves out
  // the cabin.
  enum Step : std::size_t { kClearTiles, kCabinTiles };
  const PassDecl decl_{
      "rain",
      {},
      {Resource::kViewColour, Resource::kViewDepth},
      {DepthTest::kOff, false, Blend::kPremultiplied},
      false,
      {{"clear tiles", {DepthTest::kOff, false, Blend::kPremultiplied}},
       {"cabin tiles", {DepthTest::kNearer, false, Blend::kPremultiplied, true, true}}}};
  SharedResources& shared_;
  ShaderProgram program_;
  Uniform u_plane_depth_;
  // The layer's tiles that the cabin hides, per driver's camera (cabin_tiles.hpp), the latest few.
  struct CabinTiles {
    int width = 0, height = 0;
    glm::dvec3 eye{0.0};
    glm::dmat3 axes{1.0};
    double tan_x = 0.0, tan_y = 0.0;
    sim::GlassConfig glass;  // the built-in cabin is built around it
    sim::ModelPtr cabin;     // or the session's cabin model
    std::vector<std::uint8_t> hidden;
  };
  const std::vector<std::uint8_t>& cabin_tiles_for(const FrameContext& frame, int width,
                                                   int height);
  std::vector<CabinTiles> cabin_tiles_;
  // What a layer size needs: textures and run buffers used in turn, as many as kUploadCopies
  // (gl_objects.hpp) for each of two views of that size in a tick (the demo's). Kept per size for
  // the latest few sizes (kSizesKept), so that sessions whose views differ in size, rendered in
  // turn, re-create nothing.
  static constexpr std::size_t kSizesKept = 4;
  static constexpr int kLayerCopies = 2 * kUploadCopies;
  struct Sized {
    int width = 0, height = 0;
    Texture colour[kLayerCopies];
    Buffer runs_buffer[kLayerCopies];  // the runs of tiles to draw, uv over the view (rain.vert)
    int next = 0;
  };
  Sized& sized(int width, int height);
  std::vector<std::unique_ptr<Sized>> sized_;  // the most recently used last
  std::vector<glm::vec4> runs_uv_;
  VertexArray vao_;  // none of its own attributes: rain.vert reads the runs
  Drawn drawn_;
  // A frame's build (start()): its layer and the thread it is built on (its second half on the
  // layer's own), and what the layer reads, kept until the build is taken. One for each view of a
  // tick whose layer is being built (the demo: two).
  struct Lane {
    const FrameContext* frame = nullptr;  // the frame being built for, or none
    std::uint64_t started = 0;            // when, in builds started (RainPass::starts_)
    const sim::RainState* rain = nullptr;
    RainLayerInputs in;
    std::vector<RainOccluder> occluders;  // the frame's cars, for the layer
    std::vector<RainLamp> lamps;          // and its lamps
    std::vector<std::uint8_t> cabin_tiles;
    std::vector<std::uint16_t> scene_depth_cm;  // over a client's picture, its depth
    std::uint64_t scene_depth_serial = 0;       // of the picture it is (0: the ground's)
    RainLayer layer;
    std::atomic<bool> built{false};
    std::uint32_t streaks = 0;  // the build's, once built
    double ms = 0.0;
    std::exception_ptr failure;  // what it threw
    sim::WorkerThread builder{"dp-rain-build"};
  };
  static constexpr std::size_t kMaxLanes = sim::kViewCount;
  std::vector<std::unique_ptr<Lane>> lanes_;  // made as needed
  std::uint64_t starts_ = 0;                  // builds started
  Lane* lane_of(const FrameContext& frame) const;
};

// RAIN view: the rain layer alone over black. The scene's passes before it leave their depth, so
// that the rain is left off the cabin; this clears their colour.
class RainMaskPass final : public Pass {
 public:
  explicit RainMaskPass(SharedResources&) {}
  const PassDecl& decl() const override { return decl_; }
  void execute(const FrameContext& frame, const FrameResources& resources) override;

 private:
  const PassDecl decl_{"rain_mask", {}, {Resource::kViewColour}, {}};
};

}  // namespace downpour::render
