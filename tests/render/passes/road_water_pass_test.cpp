// The water on the road, measured on the image: a wet road is darker than a dry one, mirrors the
// car's tail lights, and its puddles ripple while it rains; the golden pictures of a dry road, a
// drenched one and one with puddles.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "server/render/cpu/camera.hpp"
#include "server/sim/car_body.hpp"
#include "server/sim/lights.hpp"
#include "server/sim/pose.hpp"
#include "server/sim/scenario.hpp"
#include "server/sim/simulation.hpp"
#include "server/sim/vehicle_class.hpp"
#include "tests/render/render_fixture.hpp"
#include "tests/render/road_water_fixture.hpp"

namespace downpour::render {
namespace {

using testing::RgbaImage;

constexpr int kWidth = 320;
constexpr int kHeight = 180;

class RoadWaterPassTest : public testing::RenderTest {
 protected:
  // The red car on the highway after 5 minutes of 30 mm/h (flooded) or none (dry), the rain just
  // stopped: the road's water as the simulation leaves it. Simulated once for the tests that use
  // it (the flood takes some seconds).
  static const sim::SceneState& after_rain(bool flooded) {
    static const sim::SceneState states[2] = {simulate_rain(0.0), simulate_rain(30.0)};
    return states[flooded ? 1 : 0];
  }
  static sim::SceneState simulate_rain(double rain_mm_h) {
    const sim::Scenario scenario = sim::highway_heavy_rain();
    sim::Update update = scenario.at(10.0);
    update.vehicle->velocity_mps = glm::dvec3(0.0);
    update.weather->rain_rate_mm_h = rain_mm_h;
    update.weather->cloudiness = 0.9;
    update.weather->wind_speed_mps = 0.0;
    update.traffic = std::vector<sim::TrafficVehicle>{};
    sim::SimulationConfig config;
    config.simulate_water = false;
    config.simulate_spray = false;
    sim::Simulation simulation(scenario.seed, update, config);
    simulation.advance(rain_mm_h > 0.0 ? 300.0 : 1.0);  // (no rain: the dry road at once)
    update.weather->rain_rate_mm_h = 0.0;
    simulation.apply(update);
    simulation.advance(1.0);
    return simulation.state();
  }
  // The highway at 10 s with this rain and cloud, the glass dry and no streaks in the air (they
  // would cover the road), and the road hand-made: a film of film_mm (0: dry), with the tests'
  // puddles or not.
  static sim::SceneState scene(double rain_mm_h, double film_mm, bool puddles,
                               double cloudiness = 0.95) {
    sim::SceneState s = testing::highway_scene(rain_mm_h, cloudiness, false);
    s.rain.drops.clear();
    s.rain.splashes.clear();
    s.weather.wind_speed_mps = 0.0;  // still clouds: only ripples move on the road
    s.road_water = testing::hand_road_water(
        s.vehicle, film_mm, puddles ? testing::test_puddles() : std::vector<testing::HandPuddle>{});
    return s;
  }
  static RgbaImage render(sim::View view, const sim::SceneState& s) {
    return RenderTest::render(view_spec(view, kWidth, kHeight), s);
  }
  // Pixels in [x0, x1) x [y0, y1) whose red stands out of the grey road (by 5 levels of 255): a
  // lit lamp or its mirror image.
  static int red_pixels(const RgbaImage& image, int x0, int y0, int x1, int y1) {
    int n = 0;
    for (int y = y0; y < y1; ++y) {
      for (int x = x0; x < x1; ++x) {
        const std::uint8_t* p = &image.pixels[(static_cast<std::size_t>(y) * image.width + x) * 4];
        n += p[0] > std::max(p[1], p[2]) + 4;
      }
    }
    return n;
  }
  static double mean_abs_difference(const RgbaImage& a, const RgbaImage& b, int x0, int y0, int x1,
                                    int y1) {
    double sum = 0.0;
    for (int y = y0; y < y1; ++y) {
      for (int x = x0; x < x1; ++x) {
        const std::size_t i = (static_cast<std::size_t>(y) * a.width + x) * 4;
        for (int c = 0; c < 3; ++c) sum += std::abs(a.pixels[i + c] - b.pixels[i + c]);
      }
    }
    return sum / ((y1 - y0) * (x1 - x0) * 3.0);
  }
};

TEST_F(RoadWaterPassTest, RoadDarkensFromDryToWet) {
  // The road behind the car in the chase view, in the car's lane, seen steeply (about 35 degrees
  // down): the diffuse part falls as the texture fills and a film stands on it, and the film's
  // mirror adds little at this angle. Light rain under broken cloud: the road, not the haze. (The
  // dry road's relief casts shadows under the 30-degree sun, about 5% of its sunlight, which the
  // film fills: the bound was 0.85 before the shadows.)
  const auto road = [&](double film_mm) {
    const RgbaImage image = render(sim::View::kRoad, scene(1.0, film_mm, false, 0.3));
    return testing::mean_luma(image, kWidth * 28 / 100, kHeight * 9 / 10, kWidth * 45 / 100,
                              kHeight);
  };
  const double dry = road(0.0), wet = road(0.3);
  EXPECT_LT(wet, dry * 0.87) << "dry " << dry << ", wet " << wet;
}

// Wet markings: on the flooded road (5 minutes of 30 mm/h, the rain just stopped) the lane
// markings darken, and they no longer stand out of the road as they do dry: the water's mirror
// lies over paint and asphalt alike. In the chase view's lower half, the pixels that are markings
// on the dry road (luma over 120) and the asphalt (under 90), each set's mean luma dry and flooded.
TEST_F(RoadWaterPassTest, MarkingsDarkenAndMirrorAsTheAsphaltDoes) {
  const RgbaImage dry = render(sim::View::kRoad, after_rain(false)),
                  wet = render(sim::View::kRoad, after_rain(true));
  testing::write_png(::testing::TempDir() + "markings_dry.png", dry);
  testing::write_png(::testing::TempDir() + "markings_wet.png", wet);
  double paint[2] = {0.0, 0.0}, asphalt[2] = {0.0, 0.0};
  int n_paint = 0, n_asphalt = 0;
  for (int y = kHeight / 2; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      const double d = testing::mean_luma(dry, x, y, x + 1, y + 1) * 255.0;
      const double w = testing::mean_luma(wet, x, y, x + 1, y + 1) * 255.0;
      if (d > 120.0) paint[0] += d, paint[1] += w, ++n_paint;
      if (d < 90.0) asphalt[0] += d, asphalt[1] += w, ++n_asphalt;
    }
  }
  ASSERT_GT(n_paint, 100);
  const double paint_ratio = paint[1] / paint[0], asphalt_ratio = asphalt[1] / asphalt[0];
  std::printf(
      "markings (%d px): luma %.1f dry, %.1f flooded (x%.2f); asphalt (%d px): %.1f dry, "
      "%.1f flooded (x%.2f)\n",
      n_paint, paint[0] / n_paint, paint[1] / n_paint, paint_ratio, n_asphalt,
      asphalt[0] / n_asphalt, asphalt[1] / n_asphalt, asphalt_ratio);
  // The paint darkens; the asphalt's mirror of the bright sky makes up for its own darkening, so
  // the markings' contrast against it falls by a quarter or more.
  EXPECT_LT(paint_ratio, 0.85);
  EXPECT_LT(paint_ratio / asphalt_ratio, 0.75);
}

TEST_F(RoadWaterPassTest, TailLightsAreMirroredBelowTheCarOnAWetRoad) {
  // The chase camera's car: its lamps are red on the image's middle columns; below the car, on a
  // wet road, their mirror images. In a downpour under full cloud: a lamp outshines a bright
  // overcast sky less than the film's Fresnel (about 0.1 at this angle) can show.
  const auto below_the_car = [&](double film_mm) {
    const RgbaImage image = render(sim::View::kRoad, scene(40.0, film_mm, false, 1.0));
    return red_pixels(image, kWidth * 3 / 8, kHeight * 71 / 100, kWidth * 5 / 8, kHeight);
  };
  const int dry = below_the_car(0.0), wet = below_the_car(0.5);
  EXPECT_GT(wet, dry + 30) << "dry " << dry << ", wet " << wet;
}

TEST_F(RoadWaterPassTest, PuddlesRippleWhileItRainsAndStillWhenItStops) {
  // A tenth of a second apart: the puddle behind the car (the bottom of the chase view) changes
  // while rain falls, and not at all once it has stopped.
  const auto change = [&](double rain_mm_h) {
    sim::SceneState s = scene(rain_mm_h, 0.3, true);
    const RgbaImage before = render(sim::View::kRoad, s);
    s.sim_time_s += 0.1;
    const RgbaImage after = render(sim::View::kRoad, s);
    // The puddle 3.5 m behind the rear axle.
    return mean_abs_difference(before, after, kWidth * 35 / 100, kHeight * 4 / 5, kWidth * 65 / 100,
                               kHeight);
  };
  const double raining = change(20.0);
  std::printf("mean change of the puddle in 0.1 s: %.3f of 255 while it rains\n", raining);
  EXPECT_GT(raining, 0.08);
  EXPECT_EQ(change(0.0), 0.0);
}

// The mirror in colour: the red car on the road after 5 minutes of 30 mm/h, the rain just stopped
// (the road's water as the simulation leaves it), seen by the chase camera. Below the car, the road
// mirrors its red rear: the redness, R - (G + B) / 2, of the rows where the mirror shows the rear,
// over the dry road's.
//
// Which rows: the road mirrors the car as the camera would see it from under the road. Right under
// the bumper that eye looks into the gap beneath the car, and the mirror shows the dark underbody
// and wheels (as in photographs of cars on wet roads); the rear itself comes below that. The band
// is where the camera sees the mirror images of the rear's points, from its underside's height
// (the hull's bottom, car_body.hpp) to its tail lamps' (its class's layout). A band fixed at 75-90%
// of the image's height instead holds the underbody's image as well: it is reported, for
// comparison, and guarded at what it holds.
TEST_F(RoadWaterPassTest, AFloodedRoadMirrorsTheRedCarInRed) {
  const auto redness = [](const RgbaImage& image, int y0, int y1) {
    double sum = 0.0;
    int n = 0;
    for (int y = y0; y < y1; ++y) {
      for (int x = kWidth * 43 / 100; x < kWidth * 57 / 100; ++x, ++n) {
        const std::uint8_t* p = &image.pixels[(static_cast<std::size_t>(y) * kWidth + x) * 4];
        sum += p[0] - 0.5 * (p[1] + p[2]);
      }
    }
    return sum / n;
  };
  const sim::SceneState& wet = after_rain(true);
  const RgbaImage wet_image = render(sim::View::kRoad, wet),
                  dry_image = render(sim::View::kRoad, after_rain(false));
  testing::write_png(::testing::TempDir() + "mirror_red_wet.png", wet_image);
  testing::write_png(::testing::TempDir() + "mirror_red_dry.png", dry_image);
  for (int y = kHeight * 60 / 100; y < kHeight; y += kHeight / 20)
    std::printf("rows %d-%d: redness dry %.1f wet %.1f\n", y, y + kHeight / 20,
                redness(dry_image, y, y + kHeight / 20), redness(wet_image, y, y + kHeight / 20));
  // The image row of the mirror image of the car's rear centre at height z (the road is level
  // there: the vehicle frame's ground is the mirror's plane).
  const render::Camera camera =
      render::make_camera(view_spec(sim::View::kRoad, kWidth, kHeight), wet.vehicle);
  const glm::dmat4 to_world = sim::vehicle_to_world(wet.vehicle);
  const sim::VehicleLayout& car = sim::vehicle_layout(sim::VehicleClass::kCar);
  const auto mirrored_row = [&](double z) {
    const glm::dvec4 world = to_world * glm::dvec4(car.rear_m, 0.0, -z, 1.0);
    const glm::vec4 clip = camera.projection * camera.view * glm::vec4(world);
    return static_cast<int>(std::lround((0.5 - 0.5 * clip.y / clip.w) * kHeight));
  };
  const int rear_top = mirrored_row(sim::car_body::kHullBottomZ),
            rear_bottom = mirrored_row(car.tail_lamp_m.z);
  ASSERT_LT(rear_top + 2, rear_bottom);
  ASSERT_LE(rear_bottom, kHeight);
  const double gain =
      redness(wet_image, rear_top, rear_bottom) - redness(dry_image, rear_top, rear_bottom);
  const double fixed_band = redness(wet_image, kHeight * 75 / 100, kHeight * 90 / 100) -
                            redness(dry_image, kHeight * 75 / 100, kHeight * 90 / 100);
  std::printf(
      "the mirrored rear (rows %d-%d): redness %+.2f over the dry road's; rows 75-90%%: %+.2f\n",
      rear_top, rear_bottom, gain, fixed_band);
  // Issue 30 asks for 6 levels.
  EXPECT_GT(gain, 6.0);
  EXPECT_GT(fixed_band, 5.6);
}

// At night the flooded road mirrors the red car's tail lamps: below the car, in the band where the
// road mirrors its rear, red shows that the dry road does not have.
TEST_F(RoadWaterPassTest, AtNightTheFloodedRoadMirrorsTheTailLamps) {
  // The same roads after dark: the sun down, the car's lamps lit as its automatic lights do.
  const auto at_night = [](sim::SceneState s) {
    s.weather.sun_altitude_deg = -15.0;
    s.ego_lights = sim::resolve_lights(std::nullopt, s.weather, false);
    return s;
  };
  // The lamps' images are small: the redness, R - (G + B) / 2, of the reddest pixels (the top
  // 1%) in the band below the car where the road mirrors its rear.
  const auto reddest = [](const RgbaImage& image, int y0, int y1) {
    std::vector<double> red;
    for (int y = y0; y < y1; ++y) {
      for (int x = kWidth * 40 / 100; x < kWidth * 60 / 100; ++x) {
        const std::uint8_t* p = &image.pixels[(static_cast<std::size_t>(y) * kWidth + x) * 4];
        red.push_back(p[0] - 0.5 * (p[1] + p[2]));
      }
    }
    std::sort(red.begin(), red.end());
    return red[red.size() * 99 / 100];
  };
  const RgbaImage wet = render(sim::View::kRoad, at_night(after_rain(true)));
  const RgbaImage dry = render(sim::View::kRoad, at_night(after_rain(false)));
  testing::write_png(::testing::TempDir() + "mirror_night_wet.png", wet);
  testing::write_png(::testing::TempDir() + "mirror_night_dry.png", dry);
  const double on_wet = reddest(wet, kHeight * 75 / 100, kHeight * 92 / 100);
  const double on_dry = reddest(dry, kHeight * 75 / 100, kHeight * 92 / 100);
  std::printf(
      "at night, the reddest pixels of the mirror band: %.1f on the flooded road, %.1f on "
      "the dry\n",
      on_wet, on_dry);
  EXPECT_GT(on_wet, on_dry + 10.0);
}

class RoadWaterGoldenTest : public RoadWaterPassTest,
                            public ::testing::WithParamInterface<const char*> {};

TEST_P(RoadWaterGoldenTest, MatchesGoldenImage) {
  const std::string state = GetParam();
  // Dry: no rain yet. Wet: a film all over in moderate rain. Puddles: the same with the tests'
  // puddles, rippling (at the scene's time, so the same rings every run).
  const sim::SceneState s = state == "dry"   ? scene(0.0, 0.0, false, 0.6)
                            : state == "wet" ? scene(6.0, 0.3, false, 0.8)
                                             : scene(6.0, 0.3, true, 0.8);
  expect_golden(render(sim::View::kRoad, s), "ROAD_road_" + state + ".png");
  expect_golden(render(sim::View::kCockpit, s), "COCKPIT_road_" + state + ".png");
}

INSTANTIATE_TEST_SUITE_P(States, RoadWaterGoldenTest, ::testing::Values("dry", "wet", "puddles"),
                         [](const auto& info) { return std::string(info.param); });

// The chase view's road drawn at half size and brought in (RendererOptions::road_at_half, the
// default on llvmpipe) against the road drawn whole: at the tests' 320 x 180 (a 160 x 90 layer),
// dry, drenched and with rippling puddles, the picture is the same but for the road's finer detail
// (the asphalt's grain, the markings' edges); the car in front of the road hides it as before
// (its pixels the same), and the road's edges do not darken (its mean luma the same, and next to
// no pixel a quarter darker). Each
// renderer is made and closed in turn: a renderer's context is current on the thread it was made
// on.
class ChaseRoadAtHalfTest : public RoadWaterPassTest {
 protected:
  static void SetUpTestSuite() {}
  static RgbaImage draw(bool at_half, const sim::SceneState& s, int width = kWidth,
                        int height = kHeight) {
    auto renderer = render::Renderer::create({.road_at_half = at_half});
    return {width, height, render_image(*renderer, view_spec(sim::View::kRoad, width, height), s)};
  }
};

TEST_F(ChaseRoadAtHalfTest, ThePictureIsTheWholeRoadsButForItsFinestDetail) {
  const sim::SceneState states[] = {scene(0.0, 0.0, false, 0.6), scene(6.0, 0.3, false, 0.8),
                                    scene(6.0, 0.3, true, 0.8)};
  const char* names[] = {"dry", "wet", "puddles"};
  for (int k = 0; k < 3; ++k) {
    const RgbaImage whole = draw(false, states[k]), half = draw(true, states[k]);
    testing::write_png(::testing::TempDir() + "chase_road_whole_" + names[k] + ".png", whole);
    testing::write_png(::testing::TempDir() + "chase_road_half_" + names[k] + ".png", half);
    const double db = testing::psnr(whole, half);
    // The car: its rear between 40% and 60% across, 45-62% down (red stands out of the road).
    const int car_whole =
        red_pixels(whole, kWidth * 2 / 5, kHeight * 45 / 100, kWidth * 3 / 5, kHeight * 62 / 100);
    const int car_half =
        red_pixels(half, kWidth * 2 / 5, kHeight * 45 / 100, kWidth * 3 / 5, kHeight * 62 / 100);
    // The road: the lower third, where it fills the view.
    const double luma_whole = testing::mean_luma(whole, 0, kHeight * 2 / 3, kWidth, kHeight);
    const double luma_half = testing::mean_luma(half, 0, kHeight * 2 / 3, kWidth, kHeight);
    std::printf("%s: PSNR %.1f dB; car's red pixels %d whole, %d at half; road's luma %.4f, %.4f\n",
                names[k], db, car_whole, car_half, luma_whole, luma_half);
    // No pixel of the road goes dark where the layer's texels around it missed it (its
    // composite draws the road's own triangles): none a quarter darker than the whole road's.
    int dark = 0;
    for (std::size_t i = 0; i < whole.pixels.size(); i += 4) {
      const int w = whole.pixels[i] + whole.pixels[i + 1] + whole.pixels[i + 2];
      const int h = half.pixels[i] + half.pixels[i + 1] + half.pixels[i + 2];
      dark += 4 * h < 3 * w - 12;
    }
    std::printf("%s: %d pixels a quarter darker at half\n", names[k], dark);
    EXPECT_LE(dark, kWidth * kHeight / 2000) << names[k];
    EXPECT_GT(db, 30.0) << names[k];
    EXPECT_NEAR(car_half, car_whole, car_whole / 50 + 2) << names[k];
    EXPECT_NEAR(luma_half, luma_whole, 0.01) << names[k];
  }
  // A view of odd size, whose layer's last texels reach past its edge: the same.
  const double odd =
      testing::psnr(draw(false, states[2], 319, 179), draw(true, states[2], 319, 179));
  std::printf("puddles at 319x179: PSNR %.1f dB\n", odd);
  EXPECT_GT(odd, 38.0);
}

}  // namespace
}  // namespace downpour::render
