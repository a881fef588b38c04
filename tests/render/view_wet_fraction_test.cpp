// The fraction of a COCKPIT view hidden by water, from the water's surface on the glass: none
// without water, all of it through a glass wholly wet, about half through a glass wet on one side
// or half covered by drops.
#include "server/render/cpu/view_wet_fraction.hpp"

#include <cmath>
#include <memory>

#include <gtest/gtest.h>

#include "server/render/cpu/camera.hpp"
#include "server/sim/drop_physics.hpp"
#include "server/sim/glass_water_surface.hpp"

namespace downpour::render {
namespace {

// Water over the default glass: a cap every `pitch` mm wherever `radius_at_u` (mm, of u) is above 0
// (3 mm at 4: the caps overlap, the glass is wholly wet).
template <typename Fn>
sim::SceneState scene_with_caps(Fn&& radius_at_u, float pitch = 4.0f) {
  sim::SceneState scene;
  auto surface = std::make_shared<sim::GlassWaterSurface>();
  for (float v = 0.5f * pitch; v < scene.glass.height_mm; v += pitch) {
    for (float u = 0.5f * pitch; u < scene.glass.bottom_width_mm; u += pitch) {
      const float r = static_cast<float>(radius_at_u(u));
      if (r > 0.0f) surface->bodies.push_back(sim::cap_body({u, v}, r, sim::kContactAngleDeg));
    }
  }
  surface->index(scene.glass);
  scene.windshield.surface = std::move(surface);
  return scene;
}

sim::ViewSpec dash_view(double fov_deg = 40.0) {
  sim::ViewSpec spec = sim::view_spec(sim::View::kCockpit, 640, 360, dash_camera_pose());
  spec.fov_deg = fov_deg;
  return spec;
}
sim::ViewSpec driver_view() { return sim::view_spec(sim::View::kCockpit, 640, 360); }

TEST(ViewWetFraction, NoWaterHidesNothing) {
  EXPECT_EQ(view_wet_fraction(driver_view(), scene_with_caps([](double) { return 0.0; })), 0.0);
  EXPECT_EQ(view_wet_fraction(driver_view(), sim::SceneState{}), 0.0);  // no surface yet
}

TEST(ViewWetFraction, AWetGlassHidesWhatIsSeenThroughIt) {
  const sim::SceneState wet = scene_with_caps([](double) { return 3.0; });
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
  const sim::SceneState half = scene_with_caps([](double u) { return u < 760.0 ? 3.0 : 0.0; });
  EXPECT_NEAR(view_wet_fraction(dash_view(), half), 0.5, 0.1);
  // Drops over half the glass everywhere: half the rays. (A pitch that no sampling grid shares.)
  const float pitch = 4.37f;
  const double half_covering = pitch * std::sqrt(0.5 / M_PI);
  const sim::SceneState misty = scene_with_caps([&](double) { return half_covering; }, pitch);
  EXPECT_NEAR(view_wet_fraction(dash_view(), misty), 0.5, 0.05);
  // And of the glass itself.
  EXPECT_NEAR(misty.windshield.surface->wet_fraction, 0.5, 0.02);
}

TEST(ViewWetFraction, OnlyTheCockpitLooksThroughTheGlass) {
  const sim::SceneState wet = scene_with_caps([](double) { return 3.0; });
  for (sim::View view : {sim::View::kRoad, sim::View::kWindshield, sim::View::kRain}) {
    EXPECT_EQ(view_wet_fraction(sim::view_spec(view, 640, 360), wet), 0.0);
  }
}

}  // namespace
}  // namespace downpour::render
