// The lights' benchmark (issue: light and relief; README, Frame budget), as JSON: the built-in
// highway at night under a clear sky, the ego car on low beam, 10 cars in view (5 ahead in its
// direction, 5 oncoming, on low beam, one braking, one indicating) and the 20 nearest street
// lights lit, dry and in 10 mm/h of rain; its COCKPIT and ROAD views at 640 x 360 drawn --frames
// times each with the lamps on and off in turn, in one renderer:
// - the frame's lamps in whole frames (no finish between passes, as the server renders): the frame
//   with them less the frame without, frame by frame, median;
// - each pass's median with and without (profiling on: finished after each), for where it goes.
// Usage: downpour-lights-bench [--frames N]
#include <chrono>
#include <cstdio>
#include <map>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <glm/trigonometric.hpp>
#include <nlohmann/json.hpp>

#include "bench/stats.hpp"
#include "server/render/renderer.hpp"
#include "server/sim/scenario.hpp"
#include "server/sim/track.hpp"

using json = nlohmann::json;
using namespace downpour;

namespace {

// The benchmark's traffic: cars ahead of the ego car at `s` (m along the track), in its lanes and
// in the oncoming ones.
void add_traffic(sim::SceneState& scene, double s) {
  const sim::Track track = sim::Track::built_in();
  struct Car {
    double ahead_m;
    int lane;  // negative: the oncoming carriageway's lane -lane - 1
    sim::VehicleLights lights;
  };
  sim::VehicleLights low;
  low.headlights = sim::Headlights::kLow;
  sim::VehicleLights braking = low, indicating = low;
  braking.brake = true;
  indicating.left_indicator = true;
  const Car cars[] = {{16, 0, braking}, {32, 1, low},  {48, 0, low},  {70, 1, indicating},
                      {95, 0, low},     {22, -1, low}, {45, -2, low}, {66, -1, low},
                      {90, -2, low},    {120, -1, low}};
  std::uint32_t id = 100;
  for (const Car& c : cars) {
    const double at = s + c.ahead_m;
    const sim::TrackFrame f = track.at(at);
    const bool oncoming = c.lane < 0;
    const double lateral = oncoming ? -track.lane_centre(-c.lane - 1) : track.lane_centre(c.lane);
    sim::TrafficVehicle v;
    v.id = id++;
    const glm::dvec2 xy = glm::dvec2(f.position) + f.left * lateral;
    v.state.position_m = glm::dvec3(xy, track.surface_height(at, lateral));
    v.state.rotation.yaw_deg = glm::degrees(f.heading_rad) + (oncoming ? 180.0 : 0.0);
    v.size_m = {4.6, 1.8, 1.47};
    scene.traffic.push_back(v);
    scene.traffic_lights.push_back(c.lights);
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"The lights' benchmark: their cost at 640x360, as JSON"};
  int frames = 20;
  app.add_option("--frames", frames, "frames measured per view, with and without")
      ->check(CLI::Range(1, 1000));
  CLI11_PARSE(app, argc, argv);

  json out;
  auto renderer = render::Renderer::create({});
  out["renderer"] = renderer->gl_renderer();
  auto session = renderer->open_session();
  std::vector<std::uint8_t> pixels;
  constexpr int kWarmUp = 2;
  for (const double rain : {0.0, 10.0}) {
    const sim::Scenario scenario = sim::highway_heavy_rain();
    sim::Update update = scenario.at(10.0);
    update.weather->rain_rate_mm_h = rain;
    update.weather->fog_density = 0.0;
    update.weather->cloudiness = 0.0;
    update.weather->sun_altitude_deg = -20.0;
    sim::Simulation simulation(scenario.seed, update);
    simulation.advance(1.0);
    sim::SceneState scene = simulation.state();
    scene.traffic.clear();
    scene.traffic_lights.clear();
    const sim::Track track = sim::Track::built_in();
    add_traffic(scene, track.project(glm::dvec2(scene.vehicle.position_m), 50.0).s);
    // The process's first seconds of frames run slower, and unevenly between frames with the
    // lamps and without (the first scene measured, whichever it was, read 1-6 ms from run to
    // run; the same scene measured second, steadily 1.2): ten seconds of both views first.
    if (rain == 0.0) {
      const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(10);
      for (bool on = true; std::chrono::steady_clock::now() < until; on = !on) {
        renderer->set_lamps(on);
        for (const sim::View view : {sim::View::kCockpit, sim::View::kRoad}) {
          renderer->finish(renderer->render(*session, 0, sim::view_spec(view, 640, 360), scene),
                           pixels);
        }
      }
    }
    for (const sim::View view : {sim::View::kCockpit, sim::View::kRoad}) {
      const sim::ViewSpec spec = sim::view_spec(view, 640, 360);
      json row = {
          {"view", std::string(sim::view_name(view))}, {"size", "640x360"}, {"rain_mm_h", rain}};
      std::map<std::string, std::map<bool, std::vector<double>>> pass_ms;
      renderer->set_profiling(true);
      for (int i = 0; i < frames + kWarmUp; ++i) {
        for (const bool on : {true, false}) {
          renderer->set_lamps(on);
          renderer->finish(renderer->render(*session, 0, spec, scene), pixels);
          if (i < kWarmUp) continue;
          for (const auto& p : renderer->last_pass_timings()) pass_ms[p.name][on].push_back(p.ms);
        }
      }
      for (auto& [name, ms] : pass_ms) {
        row["pass_ms"][name] = {{"with", bench::median(ms[true])},
                                {"without", bench::median(ms[false])}};
      }
      renderer->set_profiling(false);
      const auto frame = [&](bool on) {
        renderer->set_lamps(on);
        renderer->finish(renderer->render(*session, 0, spec, scene), pixels);
      };
      const bench::Added added = bench::added_to_frames(
          frames, 3 * kWarmUp, [&] { frame(true); }, [&] { frame(false); });
      row["frame_ms"] = added.frame_ms;
      row["lights_in_frame_ms"] = added.added_ms;
      row["ceiling_ms"] = 3.0;
      out["views"].push_back(row);
      std::fprintf(stderr, "%s rain %.0f done\n", std::string(sim::view_name(view)).c_str(), rain);
    }
  }
  std::printf("%s\n", out.dump(2).c_str());
  return 0;
}
