// The WINDSHIELD view as ground truth: water where the metaballs are, black dry glass, the blades
// in a colour of their own.
#include "server/render/passes/windshield_pass.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "server/render/renderer.hpp"
#include "tests/render/render_fixture.hpp"
#include "tests/render/windshield_fixture.hpp"
#include "tests/support/png_io.hpp"

namespace downpour::render {
namespace {

using testing::RgbaImage;

constexpr int kWidth = 256;
constexpr int kHeight = 144;

class WindshieldPassTest : public testing::RenderTest {
 protected:
  static RgbaImage render(const sim::WindshieldState& water) {
    return render_water(water, view_spec(sim::View::kWindshield, kWidth, kHeight));
  }
  // The view's pixel of a glass point, as windshield.frag fits the glass (10 % margin).
  static glm::ivec2 pixel(glm::dvec2 uv_mm) {
    const sim::GlassConfig& g = dry_scene().glass;
    const double aspect = double(kWidth) / kHeight;
    const double mm_per_pixel = std::max(g.bottom_width_mm / aspect, g.height_mm) * 1.1 / kHeight;
    return {static_cast<int>(kWidth / 2 + (uv_mm.x - 0.5 * g.bottom_width_mm) / mm_per_pixel),
            static_cast<int>(kHeight / 2 - (uv_mm.y - 0.5 * g.height_mm) / mm_per_pixel)};
  }
  // The glass point at the centre of a view pixel (pixel()'s inverse).
  static glm::dvec2 centre_of(glm::ivec2 p) {
    const sim::GlassConfig& g = dry_scene().glass;
    const double aspect = double(kWidth) / kHeight;
    const double mm_per_pixel = std::max(g.bottom_width_mm / aspect, g.height_mm) * 1.1 / kHeight;
    return {0.5 * g.bottom_width_mm + (p.x + 0.5 - kWidth / 2) * mm_per_pixel,
            0.5 * g.height_mm - (p.y + 0.5 - kHeight / 2) * mm_per_pixel};
  }
  static const std::uint8_t* at(const RgbaImage& image, glm::ivec2 p) {
    return &image.pixels[(static_cast<std::size_t>(p.y) * image.width + p.x) * 4];
  }
};

TEST_F(WindshieldPassTest, ShowsWaterWhereTheMetaballsAreAndBlackElsewhere) {
  sim::WindshieldState water;
  const glm::dvec2 splashes[] = {{300.0, 200.0}, {760.0, 381.0}, {1200.0, 600.0}};
  for (const glm::dvec2& s : splashes) testing::add_splash(water, s.x, s.y, 40.0);
  const RgbaImage image = render(water);
  for (const glm::dvec2& s : splashes) {
    const std::uint8_t* p = at(image, pixel(s));
    EXPECT_GT(p[0], 80) << "splash at " << s.x << ", " << s.y;
    EXPECT_EQ(p[0], p[2]) << "water is grey";
  }
  // Dry glass between them: black.
  for (const glm::dvec2& dry :
       {glm::dvec2(500.0, 500.0), glm::dvec2(1000.0, 200.0), glm::dvec2(200.0, 650.0)}) {
    const std::uint8_t* p = at(image, pixel(dry));
    EXPECT_EQ(p[0] + p[1] + p[2], 0) << "dry glass at " << dry.x << ", " << dry.y;
  }
  // Every lit pixel inside the glass lies near a splash (or on the outline).
  const sim::GlassConfig& g = dry_scene().glass;
  int lit_far_from_water = 0;
  for (double u = 20.0; u < g.bottom_width_mm - 20.0; u += 10.0) {
    for (double v = 20.0; v < g.height_mm - 20.0; v += 10.0) {
      if (!g.contains({u + 20.0, v}) || !g.contains({u - 20.0, v})) continue;
      bool near = false;
      for (const glm::dvec2& s : splashes) near |= std::hypot(u - s.x, v - s.y) < 50.0;
      if (!near && at(image, pixel({u, v}))[0] > 0) ++lit_far_from_water;
    }
  }
  EXPECT_EQ(lit_far_from_water, 0);
}

TEST_F(WindshieldPassTest, ThickerWaterIsBrighter) {
  // A 3 mm drop rises about 1 mm; a 20 mm body to its flat top, 1.85 mm. Each centred on a pixel.
  const glm::ivec2 small_at = pixel({400.0, 381.0}), wide_at = pixel({1100.0, 381.0});
  const glm::dvec2 small = centre_of(small_at), wide = centre_of(wide_at);
  sim::WindshieldState water;
  water.metaballs.push_back({static_cast<float>(small.x), static_cast<float>(small.y), 3.0f});
  water.metaballs.push_back({static_cast<float>(wide.x), static_cast<float>(wide.y), 20.0f});
  const RgbaImage image = render(water);
  const int small_grey = at(image, small_at)[0];
  const int wide_grey = at(image, wide_at)[0];
  EXPECT_GT(small_grey, 60);
  EXPECT_GT(wide_grey, small_grey + 30);
}

TEST_F(WindshieldPassTest, BladesAreBlue) {
  sim::WindshieldState water;
  water.blades = {testing::blade_at(0, 60.0), testing::blade_at(1, 50.0)};
  const RgbaImage image = render(water);
  for (const sim::BladePose& blade : water.blades) {
    const glm::dvec2 dir(std::cos(blade.angle_rad), std::sin(blade.angle_rad));
    const std::uint8_t* p =
        at(image, pixel(glm::dvec2(blade.pivot_mm) + 0.7 * blade.length_mm * dir));
    EXPECT_GT(p[2], p[0] + 60) << "blade " << &blade - water.blades.data();
  }
}

}  // namespace
}  // namespace downpour::render
