// The water maps against the paper's formulas (seed 000, section 1.5): the metaball profile
// N = 1 / (1 + (h/R)^4) summed where metaballs overlap, the 5-step height compression, the
// threshold and the normals, read back texel by texel.
#include "server/render/passes/windshield_water_pass.hpp"

#include <cmath>
#include <memory>

#include <gtest/gtest.h>

#include "server/render/renderer.hpp"
#include "tests/render/render_fixture.hpp"

namespace downpour::render {
namespace {

// 2 mm texels over the glass's rectangle: texel (i, j) is centred at (2i + 1, 2j + 1) mm.
constexpr int kWidth = 760;
constexpr int kHeight = 381;
constexpr double kTexelMm = 2.0;

double profile(double h_mm, double radius_mm) {
  const double q = h_mm / radius_mm;
  return 1.0 / (1.0 + q * q * q * q);
}

// The paper's compression with its defaults, written out.
double compressed(double v) {
  for (double level : {0.5, 0.6, 0.7, 0.8, 0.9}) {
    if (v > level) v = 0.3 * (v - level) + level;
  }
  return v;
}

class WindshieldWaterPassTest : public testing::RenderTest {  // for the GL context
 protected:
  void SetUp() override { pass_ = std::make_unique<WindshieldWaterPass>(); }

  void render(const std::vector<sim::Metaball>& metaballs) {
    metaballs_ = metaballs;
    sim::WindshieldState state;
    state.metaballs = metaballs;
    const WaterMapLayout layout{{kWidth, kHeight}, {0.0f, 0.0f}, {1520.0f, 762.0f}};
    pass_->splat(state, layout);
    pass_->compress();
    heights_ = pass_->read_heights();
    water_ = pass_->read_water_map();
  }

  // The summed profile of the metaballs at a texel's centre, each over its sprite: a square
  // reaching 2.5 R from its centre.
  double expected_height(int i, int j) const {
    double sum = 0.0;
    for (const sim::Metaball& m : metaballs_) {
      const double du = (i + 0.5) * kTexelMm - m.u_mm, dv = (j + 0.5) * kTexelMm - m.v_mm;
      if (std::max(std::abs(du), std::abs(dv)) < 2.5 * m.radius_mm)
        sum += profile(std::hypot(du, dv), m.radius_mm);
    }
    return sum;
  }
  // Texels on a sprite's border may or may not be covered.
  bool on_a_sprite_border(int i, int j) const {
    for (const sim::Metaball& m : metaballs_) {
      const double du = (i + 0.5) * kTexelMm - m.u_mm, dv = (j + 0.5) * kTexelMm - m.v_mm;
      if (std::abs(std::max(std::abs(du), std::abs(dv)) - 2.5 * m.radius_mm) < 1.5 * kTexelMm)
        return true;
    }
    return false;
  }
  float height(int i, int j) const { return heights_[static_cast<std::size_t>(j) * kWidth + i]; }
  int water(int i, int j, int channel) const {
    return water_[(static_cast<std::size_t>(j) * kWidth + i) * 4 + channel];
  }

  std::unique_ptr<WindshieldWaterPass> pass_;
  std::vector<sim::Metaball> metaballs_;
  std::vector<float> heights_;
  std::vector<std::uint8_t> water_;
};

// One metaball of R = 16 mm centred on texel (200, 150).
const sim::Metaball kIsolated{401.0f, 301.0f, 16.0f};

TEST_F(WindshieldWaterPassTest, HeightMapIsTheMetaballProfile) {
  render({kIsolated});
  // Texel offsets at h/R = 0, 0.5, 1, 1.5, 2 and off the axes.
  const int offsets[][2] = {{0, 0}, {4, 0}, {-8, 0}, {0, 12}, {0, -16}, {6, 6}, {-5, 9}};
  for (const auto& o : offsets) {
    const int i = 200 + o[0], j = 150 + o[1];
    EXPECT_NEAR(height(i, j), expected_height(i, j), 0.01)
        << "texel offset " << o[0] << ", " << o[1];
  }
  EXPECT_NEAR(height(200, 150), 1.0, 0.01);
  EXPECT_NEAR(height(208, 150), 0.5, 0.01);  // h = R
  EXPECT_EQ(height(260, 150), 0.0f);         // beyond the sprite
}

TEST_F(WindshieldWaterPassTest, OverlappingMetaballsAdd) {
  const sim::Metaball second{421.0f, 305.0f, 12.0f};  // 20 mm right, 4 mm up
  render({kIsolated, second});
  int tested = 0;
  for (int i = 180; i <= 235; i += 3) {
    for (int j : {140, 146, 150, 153, 158}) {
      if (on_a_sprite_border(i, j)) continue;
      EXPECT_NEAR(height(i, j), expected_height(i, j), 0.01) << "texel " << i << ", " << j;
      ++tested;
    }
  }
  EXPECT_GT(tested, 60);
  // Between the two, the sum: far more than either alone.
  EXPECT_NEAR(height(205, 151),
              profile(std::hypot(10.0, 2.0), 16.0) + profile(std::hypot(10.0, 2.0), 12.0), 0.01);
  EXPECT_GT(height(205, 151), 1.5);
}

TEST_F(WindshieldWaterPassTest, WaterMapHoldsTheCompressedHeightAndThreshold) {
  const sim::Metaball second{421.0f, 305.0f, 12.0f};
  render({kIsolated, second});
  int compressed_texels = 0;
  for (int i = 180; i <= 235; ++i) {
    for (int j = 140; j <= 160; j += 2) {
      if (on_a_sprite_border(i, j)) continue;
      const double raw = expected_height(i, j);
      const double want = compressed(raw);
      EXPECT_NEAR(water(i, j, 2) / 255.0, std::min(want, 1.0), 0.012)
          << "texel " << i << ", " << j << " raw " << raw;
      compressed_texels += raw > 0.7;
      if (want > 0.55) {
        EXPECT_GE(water(i, j, 3), 250) << "inside, texel " << i << ", " << j;
      } else if (want < 0.45) {
        EXPECT_LE(water(i, j, 3), 5) << "outside, texel " << i << ", " << j;
      }
    }
  }
  EXPECT_GT(compressed_texels, 20);  // where the compression changes the height a lot
  // The peak of the pair: raw about 1.7, compressed about 0.70.
  EXPECT_GT(expected_height(205, 151), 1.5);
  EXPECT_NEAR(water(205, 151, 2) / 255.0, compressed(expected_height(205, 151)), 0.015);
}

TEST_F(WindshieldWaterPassTest, NormalsMakeALensOfADrop) {
  render({kIsolated});
  const auto lean = [&](int i, int j, int channel) { return water(i, j, channel) - 127.5; };
  EXPECT_NEAR(lean(200, 150, 0), 0.0, 3.0);  // flat on top
  EXPECT_NEAR(lean(200, 150, 1), 0.0, 3.0);
  // A spherical cap: the surface leans out of the drop by sin(contact angle, 40 degrees) h / R,
  // towards +u on the right, +v above, and not sideways.
  const double edge = 127.5 * std::sin(40.0 * M_PI / 180.0);
  EXPECT_NEAR(lean(204, 150, 0), 0.5 * edge, 6.0);
  EXPECT_NEAR(lean(196, 150, 0), -0.5 * edge, 6.0);
  EXPECT_NEAR(lean(200, 154, 1), 0.5 * edge, 6.0);
  EXPECT_NEAR(lean(200, 146, 1), -0.5 * edge, 6.0);
  EXPECT_NEAR(lean(204, 150, 1), 0.0, 2.0);
  EXPECT_NEAR(lean(208, 150, 0), edge, 8.0);  // at the edge, h = R
  EXPECT_NEAR(lean(192, 150, 0), -edge, 8.0);
  EXPECT_NEAR(lean(200, 158, 1), edge, 8.0);
}

TEST_F(WindshieldWaterPassTest, NoMetaballsLeaveDryFlatGlass) {
  render({});
  for (int i = 0; i < kWidth; i += 37) {
    for (int j = 0; j < kHeight; j += 29) {
      ASSERT_EQ(height(i, j), 0.0f);
      ASSERT_EQ(water(i, j, 2), 0);
      ASSERT_EQ(water(i, j, 3), 0);
      ASSERT_NEAR(water(i, j, 0), 128, 1);
    }
  }
}

}  // namespace
}  // namespace downpour::render
