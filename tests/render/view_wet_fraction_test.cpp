// The fraction of a COCKPIT view hidden by water, from the coverage grid: none without water, all
// of it through a glass wholly wet, about half through a glass wet on one side.
#include "server/render/view_wet_fraction.hpp"

#include <gtest/gtest.h>

#include "server/render/camera.hpp"

namespace downpour::render {
namespace {

// A coverage grid over the default glass, each cell's wet fraction from a function of u (mm).
template <typename Fn>
sim::SceneState scene_with_coverage(Fn&& wet_fraction_at_u) {
  sim::SceneState scene;
  sim::WindshieldState& w = scene.windshield;
  w.coverage_cell_mm = 4.0;
  w.coverage_width = static_cast<int>(scene.glass.bottom_width_mm / w.coverage_cell_mm);
  w.coverage_height = static_cast<int>(scene.glass.height_mm / w.coverage_cell_mm) + 1;
  w.coverage.resize(static_cast<std::size_t>(w.coverage_width) * w.coverage_height);
  for (int y = 0; y < w.coverage_height; ++y) {
    for (int x = 0; x < w.coverage_width; ++x) {
      const double u = (x + 0.5) * w.coverage_cell_mm;
      w.coverage[static_cast<std::size_t>(y) * w.coverage_width + x] =
          static_cast<std::uint8_t>(255.0 * wet_fraction_at_u(u) + 0.5);
    }
  }
  return scene;
}

sim::ViewSpec dash_view(double fov_deg = 40.0) {
  return {sim::View::kCockpit, 640, 360, 85, fov_deg, dash_camera_pose()};
}
sim::ViewSpec driver_view() { return {sim::View::kCockpit, 640, 360, 85, 0.0, std::nullopt}; }

TEST(ViewWetFraction, NoWaterHidesNothing) {
  EXPECT_EQ(view_wet_fraction(driver_view(), scene_with_coverage([](double) { return 0.0; })), 0.0);
  EXPECT_EQ(view_wet_fraction(driver_view(), sim::SceneState{}), 0.0);  // no grid yet
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
    EXPECT_EQ(view_wet_fraction({view, 640, 360, 85, 0.0, std::nullopt}, wet), 0.0);
  }
}

}  // namespace
}  // namespace downpour::render
