// The relief's shadows (seed 002) and the light of a low sun, measured on images: a grazing sun
// raises the road's fine contrast, the shadows darken the relief under a low sun and hardly at
// noon, and the golden pictures of a low sun and of dusk in the rain.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "tests/render/render_fixture.hpp"

namespace downpour::render {
namespace {

using testing::RgbaImage;

constexpr int kWidth = 320;
constexpr int kHeight = 180;

class ReliefRenderTest : public testing::RenderTest {
 protected:
  // The highway at 10 s (the car heading along +x, world yaw 0), clear air, the road dry unless it
  // rains; the sun sun_alt_deg high at world yaw sun_yaw_deg.
  static sim::SceneState scene(double sun_alt_deg, double sun_yaw_deg, double rain_mm_h = 0.0,
                               double cloudiness = 0.0) {
    sim::SceneState s = testing::highway_scene(rain_mm_h, cloudiness, false);
    if (rain_mm_h <= 0.0) {
      s.rain.drops.clear();
      s.rain.splashes.clear();
    }
    s.weather.fog_density = 0.0;
    s.weather.sun_altitude_deg = sun_alt_deg;
    s.weather.sun_azimuth_deg = sun_yaw_deg;
    return s;
  }
  // A camera on a pole beside the car's right front wheel, 1.4 m up, looking 55 degrees down at
  // the road to the right: the lane's asphalt and the shoulder's setts a few metres off, where a
  // pixel covers a few of the relief's texels.
  static sim::ViewSpec close_up() {
    sim::ViewSpec spec = view_spec(sim::View::kRoad, kWidth, kHeight);
    sim::CameraPose pose;
    pose.position_m = {2.5, -1.2, 1.4};
    pose.rotation.pitch_deg = 55.0;
    pose.rotation.yaw_deg = -50.0;
    spec.camera = pose;
    return spec;
  }
  // The image's fine contrast: in each 16 x 16 tile, the variance of each pixel's luma less the
  // mean of the 5 x 5 around it, over the tile's squared mean luma; the median over the tiles (a
  // painted line or the car's body crossing some tiles does not count).
  static double fine_contrast(const RgbaImage& image) {
    const int w = image.width, h = image.height;
    std::vector<double> luma(static_cast<std::size_t>(w * h));
    for (int i = 0; i < w * h; ++i) {
      const std::uint8_t* p = &image.pixels[static_cast<std::size_t>(i) * 4];
      luma[i] = (0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]) / 255.0;
    }
    std::vector<double> tiles;
    for (int ty = 0; ty + 16 <= h - 4; ty += 16) {
      for (int tx = 0; tx + 16 <= w - 4; tx += 16) {
        double mean = 0.0, fine2 = 0.0;
        for (int y = ty + 2; y < ty + 18; ++y) {
          for (int x = tx + 2; x < tx + 18; ++x) {
            double box = 0.0;
            for (int dy = -2; dy <= 2; ++dy) {
              for (int dx = -2; dx <= 2; ++dx) box += luma[(y + dy) * w + x + dx];
            }
            const double fine = luma[y * w + x] - box / 25.0;
            mean += luma[y * w + x];
            fine2 += fine * fine;
          }
        }
        mean /= 256.0;
        if (mean > 0.0) tiles.push_back(fine2 / 256.0 / (mean * mean));
      }
    }
    std::sort(tiles.begin(), tiles.end());
    return tiles.empty() ? 0.0 : tiles[tiles.size() / 2];
  }
  static RgbaImage render_relief(const sim::ViewSpec& spec, const sim::SceneState& s, bool on) {
    renderer().set_relief_shadows(on);
    RgbaImage image = render(spec, s);
    renderer().set_relief_shadows(true);
    return image;
  }
  static void save(const RgbaImage& image, const std::string& name) {
    if (const char* dir = std::getenv("DOWNPOUR_TEST_IMAGES")) {
      testing::write_png(std::string(dir) + "/" + name, image);
    }
  }
};

TEST_F(ReliefRenderTest, AGrazingSunRaisesTheRoadsFineContrast) {
  // The sun ahead of the car, 5 degrees high, against 60 degrees, seen from the side (the camera
  // looks to the right): the relief's lit faces and long shadows against a flat light. The fine
  // contrast is relative: the low sun's picture is darker as a whole.
  const RgbaImage low = render(close_up(), scene(5.0, 0.0));
  const RgbaImage high = render(close_up(), scene(60.0, 0.0));
  const RgbaImage low_flat = render_relief(close_up(), scene(5.0, 0.0), false);
  save(low, "relief_sun5.png");
  save(high, "relief_sun60.png");
  const double l = fine_contrast(low), h = fine_contrast(high), f = fine_contrast(low_flat);
  std::printf(
      "fine contrast (median tile's fine luma variance over its squared mean): sun 5 "
      "degrees %.4f (without the relief's shadows %.4f), 60 degrees %.4f\n",
      l, f, h);
  EXPECT_GT(l, 1.3 * h);
}

TEST_F(ReliefRenderTest, ShadowsDarkenTheReliefUnderALowSunAndHardlyAtNoon) {
  const auto darkening = [&](double alt) {
    const sim::SceneState s = scene(alt, 90.0);
    const RgbaImage with = render_relief(close_up(), s, true);
    const RgbaImage without = render_relief(close_up(), s, false);
    if (alt < 10.0) save(without, "relief_sun5_without.png");
    return 1.0 - testing::mean_luma(with) / testing::mean_luma(without);
  };
  const double low = darkening(5.0), noon = darkening(60.0);
  std::printf(
      "the relief's shadows take %.1f%% of the close-up's luma under a 5-degree sun, "
      "%.2f%% under a 60-degree one\n",
      100.0 * low, 100.0 * noon);
  EXPECT_GT(low, 0.05);
  EXPECT_LT(noon, 0.01);
  EXPECT_LT(noon, low / 5.0);
}

TEST_F(ReliefRenderTest, NoShadowsDrawnWithoutDirectSun) {
  // Under a heavy overcast in the rain, and after sunset, the sun casts no shadows: the cheaper
  // program draws the whole road.
  render(close_up(), scene(20.0, 90.0, 30.0, 1.0));
  EXPECT_FALSE(renderer().last_drew_relief()) << "overcast";
  render(close_up(), scene(-4.0, 90.0));
  EXPECT_FALSE(renderer().last_drew_relief()) << "after sunset";
  render(close_up(), scene(5.0, 90.0));
  EXPECT_TRUE(renderer().last_drew_relief()) << "a low sun in a clear sky";
}

// A sun shower: a low sun ahead under broken cloud, in light rain on a wet road, and the same at
// dusk (the sun 3 degrees under the horizon), from the driver's seat.
sim::SceneState sun_shower(double sun_alt_deg) {
  sim::SceneState s = testing::highway_scene(2.0, 0.2, false);
  s.weather.fog_density = 0.03;
  s.weather.sun_altitude_deg = sun_alt_deg;
  s.weather.sun_azimuth_deg = 20.0;
  return s;
}

TEST_F(ReliefRenderTest, GoldenLowSunInTheRain) {
  const RgbaImage image = render(view_spec(sim::View::kCockpit, kWidth, kHeight), sun_shower(6.0));
  save(image, "golden_low_sun.png");
  expect_golden(image, "relief_low_sun_COCKPIT.png");
}

TEST_F(ReliefRenderTest, GoldenDuskInTheRain) {
  const RgbaImage image = render(view_spec(sim::View::kCockpit, kWidth, kHeight), sun_shower(-3.0));
  save(image, "golden_dusk.png");
  expect_golden(image, "relief_dusk_COCKPIT.png");
}

}  // namespace
}  // namespace downpour::render
