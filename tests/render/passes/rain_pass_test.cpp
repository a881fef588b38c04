// The rain in the air, measured on the image: the RAIN view (the rain layer alone over black, from
// the driver's eye) and the scene views in rain.
#include <cmath>
#include <cstdio>
#include <optional>

#include <gtest/gtest.h>

#include "server/sim/scenario.hpp"
#include "server/sim/simulation.hpp"
#include "tests/render/render_fixture.hpp"

namespace downpour::render {
namespace {

using testing::RgbaImage;

constexpr int kWidth = 320;
constexpr int kHeight = 180;

class RainPassTest : public testing::RenderTest {
 protected:
  // The highway at 10 s with this rain, the car at `speed_mps` along its heading, the glass dry
  // (its water not simulated), after a second of rain in the air.
  // A crosswind blows towards the car's left at crosswind_mps (negative: towards its right).
  static sim::SceneState scene(double rain_mm_h, double speed_mps = 25.0, double angle_deg = 0.0,
                               double crosswind_mps = 0.0) {
    const sim::Scenario scenario = sim::highway_heavy_rain();
    sim::Update update = scenario.at(10.0);
    update.weather->rain_rate_mm_h = rain_mm_h;
    update.weather->rain_angle_deg = angle_deg;
    const double yaw = update.vehicle->rotation.yaw_deg * M_PI / 180.0;
    update.weather->wind_speed_mps = std::abs(crosswind_mps);
    update.weather->wind_direction_deg =
        update.vehicle->rotation.yaw_deg + (crosswind_mps >= 0.0 ? 90.0 : -90.0);
    update.vehicle->velocity_mps = glm::dvec3(std::cos(yaw), std::sin(yaw), 0.0) * speed_mps;
    sim::SimulationConfig config;
    config.simulate_water = false;
    sim::Simulation simulation(scenario.seed, update, config);
    simulation.advance(1.0);
    return simulation.state();
  }
  static RgbaImage render(sim::View view, const sim::SceneState& s) {
    return RenderTest::render(view_spec(view, kWidth, kHeight), s);
  }
  static int lit(const RgbaImage& image, int threshold = 8) {
    int n = 0;
    for (std::size_t i = 0; i < image.pixels.size(); i += 4) n += image.pixels[i] > threshold;
    return n;
  }
  // The structure tensor of the image's gradients over columns [x0, x1): the streaks' direction.
  struct Tensor {
    double xx = 0.0, yy = 0.0, xy = 0.0;
    // The sign of the side the streaks lean to (positive: from lower left to upper right, rows
    // counted downwards), as a fraction of the gradients' energy.
    double lean() const { return xy / std::max(1.0, xx + yy); }
    // How much the gradients share one direction: 0 for dots, 1 for parallel lines.
    double coherence() const {
      return std::sqrt((xx - yy) * (xx - yy) + 4.0 * xy * xy) / std::max(1.0, xx + yy);
    }
  };
  static Tensor tensor(const RgbaImage& image, int x0, int x1, int y0 = 0, int y1 = -1) {
    if (y1 < 0) y1 = image.height;
    Tensor t;
    auto at = [&](int x, int y) {
      return static_cast<double>(image.pixels[(y * image.width + x) * 4]);
    };
    for (int y = std::max(y0, 1); y < std::min(y1, image.height - 1); ++y) {
      for (int x = std::max(x0, 1); x < std::min(x1, image.width - 1); ++x) {
        const double gx = at(x + 1, y) - at(x - 1, y), gy = at(x, y + 1) - at(x, y - 1);
        t.xx += gx * gx;
        t.yy += gy * gy;
        t.xy += gx * gy;
      }
    }
    return t;
  }
  static double lean(const RgbaImage& image, int x0, int x1) {
    return tensor(image, x0, x1).lean();
  }
};

TEST_F(RainPassTest, TheRainViewIsBlackWithoutRain) {
  EXPECT_LT(testing::mean_luma(render(sim::View::kRain, scene(0.0))), 0.01);
}

TEST_F(RainPassTest, LitPixelsRiseWithTheRainRate) {
  const int light = lit(render(sim::View::kRain, scene(2.0)));
  const int heavy = lit(render(sim::View::kRain, scene(10.0)));
  const int cloudburst = lit(render(sim::View::kRain, scene(50.0)));
  // Light rain shows sparse streaks of smaller drops (a quarter of heavy rain's count): measured
  // 8,147 lit pixels at 2 mm/h, 19,636 at 10 and 25,750 at 50.
  EXPECT_GT(light, heavy / 5);
  EXPECT_GT(heavy, light * 2) << light << " " << heavy << " " << cloudburst;
  // In a cloudburst the streaks cover most of the view: their count still rises, their light
  // more.
  EXPECT_GT(cloudburst, heavy * 6 / 5) << light << " " << heavy << " " << cloudburst;
  const double heavy_luma = testing::mean_luma(render(sim::View::kRain, scene(10.0)));
  const double cloudburst_luma = testing::mean_luma(render(sim::View::kRain, scene(50.0)));
  EXPECT_GT(cloudburst_luma, heavy_luma * 1.5) << heavy_luma << " " << cloudburst_luma;
}

TEST_F(RainPassTest, StandingStillTheStreaksLeanWithTheRainAngle) {
  // Standing: a streak is the fall itself. A positive angle leans it towards the car's left.
  // Measured between the A-pillar and the mirror, whose edges lean too, over the middle of the
  // view, where upright streaks lean either way about equally.
  auto middle = [](const RgbaImage& image) {
    return lean(image, kWidth * 3 / 10, kWidth * 7 / 10);
  };
  const double right = middle(render(sim::View::kRain, scene(25.0, 0.0, 30.0)));
  const double left = middle(render(sim::View::kRain, scene(25.0, 0.0, -30.0)));
  const double upright = middle(render(sim::View::kRain, scene(25.0, 0.0, 0.0)));
  EXPECT_GT(std::abs(right), 0.05);
  EXPECT_LT(right * left, 0.0) << right << " " << left;  // opposite leans
  EXPECT_LT(std::abs(upright), std::abs(right) * 0.5);
}

// A crosswind carries the drops sideways: the streaks lean with it, as with the angle.
TEST_F(RainPassTest, StandingStillTheStreaksLeanWithACrosswind) {
  auto middle = [](const RgbaImage& image) {
    return lean(image, kWidth * 3 / 10, kWidth * 7 / 10);
  };
  const double to_left = middle(render(sim::View::kRain, scene(25.0, 0.0, 0.0, 6.0)));
  const double to_right = middle(render(sim::View::kRain, scene(25.0, 0.0, 0.0, -6.0)));
  const double tilted = middle(render(sim::View::kRain, scene(25.0, 0.0, 30.0)));
  EXPECT_LT(to_left * to_right, 0.0) << to_left << " " << to_right;
  EXPECT_GT(to_left * tilted, 0.0) << to_left << " " << tilted;  // the same way as a + angle
}

// Drops that land on the bonnet throw crowns the driver sees: over the bonnet the RAIN view is
// brighter with the splashes than without them, and more so in heavier rain.
TEST_F(RainPassTest, SplashesOnTheBonnetFollowTheRainRate) {
  auto splash_light = [](double rain_mm_h) {
    const sim::SceneState with = scene(rain_mm_h, 0.0);
    int on_car = 0;
    for (const sim::SplashState& s : with.rain.splashes) on_car += s.on_car;
    EXPECT_GT(on_car, 0) << rain_mm_h;
    sim::SceneState without = with;
    without.rain.splashes.clear();
    const RgbaImage a = render(sim::View::kRain, with), b = render(sim::View::kRain, without);
    // The bonnet's rows in the driver's view.
    double light = 0.0;
    for (int y = kHeight * 57 / 100; y < kHeight * 67 / 100; ++y) {
      for (int x = 0; x < kWidth; ++x) {
        const std::size_t i = (static_cast<std::size_t>(y) * kWidth + x) * 4;
        light += std::max(0, a.pixels[i] - b.pixels[i]);
      }
    }
    return light;
  };
  const double heavy = splash_light(10.0), cloudburst = splash_light(50.0);
  EXPECT_GT(heavy, 0.0);
  EXPECT_GT(cloudburst, heavy * 2.0) << heavy << " " << cloudburst;
}

TEST_F(RainPassTest, AtSpeedTheStreaksRadiateFromTheHeadingPoint) {
  const RgbaImage image = render(sim::View::kRain, scene(25.0, 30.0));
  // Left of the heading point the streaks lean one way, right of it the other: measured above the
  // bonnet, between the A-pillar and the mirror, whose edges lean too.
  const double left = tensor(image, kWidth * 3 / 10, kWidth * 9 / 20, 0, kHeight * 11 / 20).lean();
  const double right = tensor(image, kWidth * 11 / 20, kWidth * 3 / 4, 0, kHeight * 11 / 20).lean();
  EXPECT_LT(left * right, 0.0) << left << " " << right;
}

TEST_F(RainPassTest, TheExposureSetsHowLongTheStreaksAre) {
  const sim::SceneState s = scene(25.0, 30.0);
  // How much the image's gradients share one direction, left of the heading point where the
  // streaks all lean the same way: right of the A-pillar and above the bonnet, whose edges would
  // be the strongest lines.
  auto coherence = [&](std::optional<double> exposure_s) {
    sim::ViewSpec spec = view_spec(sim::View::kRain, kWidth, kHeight);
    spec.exposure_s = exposure_s;
    return tensor(RenderTest::render(spec, s), kWidth * 3 / 10, kWidth * 9 / 20, 0,
                  kHeight * 11 / 20)
        .coherence();
  };
  const double frozen = coherence(0.0), standard = coherence(std::nullopt);
  const double long_exposure = coherence(0.05);
  std::printf("coherence: frozen %.3f, 1/60 s %.3f, 1/20 s %.3f\n", frozen, standard,
              long_exposure);
  EXPECT_LT(frozen, standard) << frozen << " " << standard << " " << long_exposure;
  EXPECT_LT(standard, long_exposure) << frozen << " " << standard << " " << long_exposure;
}

// A car ahead hides the rain behind it and not the rain in front of it: over the car's pixels the
// RAIN view keeps some streaks, fewer than where the car is not.
TEST_F(RainPassTest, ACarAheadHidesTheRainBehindIt) {
  const sim::SceneState open_road = scene(25.0, 0.0);
  sim::SceneState behind_a_car = open_road;
  sim::TrafficVehicle car;
  car.id = 1;
  car.state = open_road.vehicle;
  const double yaw = open_road.vehicle.rotation.yaw_deg * M_PI / 180.0;
  // Its rear axle 12 m ahead of ours: its tail about 8 m ahead of the eye, inside the rain's box.
  car.state.position_m += glm::dvec3(std::cos(yaw), std::sin(yaw), 0.0) * 12.0;
  behind_a_car.traffic = {car};
  // The car's pixels: where the driver's view changes when it is there (no rain in either).
  sim::SceneState dry_open = open_road, dry_car = behind_a_car;
  for (sim::SceneState* s : {&dry_open, &dry_car}) {
    s->rain.drops.clear();
    s->rain.splashes.clear();
  }
  const RgbaImage a = render(sim::View::kCockpit, dry_open);
  const RgbaImage b = render(sim::View::kCockpit, dry_car);
  const RgbaImage rain_open = render(sim::View::kRain, open_road);
  const RgbaImage rain_car = render(sim::View::kRain, behind_a_car);
  double over_car_open = 0.0, over_car = 0.0;
  int pixels = 0;
  for (std::size_t i = 0; i < a.pixels.size(); i += 4) {
    if (std::abs(a.pixels[i + 1] - b.pixels[i + 1]) < 24) continue;
    ++pixels;
    over_car_open += rain_open.pixels[i];
    over_car += rain_car.pixels[i];
  }
  ASSERT_GT(pixels, 200) << "the car ahead should cover some of the view";
  EXPECT_LT(over_car, over_car_open * 0.8) << over_car / pixels << " " << over_car_open / pixels;
  EXPECT_GT(over_car, 0.0);  // the drops between us and it still show
}

TEST_F(RainPassTest, NoRainOverTheDashboardAndHeavyRainDarkensTheView) {
  sim::SceneState rainy = scene(50.0);
  sim::SceneState without_drops = rainy;
  without_drops.rain.drops.clear();
  const RgbaImage with = render(sim::View::kCockpit, rainy);
  const RgbaImage without = render(sim::View::kCockpit, without_drops);
  // The bottom tenth's middle is the dashboard (its corners are the side windows): the same
  // pixels, drops or none.
  const double dash_with =
      testing::mean_luma(with, kWidth / 4, kHeight * 9 / 10, kWidth * 3 / 4, kHeight);
  const double dash_without =
      testing::mean_luma(without, kWidth / 4, kHeight * 9 / 10, kWidth * 3 / 4, kHeight);
  EXPECT_DOUBLE_EQ(dash_with, dash_without);
  // Through the glass the streaks show.
  EXPECT_NE(testing::mean_luma(with, 0, kHeight / 4, kWidth, kHeight / 2),
            testing::mean_luma(without, 0, kHeight / 4, kWidth, kHeight / 2));
  // And more rain makes the picture darker, never brighter.
  for (sim::View view : {sim::View::kCockpit, sim::View::kRoad}) {
    EXPECT_LT(testing::mean_luma(render(view, rainy)), testing::mean_luma(render(view, scene(0.0))))
        << sim::view_name(view);
  }
}

}  // namespace
}  // namespace downpour::render
