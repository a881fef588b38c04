// The sky as the driver sees it under a clear sky (the scattered sky, sky_table.hpp): a warm
// horizon towards a low sun and not away from it, blue at noon, the twilight's glow low over where
// the sun set, and a sky unchanged under full cloud.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include <glm/trigonometric.hpp>

#include <gtest/gtest.h>

#include "server/render/cpu/camera.hpp"
#include "tests/render/render_fixture.hpp"
#include "tests/render/windshield_fixture.hpp"

namespace downpour::render {
namespace {

using testing::RgbaImage;

constexpr int kW = 320, kH = 180;

class SkyTest : public testing::RenderTest {
 protected:
  // The highway's car, dry, no rain, the sun at this altitude and this far round from straight
  // ahead (degrees), under this much cloud.
  static sim::SceneState scene(double altitude_deg, double from_ahead_deg, double cloudiness) {
    sim::SceneState s = dry_scene();
    s.weather.rain_rate_mm_h = 0.0;
    s.weather.fog_density = 0.0;
    s.weather.cloudiness = cloudiness;
    s.weather.sun_altitude_deg = altitude_deg;
    s.weather.sun_azimuth_deg = s.vehicle.rotation.yaw_deg + from_ahead_deg;
    return s;
  }
  // The mean colour of the sky straight ahead, `elevation_deg` up (a 9 x 3 pixel patch), 40 pixels
  // to the right (clear of the sun's disc when it is ahead).
  static glm::dvec3 ahead(const RgbaImage& image, const sim::SceneState& s, double elevation_deg) {
    const sim::ViewSpec spec = sim::view_spec(sim::View::kCockpit, kW, kH);
    const Camera camera = make_camera(spec, s.vehicle);
    const double yaw = glm::radians(s.vehicle.rotation.yaw_deg), e = glm::radians(elevation_deg);
    const glm::vec3 dir(std::cos(e) * std::cos(yaw), std::cos(e) * std::sin(yaw), std::sin(e));
    const glm::vec4 clip =
        camera.projection * camera.view * glm::vec4(camera.position + 1e4f * dir, 1.0f);
    const int x = static_cast<int>((clip.x / clip.w * 0.5f + 0.5f) * kW);
    const int y = static_cast<int>((0.5f - clip.y / clip.w * 0.5f) * kH);
    glm::dvec3 sum(0.0);
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -4; dx <= 4; ++dx) {
        const std::uint8_t* p =
            &image.pixels[(static_cast<std::size_t>(y + dy) * kW + x + 40 + dx) * 4];
        sum += glm::dvec3(p[0], p[1], p[2]);
      }
    }
    return sum / 27.0;
  }
  static RgbaImage shot(const sim::SceneState& s, const std::string& name) {
    const RgbaImage image = render(sim::view_spec(sim::View::kCockpit, kW, kH), s);
    testing::write_png(::testing::TempDir() + "sky_" + name + ".png", image);
    return image;
  }
};

TEST_F(SkyTest, ALowSunWarmsTheHorizonTowardsItAndTwilightGlowsWhereItSet) {
  const sim::SceneState low = scene(3.0, 0.0, 0.1), behind = scene(3.0, 180.0, 0.1),
                        noon = scene(60.0, 0.0, 0.1), dusk = scene(-3.0, 0.0, 0.1);
  const glm::dvec3 low_h = ahead(shot(low, "low"), low, 4.0);
  const glm::dvec3 behind_h = ahead(shot(behind, "behind"), behind, 4.0);
  const glm::dvec3 noon_h = ahead(shot(noon, "noon"), noon, 4.0);
  const RgbaImage dusk_image = shot(dusk, "dusk");
  const glm::dvec3 dusk_h = ahead(dusk_image, dusk, 2.0), dusk_up = ahead(dusk_image, dusk, 20.0);
  auto show = [](const char* what, const glm::dvec3& c) {
    std::printf("%-34s %5.1f %5.1f %5.1f  red - blue %+5.1f\n", what, c.x, c.y, c.z, c.x - c.z);
  };
  show("sun 3 deg ahead, horizon ahead", low_h);
  show("sun 3 deg behind, horizon ahead", behind_h);
  show("sun 60 deg, horizon ahead", noon_h);
  show("sun -3 deg ahead, 2 deg up", dusk_h);
  show("sun -3 deg ahead, 20 deg up", dusk_up);
  EXPECT_GT(low_h.x - low_h.z, 40.0);
  EXPECT_GT((low_h.x - low_h.z) - (behind_h.x - behind_h.z), 30.0);
  EXPECT_LT(noon_h.x - noon_h.z, 0.0);
  EXPECT_GT(dusk_h.x - dusk_h.z, 15.0);
  EXPECT_LT(dusk_up.x - dusk_up.z, dusk_h.x - dusk_h.z - 10.0);
}

TEST_F(SkyTest, FullCloudHidesTheScattering) {
  // Under full cloud the table adds nothing: the sun's place changes only the light.
  const sim::SceneState a = scene(3.0, 0.0, 1.0), b = scene(3.0, 180.0, 1.0);
  const glm::dvec3 ca = ahead(shot(a, "cloud_a"), a, 10.0), cb = ahead(shot(b, "cloud_b"), b, 10.0);
  EXPECT_NEAR(ca.x - ca.z, cb.x - cb.z, 2.0);
}

// Glare through the wet glass: towards a sun 4 degrees up, each drop (a small lens with a wide
// field) near the sun's image shows a bright point of it, as the lamps make them do at night. The
// glass beaded with the golden windshield's water against the same glass dry, the sun ahead and
// the sun behind: the pixels the water makes brighter by 40 levels, within 90 px of the sun's
// image (or of where it would be ahead).
TEST_F(SkyTest, TowardsALowSunTheWetGlassGlares) {
  const sim::ViewSpec spec = sim::view_spec(sim::View::kCockpit, kW, kH);
  const auto glare = [&](double from_ahead_deg, const std::string& name) {
    sim::SceneState dry = scene(4.0, from_ahead_deg, 0.0);
    sim::SceneState wet = dry;
    wet.windshield = testing::golden_windshield(wet.glass);
    const RgbaImage a = shot(wet, name + "_wet"), b = shot(dry, name + "_dry");
    // Where the sun would show ahead: 4 degrees up, 6 to the right of straight ahead.
    const Camera camera = make_camera(spec, dry.vehicle);
    const double yaw = glm::radians(dry.vehicle.rotation.yaw_deg + std::min(from_ahead_deg, 6.0)),
                 e = glm::radians(4.0);
    const glm::vec3 dir(std::cos(e) * std::cos(yaw), std::cos(e) * std::sin(yaw), std::sin(e));
    const glm::vec4 clip =
        camera.projection * camera.view * glm::vec4(camera.position + 1e4f * dir, 1.0f);
    const int sx = static_cast<int>((clip.x / clip.w * 0.5f + 0.5f) * kW);
    const int sy = static_cast<int>((0.5f - clip.y / clip.w * 0.5f) * kH);
    int lit = 0;
    for (int y = 0; y < kH; ++y) {
      for (int x = 0; x < kW; ++x) {
        if ((x - sx) * (x - sx) + (y - sy) * (y - sy) > 90 * 90) continue;
        const std::size_t i = (static_cast<std::size_t>(y) * kW + x) * 4;
        const int d = (a.pixels[i] + a.pixels[i + 1] + a.pixels[i + 2] - b.pixels[i] -
                       b.pixels[i + 1] - b.pixels[i + 2]) /
                      3;
        lit += d > 40;
      }
    }
    std::printf(
        "the sun %.0f degrees round from ahead, 4 up (at %d, %d): %d pixels the water "
        "lights\n",
        from_ahead_deg, sx, sy, lit);
    return lit;
  };
  const int ahead = glare(6.0, "glare_ahead"), behind = glare(180.0, "glare_behind");
  EXPECT_GT(ahead, 40);
  EXPECT_GT(ahead, 5 * behind + 20);
}

}  // namespace
}  // namespace downpour::render
