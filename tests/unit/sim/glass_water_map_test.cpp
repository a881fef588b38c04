// The glass water map against the paper's formulas (seed 000, section 1.5): the metaball profile
// N = 1 / (1 + (h/R)^4) summed where metaballs overlap, the 5-step height compression, the
// threshold and the normals, texel by texel; and the incremental build against a whole one.
#include "server/sim/glass_water_map.hpp"

#include <cmath>

#include <gtest/gtest.h>

#include "server/sim/random.hpp"
#include "server/sim/water.hpp"

namespace downpour::sim {
namespace {

// 2 mm texels over the default glass's rectangle: texel (i, j) is centred at (2i + 1, 2j + 1) mm.
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

class GlassWaterMapTest : public ::testing::Test {
 protected:
  void build(const std::vector<Metaball>& metaballs) {
    metaballs_ = metaballs;
    builder_.build(metaballs, map_);
  }
  // The summed profile of the metaballs at a texel's centre, each over its square reaching 2.5 R.
  double expected_height(int i, int j) const {
    double sum = 0.0;
    for (const Metaball& m : metaballs_) {
      const double du = (i + 0.5) * kTexelMm - m.u_mm, dv = (j + 0.5) * kTexelMm - m.v_mm;
      if (std::max(std::abs(du), std::abs(dv)) < 2.5 * m.radius_mm)
        sum += profile(std::hypot(du, dv), m.radius_mm);
    }
    return sum;
  }
  float height(int i, int j) const {
    return builder_.raw_heights()[static_cast<std::size_t>(j) * kWidth + i];
  }
  int water(int i, int j, int channel) const {
    return map_.rgba[(static_cast<std::size_t>(j) * kWidth + i) * 4 + channel];
  }

  GlassConfig glass_;
  GlassWaterMapBuilder builder_{glass_};
  GlassWaterMap map_;
  std::vector<Metaball> metaballs_;
};

// One metaball of R = 16 mm centred on texel (200, 150).
const Metaball kIsolated{401.0f, 301.0f, 16.0f};
const Metaball kSecond{421.0f, 305.0f, 12.0f};  // 20 mm right, 4 mm up

TEST_F(GlassWaterMapTest, CoversTheGlassAtItsTexelSize) {
  build({});
  EXPECT_EQ(map_.width, kWidth);
  EXPECT_EQ(map_.height, kHeight);
  EXPECT_EQ(map_.texel_mm, kTexelMm);
  EXPECT_EQ(map_.rgba.size(), static_cast<std::size_t>(kWidth) * kHeight * 4);
}

TEST_F(GlassWaterMapTest, HeightsAreTheMetaballProfile) {
  build({kIsolated});
  // Texel offsets at h/R = 0, 0.5, 1, 1.5, 2 and off the axes.
  const int offsets[][2] = {{0, 0}, {4, 0}, {-8, 0}, {0, 12}, {0, -16}, {6, 6}, {-5, 9}};
  for (const auto& o : offsets) {
    const int i = 200 + o[0], j = 150 + o[1];
    EXPECT_NEAR(height(i, j), expected_height(i, j), 1e-5)
        << "texel offset " << o[0] << ", " << o[1];
  }
  EXPECT_NEAR(height(200, 150), 1.0, 1e-5);
  EXPECT_NEAR(height(208, 150), 0.5, 1e-5);  // h = R
  EXPECT_EQ(height(221, 150), 0.0f);         // beyond the square, 2.5 R = 40 mm
}

TEST_F(GlassWaterMapTest, OverlappingMetaballsAdd) {
  build({kIsolated, kSecond});
  for (int i = 170; i <= 240; i += 3) {
    for (int j : {135, 146, 150, 153, 165}) {
      EXPECT_NEAR(height(i, j), expected_height(i, j), 1e-5) << "texel " << i << ", " << j;
    }
  }
  EXPECT_NEAR(height(205, 151),
              profile(std::hypot(10.0, 2.0), 16.0) + profile(std::hypot(10.0, 2.0), 12.0), 1e-5);
  EXPECT_GT(height(205, 151), 1.5);
}

TEST_F(GlassWaterMapTest, HoldsTheCompressedHeightAndTheThreshold) {
  build({kIsolated, kSecond});
  int compressed_texels = 0;
  for (int i = 170; i <= 240; ++i) {
    for (int j = 135; j <= 165; j += 2) {
      const double raw = expected_height(i, j);
      const double want = compressed(raw);
      if (raw >= 0.1) {
        EXPECT_NEAR(water(i, j, 2) / 255.0, std::min(want, 1.0), 0.003)
            << "texel " << i << ", " << j << " raw " << raw;
      }
      compressed_texels += raw > 0.7;
      if (want > 0.55) {
        EXPECT_GE(water(i, j, 3), 250) << "inside, texel " << i << ", " << j;
      } else if (want < 0.45) {
        EXPECT_LE(water(i, j, 3), 5) << "outside, texel " << i << ", " << j;
      }
    }
  }
  EXPECT_GT(compressed_texels, 20);  // where the compression changes the height a lot
  EXPECT_NEAR(water(205, 151, 2) / 255.0, compressed(expected_height(205, 151)), 0.003);
}

TEST_F(GlassWaterMapTest, NormalsMakeALensOfADrop) {
  build({kIsolated});
  const auto lean = [&](int i, int j, int channel) { return water(i, j, channel) - 127.5; };
  EXPECT_NEAR(lean(200, 150, 0), 0.0, 1.0);  // flat on top
  EXPECT_NEAR(lean(200, 150, 1), 0.0, 1.0);
  // A spherical cap: the surface leans out of the drop by sin(contact angle) h / R, towards +u on
  // the right, +v above, and not sideways.
  const double edge = 127.5 * std::sin(kContactAngleDeg * M_PI / 180.0);
  EXPECT_NEAR(lean(204, 150, 0), 0.5 * edge, 2.0);
  EXPECT_NEAR(lean(196, 150, 0), -0.5 * edge, 2.0);
  EXPECT_NEAR(lean(200, 154, 1), 0.5 * edge, 2.0);
  EXPECT_NEAR(lean(200, 146, 1), -0.5 * edge, 2.0);
  EXPECT_NEAR(lean(204, 150, 1), 0.0, 1.0);
  EXPECT_NEAR(lean(208, 150, 0), edge, 3.0);  // at the edge, h = R
  EXPECT_NEAR(lean(192, 150, 0), -edge, 3.0);
  EXPECT_NEAR(lean(200, 158, 1), edge, 3.0);
}

TEST_F(GlassWaterMapTest, NoMetaballsLeaveDryFlatGlass) {
  build({});
  for (int i = 0; i < kWidth; i += 37) {
    for (int j = 0; j < kHeight; j += 29) {
      ASSERT_EQ(height(i, j), 0.0f);
      ASSERT_EQ(water(i, j, 2), 0);
      ASSERT_EQ(water(i, j, 3), 0);
      ASSERT_EQ(water(i, j, 0), 128);
      ASSERT_EQ(water(i, j, 1), 128);
    }
  }
  EXPECT_EQ(map_.wet_fraction, 0.0);
}

TEST_F(GlassWaterMapTest, CoverageAndWetFractionFollowTheWater) {
  // Large drops over the left half of the glass.
  std::vector<Metaball> left;
  for (double v = 10.0; v < 750.0; v += 9.0) {
    for (double u = 10.0; u < 700.0; u += 9.0) {
      left.push_back({static_cast<float>(u), static_cast<float>(v),
                      static_cast<float>(drop_radius_mm(drop_mass_mg(4.4)))});
    }
  }
  build(left);
  EXPECT_GT(map_.wet_fraction, 0.3);
  EXPECT_LT(map_.wet_fraction, 0.6);
  EXPECT_EQ(map_.coverage_at({300.0, 400.0}), 1.0);   // left: wet
  EXPECT_EQ(map_.coverage_at({1200.0, 400.0}), 0.0);  // right: dry
  EXPECT_EQ(map_.coverage_at({-5.0, 400.0}), 0.0);    // off the map
}

// Drops down to 0.3 texels still wet about their own area (on average over where they lie), so
// the wet fraction stays true (measured 1.09 of it at 0.6 mm, 0.85-0.94 from 0.7 mm up).
TEST_F(GlassWaterMapTest, DropsOfEverySizeWetTheirOwnArea) {
  for (const double radius : {0.6, 0.7, 0.85, 1.0, 1.5, 3.0}) {
    RandomStream random(11, static_cast<std::uint64_t>(radius * 10));
    std::vector<Metaball> drops;
    for (int k = 0; k < 400; ++k) {  // far enough apart not to merge
      drops.push_back({static_cast<float>(40.0 + 36.0 * (k % 38) + random.uniform(0.0, 2.0)),
                       static_cast<float>(40.0 + 36.0 * (k / 38) + random.uniform(0.0, 2.0)),
                       static_cast<float>(radius)});
    }
    build(drops);
    double wet_mm2 = 0.0;
    for (std::size_t t = 0; t < map_.rgba.size() / 4; ++t)
      wet_mm2 += map_.rgba[t * 4 + 3] / 255.0 * kTexelMm * kTexelMm;
    const double expected = drops.size() * M_PI * radius * radius;
    EXPECT_NEAR(wet_mm2 / expected, 1.0, 0.2) << "radius " << radius << " mm";
  }
}

// Random drops of every size, some moved, some gone, some new, frame after frame: the map built
// incrementally is the map built whole, byte for byte, and only the rows that changed are named.
TEST_F(GlassWaterMapTest, IncrementalBuildsEqualWholeBuilds) {
  RandomStream random(5, 0);
  std::vector<Metaball> drops;
  for (int k = 0; k < 3000; ++k) {
    drops.push_back({static_cast<float>(random.uniform(0.0, 1520.0)),
                     static_cast<float>(random.uniform(0.0, 762.0)),
                     static_cast<float>(random.uniform(0.3, 4.0))});
  }
  build(drops);
  GlassWaterMap previous;
  for (int frame = 0; frame < 12; ++frame) {
    for (int k = 0; k < 40; ++k) {  // some move, some shrink, some go, some arrive
      Metaball& m = drops[static_cast<std::size_t>(random.uniform(0.0, drops.size()))];
      m.v_mm += 2.0f;
      m.radius_mm *= 0.9f;
    }
    drops.resize(drops.size() - 20);
    for (int k = 0; k < 25; ++k) {
      drops.push_back({static_cast<float>(random.uniform(0.0, 1520.0)),
                       static_cast<float>(random.uniform(0.0, 762.0)),
                       static_cast<float>(random.uniform(0.5, 3.0))});
    }
    previous = map_;
    build(drops);
    EXPECT_GT(builder_.tiles_rebuilt(), 0);
    EXPECT_LT(builder_.tiles_rebuilt(), builder_.tiles());
    ASSERT_EQ(map_.previous_stamp, previous.stamp);
    // Outside the dirty rows nothing changed.
    for (int j = 0; j < kHeight; ++j) {
      if (j >= map_.dirty_row_begin && j < map_.dirty_row_end) continue;
      for (int i = 0; i < kWidth * 4; ++i) {
        ASSERT_EQ(map_.rgba[static_cast<std::size_t>(j) * kWidth * 4 + i],
                  previous.rgba[static_cast<std::size_t>(j) * kWidth * 4 + i]);
      }
    }
    GlassWaterMapBuilder fresh(glass_);
    GlassWaterMap whole;
    fresh.build(drops, whole);
    ASSERT_EQ(whole.rgba, map_.rgba) << "frame " << frame;
    EXPECT_EQ(whole.wet_fraction, map_.wet_fraction);
  }
}

TEST_F(GlassWaterMapTest, AMapFromElsewhereIsBuiltWhole) {
  build({kIsolated});
  GlassWaterMap other;
  builder_.build({kIsolated}, other);  // not the map of the last call
  EXPECT_EQ(builder_.tiles_rebuilt(), builder_.tiles());
  EXPECT_EQ(other.rgba, map_.rgba);
  EXPECT_EQ(other.previous_stamp, 0u);
}

}  // namespace
}  // namespace downpour::sim
