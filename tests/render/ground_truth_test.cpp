// A frame's ground truth (sim::Outputs): the clean frame is the frame of the same scene without its
// water, the mask says where and how much the water changed the frame, and the depth is each
// pixel's distance along the view's axis.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include <gtest/gtest.h>

#include "server/encode/ground_truth.hpp"
#include "server/encode/image_decoder.hpp"
#include "server/render/cpu/camera.hpp"
#include "server/render/cpu/client_background.hpp"
#include "tests/render/render_fixture.hpp"
#include "tests/render/windshield_fixture.hpp"

namespace downpour::render {
namespace {

using testing::RgbaImage;

// The scene with no water anywhere: none on the glass, no rain in the air, no spray.
sim::SceneState without_any_water(sim::SceneState scene) {
  scene.windshield.surface.reset();
  scene.windshield.metaballs.clear();
  scene.windshield.glass_wet_fraction = 0.0;
  scene.rain.drops.clear();
  scene.rain.splashes.clear();
  scene.spray.reset();
  return scene;
}

int channel_difference(const RgbaImage& a, const RgbaImage& b, std::size_t pixel) {
  int d = 0;
  for (int c = 0; c < 3; ++c)
    d = std::max(d, std::abs(a.pixels[pixel * 4 + c] - b.pixels[pixel * 4 + c]));
  return d;
}

class GroundTruthTest : public testing::RenderTest {};

// The highway in heavy rain, the wipers sweeping, through the windshield: the frame, its clean
// frame, its mask (through the PNG the wire carries) and its depth, from one render.
TEST_F(GroundTruthTest, CleanMaskAndDepthDescribeTheFrame) {
  constexpr int kW = 640, kH = 360;
  const sim::SceneState wet = testing::highway_scene(25.0);
  ASSERT_GT(wet.windshield.glass_wet_fraction, 0.0);
  ASSERT_FALSE(wet.rain.drops.empty());
  sim::ViewSpec spec = sim::view_spec(sim::View::kCockpit, kW, kH);
  spec.outputs = {true, true, true};
  GroundTruthPixels truth;
  const RgbaImage frame{kW, kH, renderer().render_image(spec, wet, truth)};
  ASSERT_EQ(truth.clean.size(), frame.pixels.size());
  ASSERT_EQ(truth.depth_m.size(), static_cast<std::size_t>(kW) * kH);
  const RgbaImage clean{kW, kH, truth.clean};

  // The clean frame is the scene drawn without its water (the blades stay).
  sim::ViewSpec plain_spec = spec;
  plain_spec.outputs = {};
  const RgbaImage dry = render(plain_spec, without_any_water(wet));
  const double clean_psnr = testing::psnr(clean, dry);
  const double wet_psnr = testing::psnr(frame, dry);
  std::printf("clean frame against the scene drawn dry: %.1f dB (the frame: %.1f dB)\n", clean_psnr,
              wet_psnr);
  EXPECT_GT(clean_psnr, 45.0);
  EXPECT_LT(wet_psnr, 35.0);

  // The mask as the wire carries it: 0 exactly where the frames agree within 2 levels, above 0
  // wherever the water changed a pixel by 8 or more.
  const std::string png = encode::water_mask_png(frame.pixels, clean.pixels, kW, kH);
  // (water_mask_png takes rows bottom-up and writes the PNG top-down; these images' rows are
  // top-down, so the PNG is upside down, and decoded bottom-up it is the right way up again)
  const encode::BgrxPixels mask = encode::decode_bgrx(png, kW, kH);
  std::size_t agree_but_masked = 0, changed_not_masked = 0, masked = 0, changed = 0;
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      const std::size_t at = static_cast<std::size_t>(y) * kW + x;
      const int m = mask.bgrx[at * 4];
      const int d = channel_difference(frame, clean, at);
      if (d <= encode::kWaterMaskFloor && m != 0) ++agree_but_masked;
      if (d >= 8 && m == 0) ++changed_not_masked;
      if (m > 0) ++masked;
      if (d >= 8) ++changed;
    }
  }
  std::printf("the water changed %.1f%% of the pixels by 8 levels or more; %.1f%% are masked\n",
              100.0 * changed / (kW * kH), 100.0 * masked / (kW * kH));
  EXPECT_EQ(agree_but_masked, 0u);
  EXPECT_EQ(changed_not_masked, 0u);
  EXPECT_GT(changed, static_cast<std::size_t>(kW * kH / 20));

  // The cabin (nearer than half a metre) keeps the water off it: the mask is 0 over nearly all of
  // it (its edges blur under the glass's layer).
  std::size_t cabin = 0, cabin_masked = 0;
  for (std::size_t i = 0; i < truth.depth_m.size(); ++i) {
    if (truth.depth_m[i] <= 0.0f || truth.depth_m[i] > 0.5f) continue;
    ++cabin;
    if (channel_difference(frame, clean, i) > encode::kWaterMaskFloor) ++cabin_masked;
  }
  std::printf("cabin pixels: %zu, %.2f%% of them masked\n", cabin, 100.0 * cabin_masked / cabin);
  ASSERT_GT(cabin, static_cast<std::size_t>(kW * kH / 10));
  EXPECT_LT(cabin_masked * 50, cabin);

  // The depth: the sky is 0; the road ahead lies where the ground plane under the car puts it.
  const Camera camera = make_camera(spec, wet.vehicle, &wet.weather);
  const PictureCamera axes = picture_camera(camera);
  const GroundPlane ground = ground_plane(camera, wet.vehicle);
  std::vector<double> errors;
  std::size_t sky = 0, above_horizon = 0;
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      const float d = truth.depth_m[static_cast<std::size_t>(y) * kW + x];
      const float gx = (x + 0.5f) / kW * 2.0f - 1.0f, gy = 1.0f - (y + 0.5f) / kH * 2.0f;
      const float g = ground_depth_m(axes, ground, gx, gy);
      // Above the horizon, outside the cabin: the sky, and far terrain.
      if (g == 0.0f && (d == 0.0f || d > 1.0f)) above_horizon += 1, sky += d == 0.0f;
      // The road ahead, 8 to 30 m (not the bonnet, the cabin or a vehicle ahead).
      if (std::abs(gx) < 0.2f && g > 8.0f && g < 30.0f && d > 3.0f)
        errors.push_back(std::abs(d - g) / g);
    }
  }
  ASSERT_GT(errors.size(), 100u);
  std::nth_element(errors.begin(), errors.begin() + errors.size() / 2, errors.end());
  const double median_error = errors[errors.size() / 2];
  std::printf(
      "above the horizon: %.1f%% sky (depth 0); the road ahead: %.2f%% from the ground "
      "plane\n",
      100.0 * sky / above_horizon, 100.0 * median_error);
  EXPECT_GT(sky * 2, above_horizon);
  EXPECT_LT(median_error, 0.05);  // the road falls across its width; the ground is the wheels

  // To look at: the frame, its clean frame, the mask (levels x4) and the depth (0-60 m, grey).
  RgbaImage mask_image{kW, kH, std::vector<std::uint8_t>(frame.pixels.size(), 255)};
  RgbaImage depth_image = mask_image;
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      const std::size_t at = static_cast<std::size_t>(y) * kW + x;
      const int m = mask.bgrx[at * 4];
      const float d = truth.depth_m[at];
      const auto shade = static_cast<std::uint8_t>(d > 0.0f ? std::min(d / 60.0f, 1.0f) * 255 : 0);
      for (int c = 0; c < 3; ++c) {
        mask_image.pixels[at * 4 + c] = static_cast<std::uint8_t>(std::min(m * 4, 255));
        depth_image.pixels[at * 4 + c] = shade;
      }
    }
  }
  testing::write_png(::testing::TempDir() + "ground_truth_frame.png", frame);
  testing::write_png(::testing::TempDir() + "ground_truth_clean.png", clean);
  testing::write_png(::testing::TempDir() + "ground_truth_mask.png", mask_image);
  testing::write_png(::testing::TempDir() + "ground_truth_depth.png", depth_image);
}

// Over a client's picture the clean frame is the picture itself, the rain and the glass's water
// left out.
TEST_F(GroundTruthTest, OverAPictureTheCleanFrameIsThePicture) {
  constexpr int kW = 320, kH = 180;
  sim::SceneState scene = testing::highway_scene(25.0);
  auto picture = std::make_shared<sim::ClientImage>();
  picture->width = kW;
  picture->height = kH;
  picture->bgrx.resize(static_cast<std::size_t>(kW) * kH * 4);
  for (std::size_t i = 0; i < picture->bgrx.size(); i += 4) {
    const std::size_t p = i / 4;
    picture->bgrx[i] = static_cast<std::uint8_t>(40 + p % kW / 4);      // blue
    picture->bgrx[i + 1] = static_cast<std::uint8_t>(60 + p / kW / 2);  // green
    picture->bgrx[i + 2] = 120;                                         // red
    picture->bgrx[i + 3] = 255;
  }
  picture->serial = 1;
  scene.client_images[static_cast<int>(sim::View::kCockpit)] = picture;
  sim::ViewSpec spec = sim::view_spec(sim::View::kCockpit, kW, kH);
  spec.background = sim::Background::kClient;
  spec.outputs.clean = spec.outputs.water_mask = true;
  GroundTruthPixels truth;
  const RgbaImage frame{kW, kH, renderer().render_image(spec, scene, truth)};
  // Where the blades are not, it is the picture; and all of it is the picture drawn dry.
  sim::ViewSpec plain_spec = spec;
  plain_spec.outputs = {};
  const RgbaImage dry = render(plain_spec, without_any_water(scene));
  std::size_t off_picture = 0, off_dry = 0, changed = 0;
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      const std::size_t at = static_cast<std::size_t>(y) * kW + x;
      const std::uint8_t* c = &truth.clean[at * 4];
      const std::uint8_t* p = &picture->bgrx[(static_cast<std::size_t>(kH - 1 - y) * kW + x) * 4];
      if (c[0] != p[2] || c[1] != p[1] || c[2] != p[0]) ++off_picture;
      if (!std::equal(c, c + 3, &dry.pixels[at * 4])) ++off_dry;
      changed += channel_difference(frame, {kW, kH, truth.clean}, at) >= 8;
    }
  }
  std::printf(
      "clean pixels off the picture (the blades): %zu, off the picture drawn dry: %zu; the "
      "water changed %zu\n",
      off_picture, off_dry, changed);
  EXPECT_EQ(off_dry, 0u);
  EXPECT_LT(off_picture * 50, static_cast<std::size_t>(kW) * kH);
  EXPECT_GT(changed, static_cast<std::size_t>(kW * kH / 20));
}

}  // namespace
}  // namespace downpour::render
