// The render thread's allocations (issue 31's audit), counted through the global operator new on
// every thread (tests/support/allocation_counter.hpp). Once a drive has settled in, drawing a
// tick's views allocates a few dozen times; and after the renderer's warm-up (warm_up.hpp) no
// tick compiles a shader variant, which llvmpipe's LLVM does with tens of thousands of them.
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <tuple>
#include <vector>

#include <gtest/gtest.h>

#include "server/render/warm_up.hpp"
#include "server/sim/scenario.hpp"
#include "server/sim/simulation.hpp"
#include "tests/render/render_fixture.hpp"
#include "tests/support/allocation_counter.hpp"

namespace downpour::testing {
namespace {

// A drive of the heavy-rain scenario under `weather`, behind a truck 22 m ahead if `truck`, on a
// road under `road_water_m`; `draw` draws its views after each tick, counted; returns the most
// allocations of any tick's drawing.
struct Drive {
  sim::Weather weather = sim::highway_heavy_rain().at(0.0).weather.value_or(sim::Weather{});
  bool truck = false;
  double road_water_m = 0.0;
  double seconds = 2.0;
  std::vector<sim::ViewSpec> views;  // none: COCKPIT and ROAD
  sim::ClientImages pictures{};      // the client's pictures in every tick's scene
};

class RenderAllocationsTest : public RenderTest {
 protected:
  // The demo's two views as the session's tick draws them: both begun, then both ended, then
  // their pixels read back (a quarter of the demo's size: the counts do not depend on it).
  struct Tick {
    long allocations = 0;
    double ms = 0.0;
  };
  static std::vector<Tick> drive(const Drive& d, int counted_from_tick) {
    const sim::Scenario scenario = sim::highway_heavy_rain();
    sim::SimulationConfig config;
    config.road.initial_m = d.road_water_m;
    auto update = [&](double t) {
      sim::Update u = d.truck ? sim::behind_truck(scenario, t, 22.0) : scenario.at(t);
      u.weather = d.weather;
      return u;
    };
    sim::Simulation simulation(scenario.seed, update(0.0), config);
    const std::vector<sim::ViewSpec> views =
        !d.views.empty() ? d.views
                         : std::vector<sim::ViewSpec>{view_spec(sim::View::kCockpit, 320, 180),
                                                      view_spec(sim::View::kRoad, 320, 180)};
    std::unique_ptr<render::RenderSession> session = renderer().open_session();
    std::vector<std::uint8_t> pixels;
    render::GroundTruthPixels truth;
    sim::SceneState scene;
    const double dt = 1.0 / scenario.fps;
    std::vector<Tick> ticks;
    const int count = static_cast<int>(d.seconds * scenario.fps);
    for (int i = 0; i < count; ++i) {
      simulation.apply(update((i + 1) * dt));
      simulation.advance(dt);
      scene = simulation.state();
      scene.client_images = d.pictures;
      const auto t0 = std::chrono::steady_clock::now();
      if (i >= counted_from_tick) start_counting_allocations();
      render::draw_tick(renderer(), *session, views, views.size(), scene, pixels, truth);
      if (i < counted_from_tick) continue;
      ticks.push_back({stop_counting_allocations(), std::chrono::duration<double, std::milli>(
                                                        std::chrono::steady_clock::now() - t0)
                                                        .count()});
    }
    return ticks;
  }
};

// After 5 s of the drive, 20 ticks: a few dozen allocations each (the view frames and their
// passes' lists).
TEST_F(RenderAllocationsTest, ASettledDriveAllocatesLittleATick) {
  Drive d;
  d.seconds = 6.0;
  const std::vector<Tick> ticks = drive(d, 150);
  long sum = 0, most = 0;
  for (const Tick& t : ticks) {
    sum += t.allocations;
    most = std::max(most, t.allocations);
  }
  std::printf("%.1f allocations a tick (two views), at most %ld\n",
              static_cast<double>(sum) / ticks.size(), most);
  EXPECT_LT(most, 200);
}

// A renderer of its own (a suite's), so that no other test has had its variants compiled.
class RenderWarmUpTest : public RenderAllocationsTest {};

// With Mesa's shader cache on disk off (the test's ctest entry, render_warm_up, sets
// MESA_SHADER_CACHE_DISABLE, as on a fresh machine or in a new container), the warm-up, then
// sessions that need its variants: heavy rain behind a truck on a flooded road by day (the demo's
// weather), under a low sun in a clear sky, at night, over a client's pictures, and with every
// output. No tick compiles. (The night's drive goes past a session's 43rd tick, the first to draw
// the environment's sky face on its own: after a warm-up without it, it compiled for 130-160 ms.)
TEST_F(RenderWarmUpTest, AfterItNoTickCompilesAShader) {
  const auto w0 = std::chrono::steady_clock::now();
  render::warm_up(renderer());
  std::printf(
      "warm-up: %.0f ms\n",
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - w0).count());
  sim::Weather night = Drive{}.weather, low_sun = Drive{}.weather;
  night.sun_altitude_deg = -20.0;
  low_sun.cloudiness = 0.0;
  low_sun.sun_altitude_deg = 10.0;
  // Over a client's pictures with their depth and the server's haze, each view with its clean
  // frame and water mask; the server's world with every output.
  std::vector<sim::ViewSpec> over, outputs;
  sim::ClientImages pictures{};
  auto picture = std::make_shared<sim::ClientImage>();
  picture->width = 320;
  picture->height = 180;
  picture->bgrx.assign(320 * 180 * 4, 100);
  picture->depth_m.assign(320 * 180, 25.0f);
  picture->serial = 7;
  for (const sim::View v : {sim::View::kCockpit, sim::View::kRoad}) {
    sim::ViewSpec spec = view_spec(v, 320, 180);
    spec.outputs = {true, true, true};
    outputs.push_back(spec);
    spec.background = sim::Background::kClient;
    spec.haze = true;
    spec.outputs.depth = false;
    over.push_back(spec);
    pictures[static_cast<std::size_t>(v)] = picture;
  }
  struct Case {
    const char* name;
    sim::Weather weather;
    double seconds;
    std::vector<sim::ViewSpec> views;
    sim::ClientImages pictures{};
  };
  for (const Case& c :
       {Case{"rain", Drive{}.weather, 2.0, {}}, Case{"low sun", low_sun, 2.0, {}},
        Case{"night", night, 1.5, {}}, Case{"pictures", Drive{}.weather, 1.3, over, pictures},
        Case{"outputs", Drive{}.weather, 1.3, outputs}}) {
    const char* name = c.name;
    Drive d;
    d.weather = c.weather;
    d.truck = true;
    d.road_water_m = 0.003;
    d.seconds = c.seconds;
    d.views = c.views;
    d.pictures = c.pictures;
    int tick = 0;
    for (const Tick& t : drive(d, 0)) {
      if (std::getenv("DOWNPOUR_PRINT_TICKS"))
        std::printf("%s tick %d: %ld allocations, %.1f ms\n", name, tick, t.allocations, t.ms);
      // A compile allocates 60,000 times and more; a tick's drawing some dozens.
      EXPECT_LT(t.allocations, 2000) << name << ", tick " << tick << ": " << t.ms << " ms";
      ++tick;
    }
  }
}

}  // namespace
}  // namespace downpour::testing
