// The COCKPIT view's windshield (the glass passes): water refracts the scene where it lies and
// nowhere else, the cabin stays in front of the glass, the wiper blades show as dark strips, and
// each view's lens blurs the water by its circle of confusion.
#include "server/render/passes/glass_water_pass.hpp"

#include <cmath>
#include <cstdlib>

#include <gtest/gtest.h>

#include "server/render/cpu/camera.hpp"
#include "server/render/cpu/glass_view.hpp"
#include "server/render/renderer.hpp"
#include "server/sim/pose.hpp"
#include "tests/render/render_fixture.hpp"
#include "tests/render/windshield_fixture.hpp"
#include "tests/support/png_io.hpp"

namespace downpour::render {
namespace {

using testing::RgbaImage;

constexpr int kWidth = 256;
constexpr int kHeight = 144;

class GlassPassesTest : public testing::RenderTest {
 protected:
  static sim::ViewSpec cockpit() { return view_spec(sim::View::kCockpit, kWidth, kHeight); }
  static RgbaImage render(const sim::WindshieldState& water,
                          const sim::ViewSpec& spec = cockpit()) {
    return render_water(water, spec);
  }
  // The pixel (x right, y down) where a glass point (mm) or a vehicle-frame point shows.
  static glm::ivec2 pixel_of(const glm::dvec3& vehicle_point,
                             const sim::ViewSpec& spec = cockpit()) {
    const Camera camera = make_camera(spec, dry_scene().vehicle);
    const glm::dvec4 clip = glm::dmat4(camera.projection * camera.view) *
                            sim::vehicle_to_world(dry_scene().vehicle) *
                            glm::dvec4(vehicle_point, 1.0);
    const glm::dvec2 ndc = glm::dvec2(clip) / clip.w;
    return {static_cast<int>((ndc.x * 0.5 + 0.5) * spec.width),
            static_cast<int>((0.5 - ndc.y * 0.5) * spec.height)};
  }
  static glm::ivec2 glass_pixel(glm::dvec2 uv_mm, const sim::ViewSpec& spec = cockpit()) {
    return pixel_of(dry_scene().glass.to_vehicle(uv_mm), spec);
  }
  // The pixel box of a square of glass (the glass is raked: the box of two opposite corners).
  static glm::ivec4 glass_box(glm::dvec2 centre_mm, double half_mm,
                              const sim::ViewSpec& spec = cockpit()) {
    const glm::ivec2 a = glass_pixel(centre_mm - half_mm, spec),
                     b = glass_pixel(centre_mm + half_mm, spec);
    return {std::min(a.x, b.x), std::min(a.y, b.y), std::max(a.x, b.x), std::max(a.y, b.y)};
  }

  static double luma(const RgbaImage& image, glm::ivec2 p) {
    return testing::mean_luma(image, p.x, p.y, p.x + 1, p.y + 1);
  }
  // Mean absolute difference over RGB in a pixel rectangle, in 0..255.
  static double difference(const RgbaImage& a, const RgbaImage& b, int x0, int y0, int x1, int y1) {
    double sum = 0.0;
    for (int y = y0; y < y1; ++y) {
      for (int x = x0; x < x1; ++x) {
        for (int c = 0; c < 3; ++c) {
          const std::size_t i = (static_cast<std::size_t>(y) * a.width + x) * 4 + c;
          sum += std::abs(int(a.pixels[i]) - int(b.pixels[i]));
        }
      }
    }
    return sum / (3.0 * (x1 - x0) * (y1 - y0));
  }

  static void save_if_asked(const std::string& name, const RgbaImage& image) {
    if (std::getenv("DOWNPOUR_SAVE_RENDERS"))
      testing::write_png(::testing::TempDir() + name, image);
  }
};

// Drops of 2.5 mm radius every 7 mm over a square of glass.
sim::WindshieldState drop_patch(glm::dvec2 centre_mm, double half_mm) {
  sim::WindshieldState s;
  for (double u = centre_mm.x - half_mm; u <= centre_mm.x + half_mm; u += 7.0) {
    for (double v = centre_mm.y - half_mm; v <= centre_mm.y + half_mm; v += 7.0) {
      s.metaballs.push_back({static_cast<float>(u), static_cast<float>(v), 2.5f});
    }
  }
  return s;
}

TEST_F(GlassPassesTest, DropsRefractWhereTheyLieAndNowhereElse) {
  const RgbaImage clear = render({});
  const glm::dvec2 centre(560.0, 420.0);
  const RgbaImage wet = render(drop_patch(centre, 60.0));
  save_if_asked("cockpit_drop_patch.png", wet);
  // The patch's pixels, from two opposite corners (the glass is raked: take the box).
  const glm::ivec2 a = glass_pixel(centre - 55.0), b = glass_pixel(centre + 55.0);
  const int x0 = std::min(a.x, b.x), x1 = std::max(a.x, b.x), y0 = std::min(a.y, b.y),
            y1 = std::max(a.y, b.y);
  ASSERT_GT(x1 - x0, 8);
  ASSERT_GT(y1 - y0, 4);
  EXPECT_GT(difference(wet, clear, x0, y0, x1, y1), 4.0);
  // Away from the patch the image is the clear one.
  EXPECT_EQ(difference(wet, clear, 0, 0, kWidth, y0 - 8), 0.0);
  EXPECT_EQ(difference(wet, clear, x1 + 12, 0, kWidth, kHeight), 0.0);
}

// The simulation's water: heavy rain at 25 m/s with the wipers off for 4 s, then one wipe. In the
// cockpit image, a square of glass inside blade 0's swept sector is closer to the dry-glass image
// after the wipe than the same square is at the same time without the wipe, and than it was before
// it. (The same square in both: through traced lenses a drop changes what lies behind it by that
// scene's contrast, so squares over different parts of the scene do not compare.)
TEST_F(GlassPassesTest, AfterAWipeTheSweptSectorLooksLikeDryGlass) {
  const sim::Scenario scenario = sim::highway_heavy_rain();
  sim::Update update = scenario.at(10.0);
  update.wipers = sim::WiperState{sim::WiperMode::kOff, 4.0, {}};
  sim::Simulation simulation(scenario.seed, update);
  simulation.advance(4.0);
  const sim::WindshieldState before = simulation.state().windshield;
  sim::Simulation unwiped = simulation;
  update.wipers = sim::WiperState{sim::WiperMode::kSingle, 4.0, {}};
  simulation.apply(update);
  simulation.advance(1.6);  // a cycle at 45 per minute takes 1.33 s
  unwiped.advance(1.6);
  const sim::WindshieldState after = simulation.state().windshield;

  const sim::ViewSpec spec = view_spec(sim::View::kCockpit, 640, 360);
  const RgbaImage dry = render({}, spec), wet = render(before, spec), wiped = render(after, spec);
  const RgbaImage left = render(unwiped.state().windshield, spec);
  save_if_asked("cockpit_before_wipe.png", wet);
  save_if_asked("cockpit_after_wipe.png", wiped);
  const sim::WiperConfig wipers;
  const sim::BladeConfig& blade = wipers.blades[0];
  const double angle = (blade.park_deg + 0.5 * blade.sweep_deg) * M_PI / 180.0;
  const glm::dvec2 swept =
      glm::dvec2(blade.pivot_mm) + 420.0 * glm::dvec2(std::cos(angle), std::sin(angle));
  const auto change = [&](const RgbaImage& image) {
    const glm::ivec4 box = glass_box(swept, 30.0, spec);
    EXPECT_GT(box.z - box.x, 10);
    EXPECT_GT(box.w - box.y, 4);
    return difference(image, dry, box.x, box.y, box.z, box.w);
  };
  // Mean RGB difference to the dry image, 0..255: measured 5.70 before the wipe, 3.41 after it
  // (fresh rain since), and 4.64 without it.
  EXPECT_GT(change(wet), 1.0);
  EXPECT_LT(change(wiped), 0.8 * change(left));
  EXPECT_LT(change(wiped), 0.8 * change(wet));
}

TEST_F(GlassPassesTest, ClearGlassLeavesTheScene) {
  const RgbaImage nothing = render({});
  sim::WindshieldState parked;
  parked.blades = testing::parked_blades();
  const RgbaImage clear = render(parked);
  // Parked blades lie along (or below) the glass's bottom edge: the rest is untouched.
  const int bottom = glass_pixel({760.0, 60.0}).y;
  ASSERT_GT(bottom, kHeight / 2);
  EXPECT_EQ(difference(clear, nothing, 0, 0, kWidth, bottom), 0.0);
  EXPECT_GT(testing::psnr(clear, nothing), 40.0);
}

TEST_F(GlassPassesTest, TheCabinStaysInFrontOfTheWater) {
  // Water over the whole glass.
  sim::WindshieldState flooded;
  for (double u = 4.0; u < 1520.0; u += 8.0) {
    for (double v = 4.0; v < 762.0; v += 8.0) {
      flooded.metaballs.push_back({static_cast<float>(u), static_cast<float>(v), 6.0f});
    }
  }
  const RgbaImage clear = render({});
  const RgbaImage wet = render(flooded);
  save_if_asked("cockpit_flooded.png", wet);
  // The mirror's face, in front of the glass: dark and unchanged.
  const glm::ivec2 mirror = pixel_of({1.50, 0.0, 1.245});
  ASSERT_LT(luma(clear, mirror), 0.15);
  EXPECT_EQ(difference(wet, clear, mirror.x - 1, mirror.y - 1, mirror.x + 2, mirror.y + 2), 0.0);
  // The dashboard below the glass: unchanged. The glass itself: changed nearly everywhere.
  EXPECT_EQ(difference(wet, clear, 0, kHeight * 9 / 10, kWidth, kHeight), 0.0);
  const glm::ivec2 middle = glass_pixel({760.0, 450.0});
  EXPECT_GT(difference(wet, clear, middle.x - 20, middle.y - 10, middle.x + 20, middle.y + 10),
            3.0);
}

TEST_F(GlassPassesTest, WiperBladesAreDarkStrips) {
  sim::WindshieldState wiping;
  wiping.blades = {testing::blade_at(0, 60.0), testing::blade_at(1, 50.0)};
  const RgbaImage clear = render({});
  const RgbaImage wiped = render(wiping);
  save_if_asked("cockpit_blades.png", wiped);
  int checked = 0;
  for (const sim::BladePose& blade : wiping.blades) {
    const glm::dvec2 dir(std::cos(blade.angle_rad), std::sin(blade.angle_rad));
    for (double along : {0.5, 0.7, 0.9}) {
      const glm::dvec2 uv = glm::dvec2(blade.pivot_mm) + along * blade.length_mm * dir;
      if (!dry_scene().glass.contains(uv)) continue;
      const glm::ivec2 p = glass_pixel(uv);
      if (p.x < 0 || p.x >= kWidth || p.y < 0 || p.y >= kHeight) continue;
      // Near black, blended at 256 x 144 with what lies around the strip.
      EXPECT_LT(luma(wiped, p), 0.15) << "blade pixel " << p.x << ", " << p.y;
      EXPECT_LT(luma(wiped, p), 0.5 * luma(clear, p)) << "blade pixel " << p.x << ", " << p.y;
      ++checked;
    }
  }
  EXPECT_GE(checked, 4);
}

TEST_F(GlassPassesTest, EachLensBlursTheGlassByItsCircleOfConfusion) {
  const sim::GlassConfig& glass = dry_scene().glass;
  const auto view_of = [&](const sim::ViewSpec& spec) {
    return GlassView(make_camera(spec, dry_scene().vehicle), glass, spec.height);
  };
  // The driver's eye, focused on the road through a 4 mm pupil, about 0.7 m from the glass: the
  // glass blurs over nearly the pupil.
  const GlassView driver = view_of(cockpit());
  EXPECT_GT(driver.distance_m(), 0.5);
  EXPECT_LT(driver.distance_m(), 1.0);
  EXPECT_NEAR(driver.blur_mm(), 4.0 * (1.0 - driver.distance_m() / 20.0), 1e-9);
  // A pinhole is sharp; a lens focused on the glass is sharp.
  sim::ViewSpec pinhole = cockpit();
  pinhole.aperture_mm = 0.0;
  EXPECT_EQ(view_of(pinhole).blur_mm(), 0.0);
  EXPECT_EQ(view_of(pinhole).layer_scale(), 1);
  sim::ViewSpec on_glass = cockpit();
  on_glass.focus_distance_m = driver.distance_m();
  EXPECT_NEAR(view_of(on_glass).blur_mm(), 0.0, 1e-9);
  // A dash camera, focused at 3 m through 2 mm: nearer the glass, a larger blur.
  sim::ViewSpec dash = cockpit();
  dash.camera = dash_camera_pose();
  const double at_dash = view_of(dash).blur_mm();
  EXPECT_GT(at_dash, 0.0);
  EXPECT_LT(at_dash, 2.0);
  sim::ViewSpec nearer = dash;
  nearer.camera->position_m.x += 0.05;
  sim::ViewSpec farther = dash;
  farther.camera->position_m.x -= 0.3;
  EXPECT_GT(view_of(nearer).blur_mm(), at_dash);
  EXPECT_LT(view_of(farther).blur_mm(), at_dash);
  // The larger the image, the more pixels the blur spans, and the smaller the water layer.
  const GlassView small = view_of(view_spec(sim::View::kCockpit, 640, 360));
  const GlassView large = view_of(view_spec(sim::View::kCockpit, 1920, 1080));
  EXPECT_NEAR(large.blur_px(), 3.0 * small.blur_px(), 1e-6);
  EXPECT_LE(small.layer_scale(), large.layer_scale());
  EXPECT_EQ(large.layer_scale(), 4);
  // A widened layer (llvmpipe's) has wider pixels across only where the blur itself spans two
  // pixels or more; never a pinhole's, nor where the layer is reduced for the renderer's sake.
  const auto widened = [&](int width, int height, double aperture_mm) {
    sim::ViewSpec spec = view_spec(sim::View::kCockpit, width, height);
    spec.aperture_mm = aperture_mm;
    return GlassView(make_camera(spec, dry_scene().vehicle), glass, spec.height, 2, 1.25);
  };
  const GlassView blurred = widened(1280, 720, 4.0);
  ASSERT_GE(blurred.blur_px(), 2.0);
  const int s = blurred.layer_scale();
  EXPECT_EQ(blurred.layer_size(1280, 720),
            glm::ivec2(static_cast<int>(std::ceil(1280.0 / (1.25 * s))), (720 + s - 1) / s));
  const GlassView slight = widened(640, 360, 1.0);
  ASSERT_LT(slight.blur_px(), 1.5);
  EXPECT_EQ(slight.layer_size(640, 360), glm::ivec2(320, 180));
  EXPECT_EQ(widened(1280, 720, 0.0).layer_size(1280, 720), glm::ivec2(1280, 720));
  EXPECT_EQ(large.layer_size(1920, 1080), glm::ivec2(480, 270));  // (a GPU's: square)

  // The dash camera's view is its own, and its drops change the image.
  const sim::WindshieldState water = testing::rainy_windshield(glass, 3000);
  const RgbaImage driver_image = render(water);
  const RgbaImage dash_clear = render({}, dash);
  const RgbaImage dash_wet = render(water, dash);
  save_if_asked("cockpit_dash.png", dash_wet);
  EXPECT_LT(testing::psnr(dash_wet, driver_image), 20.0);
  EXPECT_GT(difference(dash_wet, dash_clear, 0, 0, kWidth, kHeight), 0.2);
}

}  // namespace
}  // namespace downpour::render
