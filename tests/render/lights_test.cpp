// The lamps at night, measured on images: the ego car's low beams light the road ahead and not
// beside it, and the rain in their beam; and the golden picture of a night drive in the rain with
// cars ahead and oncoming, under the street lights.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <utility>

#include <gtest/gtest.h>
#include <glm/trigonometric.hpp>

#include "server/render/cpu/camera.hpp"
#include "server/sim/pose.hpp"
#include "tests/render/render_fixture.hpp"

namespace downpour::render {
namespace {

using testing::RgbaImage;

constexpr int kWidth = 320;
constexpr int kHeight = 180;

class LightsRenderTest : public testing::RenderTest {
 protected:
  // The highway at 10 s at night (the sun 20 degrees down, clear air, the street lights lit), dry
  // unless it rains, the ego car's headlights as given.
  static sim::SceneState night(double rain_mm_h, sim::Headlights beams) {
    sim::SceneState s = testing::highway_scene(rain_mm_h, 0.0, false);
    if (rain_mm_h <= 0.0) {
      s.rain.drops.clear();
      s.rain.splashes.clear();
    }
    s.weather.fog_density = 0.0;
    s.weather.cloudiness = 0.0;
    s.weather.sun_altitude_deg = -20.0;
    s.ego_lights.headlights = beams;
    return s;
  }
  // A camera 3.5 m up over the car's boot, looking ahead 12 degrees down over its roof: the road
  // from some metres ahead of the bumper on, where the low beams fall.
  static sim::ViewSpec over_the_car() {
    sim::ViewSpec spec = view_spec(sim::View::kRoad, kWidth, kHeight);
    sim::CameraPose pose;
    pose.position_m = {-1.0, 0.0, 3.5};
    pose.rotation.pitch_deg = 12.0;
    spec.camera = pose;
    return spec;
  }
  // The mean luma (0..1) of the 5 x 5 pixels around where a point of the road, given in the car's
  // frame (x ahead of the rear axle, y left), shows.
  static double luma_at(const RgbaImage& image, const sim::ViewSpec& spec, const sim::SceneState& s,
                        double ahead_m, double left_m) {
    const Camera camera = make_camera(spec, s.vehicle);
    const glm::vec4 world =
        glm::vec4(sim::vehicle_to_world(s.vehicle) * glm::dvec4(ahead_m, left_m, 0.0, 1.0));
    const glm::vec4 clip = camera.projection * camera.view * world;
    const int x = static_cast<int>((clip.x / clip.w * 0.5f + 0.5f) * kWidth);
    const int y = static_cast<int>((0.5f - clip.y / clip.w * 0.5f) * kHeight);  // rows top-down
    EXPECT_TRUE(x >= 2 && x < kWidth - 2 && y >= 2 && y < kHeight - 2) << x << ", " << y;
    return testing::mean_luma(image, x - 2, y - 2, x + 3, y + 3);
  }
  // A car on the track `ahead_m` along it from the ego car, `lateral_m` left of its centre line,
  // driving with the traffic or against it.
  static sim::TrafficVehicle car(const sim::SceneState& s, std::uint32_t id, double ahead_m,
                                 double lateral_m, bool oncoming) {
    const sim::Track& track = sim::Track::built_in();
    const double s0 = track.project(glm::dvec2(s.vehicle.position_m), 50.0).s;
    const sim::TrackFrame f = track.at(s0 + ahead_m);
    sim::TrafficVehicle v;
    v.id = id;
    const glm::dvec2 xy = glm::dvec2(f.position) + f.left * lateral_m;
    v.state.position_m = {xy.x, xy.y, track.surface_height(s0 + ahead_m, lateral_m)};
    v.state.rotation.yaw_deg = glm::degrees(f.heading_rad) + (oncoming ? 180.0 : 0.0);
    v.size_m = {4.6, 1.8, 1.47};
    return v;
  }
  // The screen pixel (column, row top-down) where a world point shows.
  static glm::ivec2 pixel_of(const sim::ViewSpec& spec, const sim::SceneState& s,
                             glm::dvec3 world) {
    const Camera camera = make_camera(spec, s.vehicle);
    const glm::vec4 clip = camera.projection * camera.view * glm::vec4(glm::vec3(world), 1.0f);
    return {static_cast<int>((clip.x / clip.w * 0.5f + 0.5f) * spec.width),
            static_cast<int>((0.5f - clip.y / clip.w * 0.5f) * spec.height)};
  }
  static void save(const RgbaImage& image, const std::string& name) {
    if (const char* dir = std::getenv("DOWNPOUR_TEST_IMAGES")) {
      testing::write_png(std::string(dir) + "/" + name, image);
    }
  }
};

TEST_F(LightsRenderTest, TheLowBeamsLightTheRoadAheadAndNotBesideIt) {
  // The road 15 m ahead of the rear axle in the car's lane (in the beams), and 15 m ahead and 12 m
  // to the left, on the far lane (46 degrees off the beams' axis, beyond their 30): with the beams
  // on and off, under the same street lights.
  const sim::ViewSpec spec = over_the_car();
  const sim::SceneState on = night(0.0, sim::Headlights::kLow);
  const sim::SceneState off = night(0.0, sim::Headlights::kOff);
  const RgbaImage lit = render(spec, on), dark = render(spec, off);
  save(lit, "lights_low_beams.png");
  save(dark, "lights_no_beams.png");
  const double in_on = luma_at(lit, spec, on, 15.0, 0.0),
               in_off = luma_at(dark, spec, off, 15.0, 0.0);
  const double out_on = luma_at(lit, spec, on, 15.0, 12.0),
               out_off = luma_at(dark, spec, off, 15.0, 12.0);
  std::printf("in the beams %.3f (without them %.3f), beside them %.3f (%.3f)\n", in_on, in_off,
              out_on, out_off);
  // (At 11 m from the lamps the beams give the road about 7 lux, twice the street lights'.)
  EXPECT_GT(in_on, in_off + 0.05) << "the beams light the lane ahead";
  EXPECT_GT(in_on, out_on + 0.04) << "the road in the beams is brighter than beside them";
  EXPECT_NEAR(out_on, out_off, 0.01) << "and leave the far lane as the street lights light it";
}

TEST_F(LightsRenderTest, TheLowBeamsLightTheRainInTheDriversView) {
  // The RAIN view (the rain layer alone, from the driver's eye) in 10 mm/h: the streaks in the
  // beams' region (the lower middle of the view, under their cut-off, over the road ahead) against
  // those above the horizon, beams on and off.
  const sim::ViewSpec spec = view_spec(sim::View::kRain, kWidth, kHeight);
  const RgbaImage lit = render(spec, night(10.0, sim::Headlights::kLow));
  const RgbaImage dark = render(spec, night(10.0, sim::Headlights::kOff));
  save(lit, "lights_rain_low_beams.png");
  save(dark, "lights_rain_no_beams.png");
  // The mean luma of the streaks' pixels (any not black) in a region, rows top-down.
  const auto streaks = [](const RgbaImage& image, int x0, int y0, int x1, int y1) {
    double sum = 0.0;
    int n = 0;
    for (int y = y0; y < y1; ++y) {
      for (int x = x0; x < x1; ++x) {
        const std::uint8_t* p = &image.pixels[(static_cast<std::size_t>(y) * image.width + x) * 4];
        const double luma = (0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]) / 255.0;
        if (luma > 0.02) sum += luma, ++n;
      }
    }
    EXPECT_GT(n, 50) << "streaks in " << x0 << ", " << y0 << " .. " << x1 << ", " << y1;
    return n > 0 ? sum / n : 0.0;
  };
  const int beam[4] = {kWidth * 3 / 10, kHeight * 45 / 100, kWidth * 7 / 10, kHeight * 58 / 100};
  const int above[4] = {kWidth * 3 / 10, kHeight * 10 / 100, kWidth * 7 / 10, kHeight * 30 / 100};
  const double beam_on = streaks(lit, beam[0], beam[1], beam[2], beam[3]);
  const double beam_off = streaks(dark, beam[0], beam[1], beam[2], beam[3]);
  const double above_on = streaks(lit, above[0], above[1], above[2], above[3]);
  std::printf("streaks in the beams %.3f (without them %.3f), above the horizon %.3f\n", beam_on,
              beam_off, above_on);
  EXPECT_GT(beam_on, 1.5 * beam_off) << "the beams light the rain they pass through";
  EXPECT_GT(beam_on, 1.5 * above_on) << "brighter in the beams than above their cut-off";
}

TEST_F(LightsRenderTest, TheReliefCastsShadowsUnderTheLowBeams) {
  // A camera on a pole 2.5 m over the road ahead of the car and to its right, a narrow lens (20
  // degrees) looking 55 degrees down at the asphalt 9 m ahead of the headlamps, where the dipped
  // beams graze it 4 degrees high and give it some 12 lux: the relief's shadows on and off, at
  // night with the beams on, then off (the street lights alone, nearly overhead, cast none worth
  // drawing: the road is drawn without them).
  const sim::ViewSpec spec =
      posed_view(sim::View::kRoad, kWidth, kHeight, {11.0, -2.4, 2.5}, 0.0, 55.0, 20.0);
  const auto shadows_take = [&](sim::Headlights beams) {
    const sim::SceneState s = night(0.0, beams);
    const RgbaImage with = render(spec, s);
    const bool drawn = renderer().last_drew_relief();
    renderer().set_relief_shadows(false);
    const RgbaImage without = render(spec, s);
    renderer().set_relief_shadows(true);
    if (beams == sim::Headlights::kLow) {
      save(with, "lights_relief_beams.png");
      save(without, "lights_relief_beams_off.png");
    }
    const double a = testing::mean_luma(with), b = testing::mean_luma(without);
    std::printf("beams %s: relief drawn %d, luma %.4f with the shadows, %.4f without\n",
                beams == sim::Headlights::kLow ? "low" : "off", drawn, a, b);
    return std::pair<bool, double>(drawn, 1.0 - a / b);
  };
  const auto [drawn_low, taken_low] = shadows_take(sim::Headlights::kLow);
  const auto [drawn_off, taken_off] = shadows_take(sim::Headlights::kOff);
  EXPECT_TRUE(drawn_low);
  EXPECT_GT(taken_low, 0.02) << "the beams' grazing light leaves the stones' shadows";
  EXPECT_FALSE(drawn_off);
  EXPECT_NEAR(taken_off, 0.0, 1e-3);
}

TEST_F(LightsRenderTest, TheLampsBloomThroughTheWetGlass) {
  // An oncoming car on high beam 45 m off, seen from the driver's seat at night through a
  // windshield beaded with rain (the golden windshield's water) and through the same glass dry,
  // its lamps on and off. Each drop is a small lens with a wide field (some 100 degrees, most of it
  // squeezed into its rim): the drops around the lamps' image show bright points of them, fewer
  // farther off. Counted, for each glass: the pixels that the lamps make brighter by 0.1 near them
  // (8 to 40 px from them, 2 to 11 degrees) and far from them (beyond 120 px, 34 degrees).
  sim::SceneState s = night(0.0, sim::Headlights::kLow);
  const sim::Track& track = sim::Track::built_in();
  s.traffic = {car(s, 1, 45.0, -track.lane_centre(0), true)};
  sim::VehicleLights high;
  high.headlights = sim::Headlights::kHigh;
  s.traffic_lights = {high};
  const sim::ViewSpec spec = view_spec(sim::View::kCockpit, kWidth, kHeight);
  const glm::dvec3 front =
      glm::dvec3(sim::vehicle_to_world(s.traffic[0].state) * glm::dvec4(3.6, 0.0, 0.7, 1.0));
  const glm::ivec2 lamp = pixel_of(spec, s, front);
  struct Lit {
    int near = 0, far = 0;
  };
  const auto lit_by_the_lamps = [&](bool wet, const std::string& name) {
    sim::SceneState on = s;
    if (wet) on.windshield = testing::golden_windshield(on.glass);
    sim::SceneState off = on;
    off.traffic_lights[0].headlights = sim::Headlights::kOff;
    const RgbaImage a = render(spec, on), b = render(spec, off);
    save(a, name + "_on.png");
    save(b, name + "_off.png");
    Lit lit;
    for (int y = 0; y < kHeight; ++y) {
      for (int x = 0; x < kWidth; ++x) {
        const int r2 = (x - lamp.x) * (x - lamp.x) + (y - lamp.y) * (y - lamp.y);
        const double d =
            testing::mean_luma(a, x, y, x + 1, y + 1) - testing::mean_luma(b, x, y, x + 1, y + 1);
        if (d <= 0.1) continue;
        if (r2 >= 8 * 8 && r2 <= 40 * 40) ++lit.near;
        if (r2 > 120 * 120) ++lit.far;
      }
    }
    std::printf("%s glass, the lamps at (%d, %d): %d pixels lit near them, %d far off\n",
                wet ? "wet" : "dry", lamp.x, lamp.y, lit.near, lit.far);
    return lit;
  };
  const Lit wet = lit_by_the_lamps(true, "lights_bloom_wet");
  const Lit dry = lit_by_the_lamps(false, "lights_bloom_dry");
  EXPECT_GT(wet.near, 3 * dry.near + 20) << "the drops around the lamps show points of them";
  // Per pixel, near the lamps at least ten times as often as far off (the far region is some
  // eight times the near annulus here).
  EXPECT_LT(wet.far, wet.near * 8 / 10) << "and far fewer far from them";
}

TEST_F(LightsRenderTest, GoldenNightInTheRain) {
  // 10 mm/h at night from the driver's seat: the low beams, a car braking 25 m ahead in the lane
  // to the left, one oncoming 70 m off, the street lights; the road wet from the weather.
  sim::SceneState s = night(10.0, sim::Headlights::kLow);
  const sim::Track& track = sim::Track::built_in();
  s.traffic = {car(s, 1, 25.0, track.lane_centre(0), false),
               car(s, 2, 70.0, -track.lane_centre(0), true)};
  sim::VehicleLights braking;
  braking.headlights = sim::Headlights::kLow;
  braking.brake = true;
  sim::VehicleLights oncoming;
  oncoming.headlights = sim::Headlights::kLow;
  s.traffic_lights = {braking, oncoming};
  const RgbaImage image = render(view_spec(sim::View::kCockpit, kWidth, kHeight), s);
  save(image, "golden_night_rain.png");
  expect_golden(image, "lights_night_rain_COCKPIT.png");
}

}  // namespace
}  // namespace downpour::render
