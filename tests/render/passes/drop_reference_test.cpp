// The real-time drops held to the offline reference (tests/support/drop_reference.hpp): single
// spherical caps of three contact angles and three sizes, hand-placed on the default windshield,
// seen from the driver's eye through a pinhole at 1280 x 720, lit by a fixed environment with a
// sharp horizon (sky and sun above, a checkered ground below) that both see. Within each drop's
// footprint the frame must match the reference to a mean absolute error of 8 grey levels.
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>

#include <gtest/gtest.h>

#include "server/render/cpu/atmosphere.hpp"
#include "server/render/cpu/camera.hpp"
#include "server/render/environment_probe.hpp"
#include "server/render/passes/glass_water_pass.hpp"
#include "server/sim/glass_water_surface.hpp"
#include "server/sim/pose.hpp"
#include "tests/render/render_fixture.hpp"
#include "tests/support/drop_reference.hpp"

namespace downpour::render {
namespace {

using testing::RgbaImage;

constexpr int kWidth = 1280;
constexpr int kHeight = 720;
constexpr int kFace = 512;  // the fixed environment's faces: 0.18 degrees a texel

struct Placed {
  testing::ReferenceDrop drop;
};

class DropReferenceTest : public testing::RenderTest {
 protected:
  static void SetUpTestSuite() {
    RenderTest::SetUpTestSuite();
    renderer().set_fixed_environment(environment_faces(), kFace);
  }
  static void TearDownTestSuite() {
    renderer().set_fixed_environment(std::nullopt);
    RenderTest::TearDownTestSuite();
  }

  static const testing::ReferenceEnvironment& environment() {
    static const testing::ReferenceEnvironment env = [] {
      testing::ReferenceEnvironment e;
      // A sun low ahead and to the left of the car, where the drops' lower parts look.
      const double yaw = dry_scene().vehicle.rotation.yaw_deg * M_PI / 180.0 + 0.35;
      const double alt = 14.0 * M_PI / 180.0;
      e.sun_dir = {std::cos(alt) * std::cos(yaw), std::cos(alt) * std::sin(yaw), std::sin(alt)};
      return e;
    }();
    return env;
  }

  // The environment on the renderer's cube faces, each texel the mean of 2 x 2 directions.
  static std::array<std::vector<glm::vec3>, 6> environment_faces() {
    std::array<std::vector<glm::vec3>, 6> faces;
    for (int f = 0; f < 6; ++f) {
      faces[f].resize(static_cast<std::size_t>(kFace) * kFace);
      for (int j = 0; j < kFace; ++j) {
        for (int i = 0; i < kFace; ++i) {
          glm::dvec3 sum(0.0);
          for (int s = 0; s < 4; ++s) {
            const glm::vec2 xy((i + 0.25f + 0.5f * (s % 2)) / kFace * 2.0f - 1.0f,
                               (j + 0.25f + 0.5f * (s / 2)) / kFace * 2.0f - 1.0f);
            sum += environment().radiance(
                glm::normalize(glm::dvec3(EnvironmentProbe::direction(f, xy))));
          }
          faces[f][static_cast<std::size_t>(j) * kFace + i] = glm::vec3(sum * 0.25);
        }
      }
    }
    return faces;
  }

  // The nine drops: contact angles 40, 70 and 90 degrees across, radii 0.5, 1.5 and 3 mm up.
  static std::vector<testing::ReferenceDrop> drops() {
    std::vector<testing::ReferenceDrop> out;
    const double radii[] = {0.5, 1.5, 3.0}, angles[] = {40.0, 70.0, 90.0};
    for (int row = 0; row < 3; ++row) {
      for (int col = 0; col < 3; ++col)
        out.push_back({{480.0 + 170.0 * col, 330.0 + 100.0 * row}, radii[row], angles[col]});
    }
    return out;
  }

  static sim::SceneState scene_with(const std::vector<testing::ReferenceDrop>& placed) {
    sim::SceneState scene = dry_scene();
    auto surface = std::make_shared<sim::GlassWaterSurface>();
    for (const testing::ReferenceDrop& d : placed) {
      surface->bodies.push_back(sim::cap_body(
          glm::vec2(d.centre_mm), static_cast<float>(d.radius_mm), d.contact_angle_deg, false));
    }
    surface->index(scene.glass);
    scene.windshield.surface = surface;
    return scene;
  }
};

TEST_F(DropReferenceTest, EachDropMatchesTheRayTracedReference) {
  sim::ViewSpec spec = view_spec(sim::View::kCockpit, kWidth, kHeight);
  spec.aperture_mm = 0.0;  // a pinhole: the drops in focus
  const std::vector<testing::ReferenceDrop> placed = drops();
  const sim::SceneState scene = scene_with(placed);
  const RgbaImage frame = render(spec, scene);
  sim::SceneState dry_glass = scene;
  dry_glass.windshield.surface.reset();
  const RgbaImage dry = render(spec, dry_glass);

  const Camera camera = make_camera(spec, scene.vehicle);
  testing::ReferenceView view;
  view.eye = glm::dvec3(camera.position);
  view.inv_view_proj = glm::inverse(glm::dmat4(camera.projection) * glm::dmat4(camera.view));
  view.width = kWidth;
  view.height = kHeight;
  const glm::dmat4 to_world = sim::vehicle_to_world(scene.vehicle);
  const glm::dmat3 rotation(to_world);
  const testing::ReferenceGlass glass{
      glm::dvec3(to_world * glm::dvec4(scene.glass.bottom_left_m, 1.0)),
      rotation * scene.glass.u_axis(), rotation * scene.glass.v_axis()};
  const glm::dvec3 cabin(cabin_radiance(atmosphere_from(scene.weather)));
  const std::string dir = ::testing::TempDir() + "drop_reference/";
  std::filesystem::create_directories(dir);
  for (const testing::ReferenceDrop& drop : placed) {
    const testing::ReferencePixels ref =
        testing::trace_drop(view, glass, drop, environment(), cabin);
    double error = 0.0, dry_error = 0.0;
    int pixels = 0;
    testing::RgbaImage side{2 * ref.width + 1, ref.height,
                            std::vector<std::uint8_t>(
                                static_cast<std::size_t>(2 * ref.width + 1) * ref.height * 4, 255)};
    for (int y = 0; y < ref.height; ++y) {
      for (int x = 0; x < ref.width; ++x) {
        const std::size_t at = static_cast<std::size_t>(y) * ref.width + x;
        const std::uint8_t* p =
            &frame.pixels[(static_cast<std::size_t>(ref.y0 + y) * kWidth + ref.x0 + x) * 4];
        const double luma = 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
        if (ref.coverage[at] > 0.0) {
          error += std::abs(luma - ref.luma[at]);
          const std::uint8_t* q =
              &dry.pixels[(static_cast<std::size_t>(ref.y0 + y) * kWidth + ref.x0 + x) * 4];
          dry_error += std::abs(0.2126 * q[0] + 0.7152 * q[1] + 0.0722 * q[2] - ref.luma[at]);
          ++pixels;
        }
        for (int c = 0; c < 3; ++c) {
          side.pixels[(static_cast<std::size_t>(y) * side.width + x) * 4 + c] = ref.rgb[3 * at + c];
          side.pixels[(static_cast<std::size_t>(y) * side.width + ref.width + 1 + x) * 4 + c] =
              p[c];
        }
      }
    }
    ASSERT_GT(pixels, 0) << ref.x0 << "," << ref.y0 << " " << ref.width << "x" << ref.height;
    const double mae = error / pixels, dry_mae = dry_error / pixels;
    char name[96];
    std::snprintf(name, sizeof name, "drop_%.1fmm_%.0fdeg.png", drop.radius_mm,
                  drop.contact_angle_deg);
    testing::write_png(dir + name, side);
    std::printf(
        "drop r %.1f mm, contact %.0f deg: %d pixels, mean |frame - reference| %.2f grey"
        " levels (dry glass: %.2f; reference left, frame right: %s%s)\n",
        drop.radius_mm, drop.contact_angle_deg, pixels, mae, dry_mae, dir.c_str(), name);
    EXPECT_LE(mae, 8.0) << "r " << drop.radius_mm << " mm, " << drop.contact_angle_deg << " deg";
    // The bound means something: the drop not drawn at all misses the reference by more.
    if (drop.radius_mm >= 1.0) {
      EXPECT_GE(dry_mae, 2.0 * mae + 8.0) << drop.radius_mm;
    }
  }
}

}  // namespace
}  // namespace downpour::render
