#include "server/render/view_passes.hpp"

#include <string>
#include <utility>

#include "server/render/passes/client_background_pass.hpp"
#include "server/render/passes/cockpit_pass.hpp"
#include "server/render/passes/environment_background_pass.hpp"
#include "server/render/passes/glass_composite_pass.hpp"
#include "server/render/passes/glass_water_mask_pass.hpp"
#include "server/render/passes/glass_water_pass.hpp"
#include "server/render/passes/lamp_glow_pass.hpp"
#include "server/render/passes/lamp_map_pass.hpp"
#include "server/render/passes/rain_pass.hpp"
#include "server/render/passes/road_pass.hpp"
#include "server/render/passes/road_reflection_pass.hpp"
#include "server/render/passes/sky_pass.hpp"
#include "server/render/passes/spray_mirror_pass.hpp"
#include "server/render/passes/spray_pass.hpp"
#include "server/render/passes/street_light_pass.hpp"
#include "server/render/passes/terrain_pass.hpp"
#include "server/render/passes/vehicle_pass.hpp"
#include "server/render/passes/windshield_pass.hpp"

namespace downpour::render {

ViewPasses make_view_passes(SharedResources& shared, FrameBlockBuffer& block,
                            const FrameLamps& lamps, SpraySmoothing smoothing, bool road_at_half,
                            bool keep_cabin) {
  ViewPasses p;
  auto own = [&p](auto pass) {
    auto* raw = pass.get();
    p.owned.push_back(std::move(pass));
    return raw;
  };
  p.cockpit = own(std::make_unique<CockpitPass>(shared, keep_cabin));
  Pass* cockpit = p.cockpit;
  Pass* vehicles = own(std::make_unique<VehiclePass>(shared));
  Pass* street_lights = own(std::make_unique<StreetLightPass>(shared));
  p.road = own(std::make_unique<RoadPass>(shared));
  Pass* road = p.road;
  // (Made only where drawn: each is twelve programs to compile.)
  std::vector<Pass*> chase_road = {road};
  if (road_at_half) {
    p.road_layer = own(std::make_unique<RoadPass>(shared, RoadPart::kNearInLayer));
    p.road_far = own(std::make_unique<RoadPass>(shared, RoadPart::kFar));
    chase_road = {p.road_layer, own(std::make_unique<RoadCompositePass>()), p.road_far};
  }
  Pass* terrain = own(std::make_unique<TerrainPass>(shared));
  Pass* sky = own(std::make_unique<SkyPass>(shared));
  Pass* glow = own(std::make_unique<LampGlowPass>(shared));
  p.rain = own(std::make_unique<RainPass>(shared));
  Pass* rain = p.rain;
  Pass* rain_mask = own(std::make_unique<RainMaskPass>(shared));
  Pass* environment_background = own(std::make_unique<EnvironmentBackgroundPass>(shared));
  GlassWaterPass* glass_water = own(std::make_unique<GlassWaterPass>(shared));
  Pass* glass_water_mask = own(std::make_unique<GlassWaterMaskPass>(shared, *glass_water));
  p.glass_composite = own(std::make_unique<GlassCompositePass>(shared));
  Pass* glass_composite = p.glass_composite;
  Pass* windshield = own(std::make_unique<WindshieldPass>(shared));
  // The spray's chain: maps, smoothing, shading, haze, haze over, composite (spray_pass.hpp).
  p.spray = own(std::make_unique<SprayPass>(shared));
  p.spray_smooth = own(std::make_unique<SpraySmoothPass>(shared, *p.spray));
  p.spray_smooth->set_smoothing(smoothing);
  const std::vector<Pass*> spray = {p.spray,
                                    p.spray_smooth,
                                    own(std::make_unique<SprayShadePass>(shared, *p.spray)),
                                    own(std::make_unique<SprayHazePass>(shared, *p.spray)),
                                    own(std::make_unique<SprayHazeOverPass>(shared, *p.spray)),
                                    own(std::make_unique<SprayCompositePass>(shared, *p.spray))};
  p.water = {rain, spray.front(), glass_water_mask, glass_water, glass_composite};
  p.lamp_map = own(std::make_unique<LampMapPass>(lamps));
  p.spray_mirror = own(std::make_unique<SprayMirrorPass>(shared));
  // What the road's mirror shows, each clipped this far above the road's plane.
  p.reflection = own(std::make_unique<RoadReflectionPass>(
      block, std::vector<RoadReflectionPass::Reflected>{{vehicles, -0.02f},
                                                        {street_lights, 0.0f},
                                                        {terrain, 0.5f},
                                                        {sky, 0.0f},
                                                        {p.spray_mirror, 0.0f}}));

  auto& views = p.views;
  auto& frame = p.frame;
  const auto cockpit_view = static_cast<int>(sim::View::kCockpit);
  const auto road_view = static_cast<int>(sim::View::kRoad);
  auto then = [](std::vector<Pass*> a, const std::vector<Pass*>& b) {
    a.insert(a.end(), b.begin(), b.end());
    return a;
  };
  frame[cockpit_view] = {p.lamp_map, p.reflection};
  views[cockpit_view] =
      then(then({cockpit, vehicles, street_lights, road, terrain, sky, glow, rain}, spray),
           {glass_water_mask, glass_water, glass_composite});
  frame[road_view] = {p.lamp_map, p.reflection};
  views[road_view] =
      then(then(then({vehicles, street_lights}, chase_road), {terrain, sky, glow, rain}), spray);
  views[static_cast<int>(sim::View::kWindshield)] = {windshield};
  // The rain layer alone from the driver's eye: the scene for its depth alone (no lamp map, no
  // mirror), then black, then rain and spray.
  views[static_cast<int>(sim::View::kRain)] =
      then({cockpit, vehicles, street_lights, road, terrain, rain_mask, rain}, spray);
  // Over a client's picture: the rain, the spray and the glass; the picture holds the world, and in
  // COCKPIT the cabin.
  Pass* picture = own(std::make_unique<ClientBackgroundPass>(shared));
  Pass* haze = own(std::make_unique<ClientHazePass>(shared));
  auto& client = p.client_views;
  client[cockpit_view] =
      then(then({picture, haze, rain}, spray), {glass_water_mask, glass_water, glass_composite});
  client[road_view] = then({picture, haze, rain}, spray);
  client[static_cast<int>(sim::View::kWindshield)] = {picture, haze, glass_water_mask, glass_water,
                                                      glass_composite};
  p.client_environment = {own(std::make_unique<ClientEnvironmentPass>(shared))};
  p.environment = {vehicles, street_lights, road, terrain, sky};
  p.fixed_environment_cockpit = {environment_background, glass_water_mask, glass_water,
                                 glass_composite};

  check_pass_order("COCKPIT (fixed environment)", p.fixed_environment_cockpit);
  check_pass_order("environment faces", p.environment);
  check_pass_order("environment faces from a client's picture", p.client_environment);
  for (int v = 0; v < sim::kViewCount; ++v) {
    if (!client[v].empty())
      check_pass_order(std::string(sim::view_name(static_cast<sim::View>(v))) + " (client's)",
                       client[v]);
  }
  for (int v = 0; v < sim::kViewCount; ++v) {
    check_pass_order(sim::view_name(static_cast<sim::View>(v)), views[v]);
    for (const Pass* pass : frame[v]) check_frame_pass(*pass);
  }
  return p;
}

}  // namespace downpour::render
