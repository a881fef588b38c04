// The rain layer on the CPU (no GL): a box hides the streaks behind it and not those in front of
// it, on the texels inside its outline; the composite's runs of tiles cover every texel with rain
// and, for rain in one part of the view, little else; the cabin's tiles are left out or put apart;
// a lamp's light leaves nothing for the next frame; long streaks at every slope, up to the view's
// edges, stay in the layer; far streaks are thinned, to the same opacity, the same drops in every
// frame and in every copy of the box.
#include "server/render/cpu/rain_layer.hpp"

#include "server/render/cpu/cabin_tiles.hpp"

#include <gtest/gtest.h>
#include <glm/ext/matrix_transform.hpp>

namespace downpour::render {
namespace {

constexpr int kWidth = 160;
constexpr int kHeight = 90;

// A camera at the world's origin looking along +x (z up), 60 degrees high, and a box of rain
// around it with no fall speed to speak of (dots, not streaks).
RainLayerInputs inputs() {
  RainLayerInputs in;
  in.view = glm::lookAt(glm::vec3(0.0f), glm::vec3(1.0f, 0.0f, 0.0f), glm::vec3(0.0f, 0.0f, 1.0f));
  in.tan_half_fov_y = std::tan(glm::radians(30.0));
  in.tan_half_fov_x = in.tan_half_fov_y * kWidth / kHeight;
  in.exposure_s = 0.0;
  in.light = glm::vec3(0.6f);
  in.haze = glm::vec3(0.5f);
  in.pixels_per_texel = 2.0f;
  return in;
}

sim::RainState rain_at(const std::vector<glm::vec3>& positions) {
  sim::RainState rain;
  rain.box_half_m = glm::vec3(40.0f, 40.0f, 10.0f);
  for (const glm::vec3& p : positions) rain.drops.emplace_back(p, 3.0f);
  return rain;
}

// A column of drops at distance x, straight ahead, from z = -0.6 to 0.6 m.
std::vector<glm::vec3> column(float x) {
  std::vector<glm::vec3> out;
  for (int i = 0; i <= 24; ++i) out.emplace_back(x, 0.0f, -0.6f + 0.05f * i);
  return out;
}

std::uint32_t alpha_at_centre(const RainLayer& layer) {
  return layer.colour()[static_cast<std::size_t>(kHeight / 2) * kWidth + kWidth / 2] >> 24;
}

TEST(RainLayerTest, ABoxHidesTheDropsBehindItAndNotThoseInFront) {
  // A box 1 m either side of the view's centre line, 8 to 9 m ahead.
  const RainOccluder box{glm::dmat4(1.0), glm::vec3(8.0f, -1.0f, -1.0f),
                         glm::vec3(9.0f, 1.0f, 1.0f)};
  RainLayerInputs in = inputs();
  RainLayer layer;
  for (const float x : {4.0f, 20.0f}) {
    SCOPED_TRACE(x);
    layer.build(rain_at(column(x)), in, kWidth, kHeight);
    EXPECT_GT(alpha_at_centre(layer), 0u) << "no box: the drops show";
    in.occluders = std::span<const RainOccluder>(&box, 1);
    layer.build(rain_at(column(x)), in, kWidth, kHeight);
    if (x < 8.0f) {
      EXPECT_GT(alpha_at_centre(layer), 0u) << "in front of the box";
    } else {
      EXPECT_EQ(alpha_at_centre(layer), 0u) << "behind the box";
    }
    in.occluders = {};
  }
}

// Drops on a grid over the whole view, from 2 to 20 m ahead.
std::vector<glm::vec3> everywhere() {
  std::vector<glm::vec3> out;
  for (int i = 0; i < 4000; ++i) {
    const float x = 2.0f + 18.0f * static_cast<float>(i % 97) / 96.0f;
    const float across = (static_cast<float>(i % 61) / 30.0f - 1.0f) * 1.8f * x;
    const float up = (static_cast<float>(i % 37) / 18.0f - 1.0f) * 0.6f * x;
    out.emplace_back(x, across, up);
  }
  return out;
}

TEST(RainLayerTest, ALampsLightLeavesNothingForTheNextFrame) {
  // A lamp at the camera shining ahead (the lit texels are kept apart from the rest).
  RainLamp lamp;
  lamp.position = glm::vec3(0.0f);
  lamp.axis = glm::vec3(0.0f, 0.0f, -1.0f);
  lamp.intensity = 50.0f;
  lamp.cos_outer = 0.8f;
  lamp.cos_inner = 0.95f;
  RainLayerInputs dark = inputs(), lit = inputs();
  lit.lamp_colour = glm::vec3(1.0f, 0.2f, 0.2f);
  lit.lamps = std::span<const RainLamp>(&lamp, 1);
  const sim::RainState rain = rain_at(everywhere());
  RainLayer fresh_dark, fresh_lit, layer;
  fresh_dark.build(rain, dark, kWidth, kHeight);
  fresh_lit.build(rain, lit, kWidth, kHeight);
  ASSERT_NE(fresh_dark.colour(), fresh_lit.colour()) << "the lamp lights the drops";
  layer.build(rain, lit, kWidth, kHeight);
  layer.build(rain, dark, kWidth, kHeight);
  EXPECT_EQ(layer.colour(), fresh_dark.colour()) << "no lamp after a lit frame";
  layer.build(rain, lit, kWidth, kHeight);
  layer.build(rain, lit, kWidth, kHeight);
  EXPECT_EQ(layer.colour(), fresh_lit.colour()) << "a lit frame after a lit frame";
}

TEST(RainLayerTest, LongStreaksAtEverySlopeStayInTheLayer) {
  // The camera driving at 40 m/s through drops falling slantwise, exposed for a tenth of a second:
  // streaks tens of texels long at every angle, many of them crossing the view's edges (the
  // sanitizers' build checks every write).
  RainLayerInputs in = inputs();
  in.exposure_s = 0.1;
  in.camera_velocity = glm::dvec3(40.0, 3.0, 0.0);
  sim::RainState rain = rain_at(everywhere());
  rain.fall_direction = glm::normalize(glm::vec3(0.2f, 0.5f, -1.0f));
  rain.wind_mps = glm::vec3(0.0f, -6.0f, 0.0f);
  RainLayer layer;
  in.far_share = 1.0f;  // every streak
  EXPECT_GT(layer.build(rain, in, kWidth, kHeight), 3000u);
  int corners[4] = {};
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      if (layer.colour()[static_cast<std::size_t>(y) * kWidth + x] != 0u)
        ++corners[(y < kHeight / 2 ? 0 : 2) + (x < kWidth / 2 ? 0 : 1)];
    }
  }
  for (int q = 0; q < 4; ++q) EXPECT_GT(corners[q], kWidth * kHeight / 16) << "quarter " << q;
}

// Drops scattered over the view from 25 to 30 m ahead, where the far streaks are thinned.
std::vector<glm::vec3> far_off(int count = 3000) {
  std::vector<glm::vec3> out;
  for (int i = 0; i < count; ++i) {
    const float x = 25.0f + 5.0f * static_cast<float>(i % 101) / 100.0f;
    const float across = (static_cast<float>(i % 67) / 33.0f - 1.0f) * 0.95f * x;
    const float up = (static_cast<float>(i % 43) / 21.0f - 1.0f) * 0.28f * x;  // under the top
    out.emplace_back(x, across, up);
  }
  return out;
}

std::uint64_t opacity_sum(const RainLayer& layer) {
  std::uint64_t sum = 0;
  for (const std::uint32_t c : layer.colour()) sum += c >> 24;
  return sum;
}

TEST(RainLayerTest, FarStreaksAreThinnedToTheSameOpacityOnAverage) {
  static_assert(RainLayerInputs::kThinToM <= 25.0f, "the drops lie where the share is far_share");
  const sim::RainState rain = rain_at(far_off());
  RainLayerInputs all = inputs(), thinned = inputs();
  all.far_share = 1.0f;
  ASSERT_LT(thinned.far_share, 0.75f) << "the default thins them";
  RainLayer every, fewer;
  const std::uint32_t drawn_all = every.build(rain, all, kWidth, kHeight);
  const std::uint32_t drawn = fewer.build(rain, thinned, kWidth, kHeight);
  EXPECT_GT(drawn_all, 2900u) << "nearly all in view";
  // (those that fade in too: a few percent more than the share)
  EXPECT_GT(drawn, thinned.far_share * drawn_all);
  EXPECT_LT(drawn, (thinned.far_share + 0.1) * drawn_all);
  // Each streak drawn the more opaque: the layer as opaque as before, summed over its texels.
  const double ratio =
      static_cast<double>(opacity_sum(fewer)) / static_cast<double>(opacity_sum(every));
  EXPECT_NEAR(ratio, 1.0, 0.06);
}

// Summed over the texels, how much two layers' opacities differ.
std::uint64_t opacity_change(const RainLayer& a, const RainLayer& b) {
  std::uint64_t changed = 0;
  for (std::size_t k = 0; k < a.colour().size(); ++k) {
    changed += static_cast<std::uint64_t>(
        std::abs(static_cast<int>(a.colour()[k] >> 24) - static_cast<int>(b.colour()[k] >> 24)));
  }
  return changed;
}

TEST(RainLayerTest, TheSameFarDropsAreDrawnFromFrameToFrame) {
  // The drops a little lower in the next frame (2 mm: a hundredth of a texel at 30 m), on both
  // threads (two from 4,096 drops): nearly the same layer, not another half of them drawn, which
  // would change it by most of its opacity.
  const sim::RainState now = rain_at(far_off(5000));
  sim::RainState later = now;
  for (glm::vec4& d : later.drops) d.z -= 0.002f;
  RainLayer a, b;
  a.build(now, inputs(), kWidth, kHeight);
  b.build(later, inputs(), kWidth, kHeight);
  EXPECT_LT(static_cast<double>(opacity_change(a, b)), 0.1 * static_cast<double>(opacity_sum(a)));
}

TEST(RainLayerTest, ADropThatWrapsAcrossTheBoxIsDrawnAsBefore) {
  // The box's centre 30 m to the left, so that its right side lies on the view's centre line, and
  // drops just inside that side; then the same drops a box's width to the left, past its other
  // side, where the copy of the box to their right draws them where they were (as it draws a drop
  // that wrapped across the side). The same streaks must be drawn: a drop's number is the same in
  // every copy.
  const std::vector<glm::vec3> inside = far_off(5000);
  sim::RainState before;
  before.origin_m = glm::dvec3(0.0, 30.0, 0.0);
  before.box_half_m = glm::vec3(40.0f, 30.0f, 10.0f);
  sim::RainState after = before;
  for (const glm::vec3& p : inside) {
    const float y = std::abs(p.y) * 0.1f;  // 0 to 3 m left of the centre line
    before.drops.emplace_back(p.x, y - 30.0f, p.z, 3.0f);
    after.drops.emplace_back(p.x, y + 30.0f, p.z, 3.0f);
  }
  RainLayer a, b;
  a.build(before, inputs(), kWidth, kHeight);
  b.build(after, inputs(), kWidth, kHeight);
  ASSERT_GT(opacity_sum(a), 0u);
  EXPECT_LT(static_cast<double>(opacity_change(a, b)), 0.01 * static_cast<double>(opacity_sum(a)));
}

TEST(RainLayerTest, TheRunsCoverEveryTexelWithRainAndLittleElse) {
  // Drops in the upper right part of the view only, 10 m ahead.
  std::vector<glm::vec3> drops;
  for (int i = 0; i < 200; ++i)
    drops.emplace_back(10.0f, -2.0f - 0.02f * i, 1.5f + 0.01f * (i % 50));
  RainLayer layer;
  layer.build(rain_at(drops), inputs(), kWidth, kHeight);
  int lit = 0, covered = 0;
  for (int y = 0; y < kHeight; ++y) {
    for (int x = 0; x < kWidth; ++x) {
      bool in_run = false;
      for (const RainLayer::Bounds& r : layer.runs())
        in_run = in_run || (x >= r.x0 && x < r.x1 && y >= r.y0 && y < r.y1);
      covered += in_run;
      if (layer.colour()[static_cast<std::size_t>(y) * kWidth + x] == 0u) continue;
      ++lit;
      EXPECT_TRUE(in_run) << x << "," << y;
    }
  }
  EXPECT_GT(lit, 20);
  EXPECT_LT(covered, kWidth * kHeight / 4) << "runs over a corner of rain, not the view";
}

TEST(RainLayerTest, TheCabinsTilesAreLeftOutOrDrawnApart) {
  // Rain over the whole view; the cabin hides the left third of the tiles and reaches into the
  // column after it.
  std::vector<glm::vec3> drops;
  for (int i = 0; i < 4000; ++i)
    drops.emplace_back(6.0f + 0.01f * (i % 7), -4.0f + 0.002f * i,
                       -3.0f + 0.0015f * ((i * 37) % 4000));
  constexpr int kTilesX = kWidth / RainLayer::kTile;
  constexpr int kTilesY = (kHeight + RainLayer::kTile - 1) / RainLayer::kTile;
  std::vector<std::uint8_t> cabin(kTilesX * kTilesY, kCabinClear);
  for (int ty = 0; ty < kTilesY; ++ty) {
    for (int tx = 0; tx < kTilesX / 3; ++tx) cabin[ty * kTilesX + tx] = kCabinHidden;
    cabin[ty * kTilesX + kTilesX / 3] = kCabinEdge;
  }
  RainLayerInputs in = inputs();
  in.cabin_tiles = cabin;
  RainLayer layer;
  layer.build(rain_at(drops), in, kWidth, kHeight);
  const std::vector<RainLayer::Bounds>& runs = layer.runs();
  ASSERT_GT(layer.clear_runs(), 0u);
  ASSERT_LT(layer.clear_runs(), runs.size()) << "some runs of edge tiles";
  int clear_tiles = 0, edge_tiles = 0;
  for (std::size_t k = 0; k < runs.size(); ++k) {
    const RainLayer::Bounds& r = runs[k];
    for (int tx = r.x0 / RainLayer::kTile; tx * RainLayer::kTile < r.x1; ++tx) {
      const std::uint8_t c = cabin[(r.y0 / RainLayer::kTile) * kTilesX + tx];
      EXPECT_NE(c, kCabinHidden) << "run " << k;
      EXPECT_EQ(c, k < layer.clear_runs() ? kCabinClear : kCabinEdge) << "run " << k;
      (c == kCabinEdge ? edge_tiles : clear_tiles) += 1;
    }
  }
  EXPECT_GT(edge_tiles, kTilesY / 2) << "most of the edge column has rain";
  EXPECT_GT(clear_tiles, (kTilesX - kTilesX / 3 - 1) * kTilesY / 2) << "most clear tiles have rain";
  // Without a cabin, every run is clear.
  in.cabin_tiles = {};
  layer.build(rain_at(drops), in, kWidth, kHeight);
  EXPECT_EQ(layer.clear_runs(), layer.runs().size());
}

}  // namespace
}  // namespace downpour::render
