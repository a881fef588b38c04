// The passes the renderer owns, and each view as lists of them: data, checked at start-up
// (check_pass_order, check_frame_pass). Nearest first, sky last: llvmpipe tests depth before
// shading, so what is hidden costs little, and the sky shades only the pixels left empty.
#pragma once

#include <array>
#include <memory>
#include <vector>

#include "server/render/cpu/spray_smoothing.hpp"
#include "server/render/frame_block.hpp"
#include "server/render/frame_lamps.hpp"
#include "server/render/pass.hpp"
#include "server/sim/types.hpp"

namespace downpour::render {

class CockpitPass;
class GlassCompositePass;
class LampMapPass;
class RainPass;
class RoadPass;
class RoadReflectionPass;
class SprayPass;
class SprayMirrorPass;
class SpraySmoothPass;

struct ViewPasses {
  std::vector<std::unique_ptr<Pass>> owned;
  // Per view: its frame passes, drawn before the rest where they are wanted (the lamp map, the
  // road reflection), and its passes.
  std::array<std::vector<Pass*>, sim::kViewCount> frame;
  std::array<std::vector<Pass*>, sim::kViewCount> views;
  // What draws the environment probe's faces (the world outside the glass), the sky last; and,
  // with a fixed environment, COCKPIT's passes (the probe as the background, then the glass).
  std::vector<Pass*> environment;
  std::vector<Pass*> fixed_environment_cockpit;
  // Per view, where its background is the client's picture (no frame passes): the picture, then
  // what the server adds over it; and what draws the probe's faces from the picture.
  std::array<std::vector<Pass*>, sim::kViewCount> client_views;
  std::vector<Pass*> client_environment;
  // The passes that add water (the rain, the spray, the glass's water): a view's clean frame
  // (ground truth, sim::Outputs) is its colour before the first of them.
  std::vector<const Pass*> water;
  // Those the renderer asks or tells something of.
  CockpitPass* cockpit = nullptr;
  GlassCompositePass* glass_composite = nullptr;
  LampMapPass* lamp_map = nullptr;
  RoadReflectionPass* reflection = nullptr;
  SprayMirrorPass* spray_mirror = nullptr;
  RoadPass* road = nullptr;
  // The near road at half size and the far road (ROAD, where the renderer asks for them; else
  // null).
  RoadPass* road_layer = nullptr;
  RoadPass* road_far = nullptr;
  RainPass* rain = nullptr;
  SprayPass* spray = nullptr;
  SpraySmoothPass* spray_smooth = nullptr;
};

// Makes every pass and the views' lists; throws std::logic_error where a list breaks the pass
// contract.
// road_at_half: the chase view (ROAD) draws its road into the road's layer at half its size and
// brings that in (RoadPass, RoadCompositePass), where shading costs for every pixel (llvmpipe).
// keep_cabin: the cabin's pictures kept and restored (CockpitPass), likewise.
ViewPasses make_view_passes(SharedResources& shared, FrameBlockBuffer& block,
                            const FrameLamps& lamps, SpraySmoothing smoothing, bool road_at_half,
                            bool keep_cabin);

}  // namespace downpour::render
