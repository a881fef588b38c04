// The drops in the full scene (COCKPIT at 1280 x 720 from the driver's eye, the car parked in 10
// mm/h, the wipers off): each drop is a lens that shows the world turned over. Over the sky a
// drop's lower part shows the sky and its upper part the ground (and, steeper, the dark rim where
// its surface is too steep for the rays to leave), so its bottom third is brighter than its top
// third, against the same glass dry; over the grass it shows the bright sky. At night the glass is
// calm but for the glints of the lamps.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <vector>

#include <gtest/gtest.h>

#include "server/render/cpu/camera.hpp"
#include "server/render/cpu/glass_view.hpp"
#include "server/sim/glass_water_surface.hpp"
#include "server/sim/pose.hpp"
#include "tests/render/drop_footprints.hpp"
#include "tests/render/render_fixture.hpp"
#include "tests/render/windshield_fixture.hpp"

namespace downpour::render {
namespace {

using testing::Footprint;
using testing::footprints;
using testing::luma;
using testing::RgbaImage;

constexpr int kWidth = 1280;
constexpr int kHeight = 720;
// Drops over the grass in the day scene, with the renderer before traced drops: the mean of wet -
// dry over their footprints (grey levels).
constexpr double kGrassBefore = 4.1;  // (and over the sky: 0.3 levels, 10% of the drops)

class DropInversionTest : public testing::RenderTest {
 protected:
  static sim::SceneState without_water(sim::SceneState scene) {
    scene.windshield.surface.reset();
    scene.windshield.metaballs.clear();
    scene.windshield.glass_wet_fraction = 0.0;
    return scene;
  }
};

// Over the sky (every pixel behind the drop bright, its rays above the horizon): the drops'
// bottom thirds are brighter than their top thirds, against dry glass, by 10 grey levels or more on
// average, and at least 60% of them show it; small lenses and large bodies alike.
TEST_F(DropInversionTest, DropsOverTheSkyShowTheGroundAtTheirTop) {
  const sim::SceneState wet = testing::parked_in_rain(10.0, 3.0, 40.0, 0.3);
  const sim::ViewSpec spec = view_spec(sim::View::kCockpit, kWidth, kHeight);
  const RgbaImage a = render(spec, wet), b = render(spec, without_water(wet));
  testing::write_png(::testing::TempDir() + "drop_inversion_day.png", a);
  std::vector<Footprint> sky;
  for (const Footprint& f : footprints(wet, spec, a, b, 0.5)) {
    if (f.lowest_dry > 120.0 && f.min_elevation > 0.04) sky.push_back(f);
  }
  ASSERT_GE(sky.size(), 10u) << "drops over the sky";
  double sum = 0.0;
  int showing = 0;
  for (const Footprint& f : sky) {
    sum += f.inversion();
    showing += f.inversion() >= 3.0;
  }
  const double mean = sum / sky.size(), share = static_cast<double>(showing) / sky.size();
  std::printf(
      "%zu drops over the sky: bottom third minus top third, wet against dry, %.1f grey"
      " levels on average; %.0f%% show 3 or more\n",
      sky.size(), mean, 100.0 * share);
  for (const double from : {0.5, 1.5, 3.0}) {
    double s = 0.0;
    int n = 0;
    for (const Footprint& f : sky) {
      if (f.radius_mm >= from && f.radius_mm < from * 2.0) s += f.inversion(), ++n;
    }
    if (n) std::printf("  radius %.1f-%.1f mm: %d drops, %.1f levels\n", from, 2 * from, n, s / n);
  }
  EXPECT_GE(mean, 10.0);
  EXPECT_GE(share, 0.6);
}

// Over the grass beside the road (dark, below the horizon) a drop shows the sky: it brightens what
// lies behind it, by more than the renderer before traced drops did in the same scene (grey
// levels on average over its footprint there: 4.1).
TEST_F(DropInversionTest, DropsOverTheGrassShowTheSky) {
  const sim::SceneState wet = testing::parked_in_rain(10.0, 3.0, 40.0, 0.3);
  const sim::ViewSpec spec = view_spec(sim::View::kCockpit, kWidth, kHeight);
  const RgbaImage a = render(spec, wet), b = render(spec, without_water(wet));
  double sum = 0.0;
  int n = 0;
  for (const Footprint& f : footprints(wet, spec, a, b, 0.5)) {
    if (f.highest_dry < 110.0 && f.lowest_dry > 40.0 && f.min_elevation < -0.01) {
      sum += f.change;
      ++n;
    }
  }
  ASSERT_GE(n, 10) << "drops over the grass";
  std::printf("%d drops over the grass: %.1f grey levels brighter on average\n", n, sum / n);
  EXPECT_GE(sum / n, kGrassBefore + 0.5);
}

// At night in the rain under the street lights, the glass is calm but for the lamps' glints: its
// 3 x 3 high-pass (each pixel less the mean of its neighbours) holds at most twice the energy of
// the same frame with dry glass, outside the glints (where the water brightens the frame by more
// than 30 grey levels, and two pixels round them). The drops' glints are there, and soft.
TEST_F(DropInversionTest, AtNightTheGlassIsCalmButForTheGlints) {
  const sim::SceneState wet = testing::parked_in_rain(10.0, 3.0, -10.0, 0.3);
  const sim::ViewSpec spec = view_spec(sim::View::kCockpit, kWidth, kHeight);
  const RgbaImage a = render(spec, wet), b = render(spec, without_water(wet));
  testing::write_png(::testing::TempDir() + "drop_inversion_night.png", a);
  const Camera camera = make_camera(spec, wet.vehicle, &wet.weather);
  const GlassView view(camera, wet.glass, spec.height);
  std::vector<std::uint8_t> glint(static_cast<std::size_t>(kWidth) * kHeight, 0);
  int glints = 0;
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      if (luma(a, x, y) - luma(b, x, y) <= 30.0) continue;
      ++glints;
      for (int j = std::max(y - 2, 0); j <= std::min(y + 2, kHeight - 1); ++j) {
        for (int i = std::max(x - 2, 0); i <= std::min(x + 2, kWidth - 1); ++i)
          glint[static_cast<std::size_t>(j) * kWidth + i] = 1;
      }
    }
  }
  auto high_pass = [&](const RgbaImage& image, int x, int y) {
    double around = 0.0;
    for (int j = -1; j <= 1; ++j) {
      for (int i = -1; i <= 1; ++i) around += luma(image, x + i, y + j);
    }
    return luma(image, x, y) - around / 9.0;
  };
  double wet_energy = 0.0, dry_energy = 0.0;
  for (int y = 1; y + 1 < kHeight; ++y) {
    for (int x = 1; x + 1 < kWidth; ++x) {
      const auto g = view.hit((x + 0.5) / kWidth * 2.0 - 1.0, 1.0 - (y + 0.5) / kHeight * 2.0);
      if (!g || !wet.glass.contains(*g) || glint[static_cast<std::size_t>(y) * kWidth + x])
        continue;
      const double hw = high_pass(a, x, y), hd = high_pass(b, x, y);
      wet_energy += hw * hw;
      dry_energy += hd * hd;
    }
  }
  std::printf("night: %d glint pixels; high-pass energy of the glass, wet %.0f, dry %.0f (%.2f)\n",
              glints, wet_energy, dry_energy, wet_energy / dry_energy);
  EXPECT_GT(glints, 20) << "the lamps glint in the drops";
  EXPECT_LE(wet_energy, 2.0 * dry_energy);
}

}  // namespace
}  // namespace downpour::render
