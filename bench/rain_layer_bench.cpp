// The rain layer alone (rain_layer.hpp): the CPU's streaks for the COCKPIT view (or ROAD's chase
// camera) of the standard scene, without GL, so that its cost can be measured quietly and compared
// change by change.
//   downpour-rain-layer-bench [--counts N ...] [--frames F] [--size WxH] [--no-splashes]
//                             [--warm-seconds S] [--view cockpit|road]
// For each rain_streak_count, the scene's drive is warmed for S s (2 by default) and the layer is
// built for F frames (the simulation stepping between them); prints one JSON line per count: the
// streaks drawn and the splashes alive (medians), and the layer's median and 90th-percentile
// milliseconds.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <vector>

#include <CLI/CLI.hpp>

#include "bench/stats.hpp"
#include "server/model/default_models.hpp"
#include "server/render/cpu/atmosphere.hpp"
#include "server/render/cpu/cabin_tiles.hpp"
#include "server/render/cpu/camera.hpp"
#include "server/render/passes/rain_pass.hpp"
#include "server/sim/pose.hpp"
#include "server/sim/scenario.hpp"
#include "server/sim/simulation.hpp"

using namespace downpour;

using bench::percentile;

int main(int argc, char** argv) {
  // The counts that drew about 10,000 and 80,000 streaks from the driver's eye (downpour-bench's
  // probe found them: about 1.6 streaks per drop) before the far streaks were thinned; about 7,300
  // and 58,000 since (RainLayerInputs::far_share). Kept, so that figures compare across changes.
  std::vector<std::uint32_t> counts{6161, 49103};
  int frames = 60;
  std::string size = "640x360";
  bool splashes_too = true;
  double warm_s = 2.0;
  std::string view_name = "cockpit";
  CLI::App app{"Downpour rain layer benchmark: the CPU streaks of one view, as JSON lines"};
  app.add_option("--counts", counts, "rain_streak_count values");
  app.add_option("--frames", frames)->check(CLI::Range(5, 100000));
  app.add_option("--size", size, "the view's WIDTHxHEIGHT");
  app.add_flag("!--no-splashes", splashes_too, "the streaks alone");
  app.add_option("--warm-seconds", warm_s, "the scene's drive before measuring")
      ->check(CLI::Range(0.0, 600.0));
  app.add_option("--view", view_name, "the view: cockpit, or road (the chase camera)")
      ->check(CLI::IsMember({"cockpit", "road"}));
  CLI11_PARSE(app, argc, argv);
  const sim::View view = view_name == "road" ? sim::View::kRoad : sim::View::kCockpit;
  int width = 0, height = 0;
  if (std::sscanf(size.c_str(), "%dx%d", &width, &height) != 2 || width < 16 || height < 16) {
    std::fprintf(stderr, "--size: WIDTHxHEIGHT\n");
    return 2;
  }
  const sim::ViewSpec spec = sim::view_spec(view, width, height);
  const int layer_w =
      (width + render::RainPass::kLayerDivisor - 1) / render::RainPass::kLayerDivisor;
  const int layer_h =
      (height + render::RainPass::kLayerDivisor - 1) / render::RainPass::kLayerDivisor;
  for (const std::uint32_t count : counts) {
    sim::Scenario scenario = sim::highway_heavy_rain();
    for (sim::Keyframe& k : scenario.keyframes) {
      if (k.weather) k.weather->rain_streak_count = count;
    }
    sim::SimulationConfig config;
    config.simulate_water = false;  // the glass is not this layer's
    sim::Simulation simulation(scenario.seed, scenario.at(0.0), config);
    const double dt = 1.0 / scenario.fps;
    auto step = [&] {
      simulation.apply(scenario.at(simulation.state().sim_time_s + dt));
      simulation.advance(dt);
    };
    for (double t = 0.0; t < warm_s; t += dt) step();
    render::RainLayer layer;
    std::vector<render::RainOccluder> occluders;
    std::vector<render::RainLamp> lamps;
    std::vector<std::uint8_t> cabin;
    std::vector<double> ms, streaks, splashes;
    for (int i = 0; i < frames + 3; ++i) {
      step();
      sim::SceneState state = simulation.state();
      if (!splashes_too) state.rain.splashes.clear();
      const render::Camera camera = render::make_camera(spec, state.vehicle);
      const render::FrameContext frame{state,
                                       spec,
                                       camera,
                                       render::atmosphere_from(state.weather),
                                       glm::mat4(sim::vehicle_to_world(state.vehicle)),
                                       render::GlassView(camera, state.glass, spec.height),
                                       [&]() -> const sim::SceneState& { return state; }};
      render::RainLayerInputs in = render::rain_layer_inputs(frame, layer_h, occluders, lamps);
      // The cabin's tiles, as the pass has them (made once per camera there).
      if (view == sim::View::kCockpit && cabin.empty()) {
        cabin = render::cabin_tiles(model::default_cabin(state.glass).mesh, camera, layer_w,
                                    layer_h, render::RainLayer::kTile);
      }
      in.cabin_tiles = cabin;
      const auto t0 = std::chrono::steady_clock::now();
      const std::uint32_t drawn = layer.build(state.rain, in, layer_w, layer_h);
      const auto t1 = std::chrono::steady_clock::now();
      if (i < 3) continue;  // first touches of the layer's memory
      ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
      streaks.push_back(drawn);
      splashes.push_back(static_cast<double>(state.rain.splashes.size()));
    }
    std::printf(
        "{\"view\": \"%s\", \"rain_streak_count\": %u, \"size\": \"%dx%d\", \"streaks_drawn\": "
        "%.0f, "
        "\"splashes\": %.0f, \"layer_ms\": %.3f, \"layer_ms_p90\": %.3f}\n",
        view_name.c_str(), count, width, height, percentile(streaks, 0.5),
        percentile(splashes, 0.5), percentile(ms, 0.5), percentile(ms, 0.9));
  }
  return 0;
}
