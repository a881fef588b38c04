// The relief shadows' benchmark (seed 002; README, Frame budget), as JSON: the built-in highway,
// dry, under a clear sky and a low sun (8 degrees, where the shadows are long), its COCKPIT and
// ROAD views at 640 x 360 drawn --frames times each with the shadows on and off in turn, in one
// renderer:
// - the road pass with and without them, each finished (profiling on), medians;
// - their share of whole frames (no finish between passes, as the server renders): the frame with
//   them less the frame without, frame by frame, median;
// - the horizon maps' build at start-up (both reliefs, all azimuths).
// Usage: downpour-relief-bench [--frames N] [--sun-altitude DEG] [--sun-azimuth DEG]
#include <chrono>
#include <cstdio>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include "bench/stats.hpp"
#include "server/render/cpu/relief.hpp"
#include "server/render/renderer.hpp"
#include "server/sim/scenario.hpp"

using json = nlohmann::json;
using namespace downpour;

int main(int argc, char** argv) {
  CLI::App app{"The relief shadows' benchmark: their cost at 640x360, as JSON"};
  int frames = 20;
  double altitude = 8.0, azimuth = 200.0;
  app.add_option("--frames", frames, "frames measured per view, with and without")
      ->check(CLI::Range(1, 1000));
  app.add_option("--sun-altitude", altitude, "degrees")->check(CLI::Range(0.5, 90.0));
  app.add_option("--sun-azimuth", azimuth, "degrees, world yaw")->check(CLI::Range(-360.0, 360.0));
  CLI11_PARSE(app, argc, argv);

  const sim::Scenario scenario = sim::highway_heavy_rain();
  sim::Update update = scenario.at(10.0);
  update.weather->rain_rate_mm_h = 0.0;
  update.weather->fog_density = 0.0;
  update.weather->cloudiness = 0.0;
  update.weather->sun_altitude_deg = altitude;
  update.weather->sun_azimuth_deg = azimuth;
  sim::Simulation simulation(scenario.seed, update);
  simulation.advance(1.0);
  const sim::SceneState scene = simulation.state();

  json out;
  const auto t0 = std::chrono::steady_clock::now();
  const auto reliefs = render::relief::road_reliefs(32);
  out["horizon_maps"] = {
      {"directions", 32},
      {"texels", reliefs->asphalt_horizon.size},
      {"build_ms",
       std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count()}};
  auto renderer = render::Renderer::create({});
  out["renderer"] = renderer->gl_renderer();
  auto session = renderer->open_session();
  std::vector<std::uint8_t> pixels;
  constexpr int kWarmUp = 2;
  for (const sim::View view : {sim::View::kCockpit, sim::View::kRoad}) {
    const sim::ViewSpec spec = sim::view_spec(view, 640, 360);
    json row = {{"view", std::string(sim::view_name(view))}, {"size", "640x360"}};
    // On and off in turn, frame by frame, so that a machine whose speed drifts affects both alike.
    std::map<bool, std::vector<double>> road_ms;
    renderer->set_profiling(true);
    for (int i = 0; i < frames + kWarmUp; ++i) {
      for (const bool on : {true, false}) {
        renderer->set_relief_shadows(on);
        renderer->finish(renderer->render(*session, 0, spec, scene), pixels);
        if (on) row["drawn"] = renderer->last_drew_relief();
        if (i < kWarmUp) continue;
        double sum = 0.0;
        for (const auto& p : renderer->last_pass_timings()) {
          for (std::string_view road : render::kRoadPassNames) {
            if (p.name == road) sum += p.ms;
          }
        }
        road_ms[on].push_back(sum);
      }
    }
    row["road_pass_ms"] = {{"with", bench::median(road_ms[true])},
                           {"without", bench::median(road_ms[false])}};
    renderer->set_profiling(false);
    const auto frame = [&](bool on) {
      renderer->set_relief_shadows(on);
      renderer->finish(renderer->render(*session, 0, spec, scene), pixels);
    };
    const bench::Added added = bench::added_to_frames(
        frames, kWarmUp, [&] { frame(true); }, [&] { frame(false); });
    row["frame_ms"] = added.frame_ms;
    row["relief_in_frame_ms"] = added.added_ms;
    row["ceiling_ms"] = 1.5;
    out["views"].push_back(row);
    std::fprintf(stderr, "%s done\n", std::string(sim::view_name(view)).c_str());
  }
  std::printf("%s\n", out.dump(2).c_str());
  return 0;
}
