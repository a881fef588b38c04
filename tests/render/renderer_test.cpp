// Render tests on llvmpipe: each view against a golden PNG, and properties a golden file cannot
// fake. Set DOWNPOUR_UPDATE_GOLDEN=1 to rewrite the golden files after a deliberate change (then
// look at them).
#include <algorithm>
#include <array>
#include <cstdint>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "server/render/environment_probe.hpp"
#include "server/render/renderer.hpp"
#include "server/sim/scenario.hpp"
#include "server/sim/simulation.hpp"
#include "tests/render/render_fixture.hpp"
#include "tests/render/windshield_fixture.hpp"
#include "tests/support/png_io.hpp"

namespace downpour::render {
namespace {

using testing::RgbaImage;

constexpr int kWidth = 256;
constexpr int kHeight = 144;

class RendererTest : public testing::RenderTest {
 protected:
  // The highway scene 10 s in: on the straight, heavy rain; the windshield as the simulation
  // left it.
  static sim::SceneState highway_scene(double rain_mm_h = 25.0, double cloudiness = 0.95) {
    return testing::highway_scene(rain_mm_h, cloudiness);
  }
  // The same with a dry windshield and no blades on it (the water not simulated).
  static sim::SceneState dry_highway_scene(double rain_mm_h = 25.0, double cloudiness = 0.95) {
    sim::SceneState scene = testing::highway_scene(rain_mm_h, cloudiness, false);
    scene.windshield = sim::WindshieldState{};
    return scene;
  }

  static RgbaImage render(sim::View view, const sim::SceneState& scene) {
    return RenderTest::render(view_spec(view, kWidth, kHeight), scene);
  }
};

class GoldenTest : public RendererTest, public ::testing::WithParamInterface<sim::View> {};

TEST_P(GoldenTest, MatchesGoldenImage) {
  const sim::View view = GetParam();
  // A hand-made windshield, so that the pictures do not move with the water simulation.
  sim::SceneState scene = highway_scene();
  scene.windshield = testing::golden_windshield(scene.glass);
  expect_golden(render(view, scene), std::string(sim::view_name(view)) + ".png");
}

INSTANTIATE_TEST_SUITE_P(Views, GoldenTest,
                         ::testing::Values(sim::View::kCockpit, sim::View::kRoad,
                                           sim::View::kWindshield, sim::View::kRain),
                         [](const auto& info) { return std::string(sim::view_name(info.param)); });

TEST_F(RendererTest, SkyDarkensAsTheRainRateRises) {
  double previous = 1e9;
  for (double rain : {0.0, 2.0, 10.0, 50.0, 200.0}) {
    const RgbaImage image = render(sim::View::kRoad, dry_highway_scene(rain, 0.3));
    // The top fifth of the chase view is sky.
    const double sky = testing::mean_luma(image, 0, 0, kWidth, kHeight / 5);
    EXPECT_LT(sky, previous) << "rain " << rain << " mm/h";
    previous = sky;
  }
}

TEST_F(RendererTest, WetAsphaltIsDarkerThanDry) {
  // The road just ahead of the car in the chase view, between the lane lines, below the car.
  const auto road = [&](double rain) {
    const RgbaImage image = render(sim::View::kRoad, dry_highway_scene(rain, 0.6));
    return testing::mean_luma(image, kWidth / 8, kHeight * 7 / 8, kWidth / 3, kHeight);
  };
  EXPECT_LT(road(25.0), road(0.0) * 0.9);
}

TEST_F(RendererTest, CockpitShowsTheDashboardBelowTheGlass) {
  const RgbaImage image = render(sim::View::kCockpit, dry_highway_scene(0.0, 0.2));
  const double dashboard =
      testing::mean_luma(image, kWidth / 3, kHeight * 9 / 10, kWidth * 2 / 3, kHeight);
  const double through_glass =
      testing::mean_luma(image, kWidth / 3, kHeight / 4, kWidth * 2 / 3, kHeight / 2);
  EXPECT_LT(dashboard, through_glass * 0.5);
}

TEST_F(RendererTest, DryWindshieldViewIsTheOutlineOnBlack) {
  const RgbaImage image = render(sim::View::kWindshield, dry_highway_scene());
  int lit = 0;
  for (std::size_t i = 0; i < image.pixels.size(); i += 4) lit += image.pixels[i] > 10;
  const int total = kWidth * kHeight;
  EXPECT_GT(lit, total / 200);  // the outline is there
  EXPECT_LT(lit, total / 10);   // and nothing else: no water on dry glass
}

// A tick's views begun together and then ended (as the scheduler draws them, so that they
// overlap) give the pixels that rendering them one at a time gives, by day and at night (where
// each view's lamps, and the lamp map under the glass's environment, are its own again), whether
// a view's rain pass came in begin() or was left to end().
TEST_F(RendererTest, ViewsBegunTogetherDrawAsOneAtATime) {
  sim::SceneState day = highway_scene();
  sim::SceneState night = day;
  night.weather.sun_altitude_deg = -20.0;
  night.weather.cloudiness = 0.0;
  night.weather.fog_density = 0.0;
  night.ego_lights.headlights = sim::Headlights::kLow;
  // Three, each with rain: each view's rain layer is built in a lane of its own.
  const std::array<sim::ViewSpec, 3> specs = {view_spec(sim::View::kCockpit, kWidth, kHeight),
                                              view_spec(sim::View::kRoad, kWidth, kHeight),
                                              view_spec(sim::View::kRain, kWidth, kHeight)};
  for (const sim::SceneState* scene : {&day, &night}) {
    const StepSource stepped = [scene]() -> const sim::SceneState& { return *scene; };
    auto pixels = [&](const PendingReadback& pending) {
      std::vector<std::uint8_t> out;
      renderer().finish(pending, out);
      return out;
    };
    const std::unique_ptr<RenderSession> alone = renderer().open_session();
    std::array<std::vector<std::uint8_t>, 3> one_at_a_time;
    for (int v = 0; v < 3; ++v)
      one_at_a_time[v] = pixels(renderer().render(*alone, v, specs[v], *scene, stepped));
    const std::unique_ptr<RenderSession> together = renderer().open_session();
    std::array<std::unique_ptr<Renderer::ViewFrame>, 3> begun;
    for (int v = 0; v < 3; ++v)
      begun[v] = renderer().begin(*together, v, specs[v], *scene, stepped, true);
    for (int v = 0; v < 3; ++v) {
      const std::vector<std::uint8_t> overlapped = pixels(renderer().end(*begun[v]));
      ASSERT_EQ(overlapped.size(), one_at_a_time[v].size());
      EXPECT_TRUE(overlapped == one_at_a_time[v])
          << sim::view_name(specs[v].view) << (scene == &night ? " at night" : " by day")
          << " differs when begun beside another view";
    }
  }
}

// The server draws the rain of the step before the frame's, its drops moved on to the frame's time
// (Simulation::inputs_after, RainLayerInputs::dt_s), so that no pass waits for the step: the
// streaks fall where the step's own would, but for the drops born or landed in the step (at 10 s
// of heavy rain, RAIN 33.8 dB and ROAD 40.2 dB against the step's own; left where they were, 31.5
// and 36.6, as far as a frame behind).
TEST_F(RendererTest, TheLastStepsRainMovedOnDrawsAsTheStepsOwn) {
  const sim::Scenario scenario = sim::highway_heavy_rain();
  sim::SimulationConfig config;
  config.simulate_water = false;
  sim::Simulation simulation(scenario.seed, scenario.at(10.0), config);
  simulation.advance(10.0);
  const sim::SceneState inputs = simulation.inputs_after(1.0 / 30.0);
  simulation.advance(1.0 / 30.0);
  const sim::SceneState& stepped = simulation.state();
  ASSERT_LT(inputs.rain.time_s, stepped.rain.time_s);
  sim::SceneState left_behind = inputs;  // the drops drawn where the last step left them
  left_behind.rain.time_s = left_behind.sim_time_s;
  for (const sim::View view : {sim::View::kRain, sim::View::kRoad}) {
    const RgbaImage own = render(view, stepped);
    const double moved_on = testing::psnr(render(view, inputs), own);
    const double left = testing::psnr(render(view, left_behind), own);
    EXPECT_GT(moved_on, 32.0) << sim::view_name(view);
    EXPECT_GT(moved_on, left + 1.5) << sim::view_name(view) << ": left behind " << left << " dB";
  }
}

TEST_F(RendererTest, SameSceneRendersTheSamePixels) {
  const sim::SceneState scene = highway_scene();
  EXPECT_EQ(render(sim::View::kCockpit, scene).pixels, render(sim::View::kCockpit, scene).pixels);
}

// The environment's schedule: after the first tick (every face), a face on its own every few
// ticks, the front every other time. The count the warm-up draws to ends on the tick of the last
// face's first turn alone, and by then each face but the back has had one.
TEST_F(RendererTest, EachEnvironmentFaceIsDrawnAloneByTheWarmUpsCount) {
  for (const int every : {6, 1, 4}) {
    EnvironmentConfig config;
    config.ticks_per_face = every;
    EnvironmentProbe probe(config);
    const int ticks = EnvironmentProbe::ticks_until_each_face_alone(config);
    std::array<int, EnvironmentProbe::kFaces> first_alone{};
    first_alone.fill(-1);
    for (int tick = 0; tick < ticks; ++tick) {
      const std::vector<EnvironmentProbe::Due>& due = probe.faces_due(tick / 30.0, false);
      if (tick == 0) continue;  // all six
      for (const EnvironmentProbe::Due& d : due) {
        if (first_alone[d.face] < 0) first_alone[d.face] = tick;
      }
    }
    EXPECT_EQ(first_alone[1], -1) << "the back is never drawn";
    int last = -1;
    for (int f = 0; f < EnvironmentProbe::kFaces; ++f) {
      if (f == 1) continue;
      EXPECT_GE(first_alone[f], 0) << "face " << f << ", every " << every;
      last = std::max(last, first_alone[f]);
    }
    EXPECT_EQ(last, ticks - 1) << "every " << every;
  }
}

}  // namespace
}  // namespace downpour::render
