// The fraction of a COCKPIT view hidden by water, from the glass water map's coverage: none without
// water, all of it through a glass wholly wet, about half through a glass wet on one side.
#include "server/render/view_wet_fraction.hpp"

#include <gtest/gtest.h>

#include "server/render/camera.hpp"

namespace downpour::render {
namespace {

// A glass water map over the default glass, each texel's coverage from a function of u (mm).
template <typename Fn>
sim::SceneState scene_with_coverage(Fn&& wet_fraction_at_u) {
  sim::SceneState scene;
  sim::GlassWaterMap& map = scene.windshield.map;
  map.texel_mm = 2.0;
  map.width = static_cast<int>(scene.glass.bottom_width_mm / map.texel_mm);
  map.height = static_cast<int>(scene.glass.height_mm / map.texel_mm) + 1;
  map.rgba.assign(static_cast<std::size_t>(map.width) * map.height * 4, 0);
  for (int y = 0; y < map.height; ++y) {
    for (int x = 0; x < map.width; ++x) {
      const double u = (x + 0.5) * map.texel_mm;
      map.rgba[(static_cast<std::size_t>(y) * map.width + x) * 4 + 3] =
          static_cast<std::uint8_t>(255.0 * wet_fraction_at_u(u) + 0.5);
    }
  }
  return scene;
}

sim::ViewSpec dash_view(double fov_deg = 40.0) {
  sim::ViewSpec spec = sim::view_spec(sim::View::kCockpit, 640, 360, dash_camera_pose());
  spec.fov_deg = fov_deg;
  return spec;
}
sim::ViewSpec driver_view() { return sim::view_spec(sim::View::kCockpit, 640, 360); }

TEST(ViewWetFraction, NoWaterHidesNothing) {
  EXPECT_EQ(view_wet_fraction(driver_view(), scene_with_coverage([](double) { return 0.0; })), 0.0);
  EXPECT_EQ(view_wet_fraction(driver_view(), sim::SceneState{}), 0.0);  // no map yet
}

TEST(ViewWetFraction, AWetGlassHidesWhatIsSeenThroughIt) {
  const sim::SceneState wet = scene_with_coverage([](double) { return 1.0; });
  // The dash camera sees only glass.
  EXPECT_GT(view_wet_fraction(dash_view(), wet), 0.99);
  // The driver sees the dashboard, the roof and a side window too: the glass is about half the
  // view.
  const double driver = view_wet_fraction(driver_view(), wet);
  EXPECT_GT(driver, 0.35);
  EXPECT_LT(driver, 0.75);
}

TEST(ViewWetFraction, HalfAGlassHidesAboutHalf) {
  // The glass wet on the driver's left half (u < 760); the dash camera on the centre line.
  const sim::SceneState half = scene_with_coverage([](double u) { return u < 760.0 ? 1.0 : 0.0; });
  EXPECT_NEAR(view_wet_fraction(dash_view(), half), 0.5, 0.1);
  // Cells half wet everywhere: half of each ray.
  const sim::SceneState misty = scene_with_coverage([](double) { return 0.5; });
  EXPECT_NEAR(view_wet_fraction(dash_view(), misty), 0.5, 0.01);
}

TEST(ViewWetFraction, OnlyTheCockpitLooksThroughTheGlass) {
  const sim::SceneState wet = scene_with_coverage([](double) { return 1.0; });
  for (sim::View view : {sim::View::kRoad, sim::View::kWindshield, sim::View::kRain}) {
    EXPECT_EQ(view_wet_fraction(sim::view_spec(view, 640, 360), wet), 0.0);
  }
}

}  // namespace
}  // namespace downpour::render
