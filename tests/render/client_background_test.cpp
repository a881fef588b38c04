// Views over a client's picture (sim::Background::kClient): the picture comes through, the drops
// on the glass turn it over as they turn the server's own world over, and the rain is hidden by
// what the picture's depth (or, without one, the ground) puts nearer.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>
#include <vector>

#include <gtest/gtest.h>

#include "server/render/cpu/camera.hpp"
#include "server/render/cpu/client_background.hpp"
#include "server/render/cpu/glass_view.hpp"
#include "tests/render/drop_footprints.hpp"
#include "tests/render/render_fixture.hpp"
#include "tests/render/windshield_fixture.hpp"

namespace downpour::render {
namespace {

using testing::RgbaImage;

sim::ViewSpec picture_view(sim::View view, int width, int height) {
  sim::ViewSpec spec = sim::view_spec(view, width, height);
  spec.background = sim::Background::kClient;
  return spec;
}

// A rendered frame (RGBA, rows top-down) as a client's picture (rows bottom-up, as decoded).
std::shared_ptr<sim::ClientImage> as_picture(const RgbaImage& frame) {
  auto image = std::make_shared<sim::ClientImage>();
  image->width = frame.width;
  image->height = frame.height;
  image->bgrx.resize(frame.pixels.size());
  const std::size_t row = static_cast<std::size_t>(frame.width) * 4;
  for (int y = 0; y < frame.height; ++y) {
    for (std::size_t x = 0; x < row; x += 4) {  // RGBA to BGRX
      const std::uint8_t* from = &frame.pixels[y * row + x];
      std::uint8_t* to = &image->bgrx[(frame.height - 1 - y) * row + x];
      to[0] = from[2], to[1] = from[1], to[2] = from[0], to[3] = 255;
    }
  }
  static std::uint64_t serial = 0;
  image->serial = ++serial;
  return image;
}

// A picture of one colour, `level` grey.
std::shared_ptr<sim::ClientImage> flat_picture(int width, int height, std::uint8_t level) {
  RgbaImage frame{width, height,
                  std::vector<std::uint8_t>(static_cast<std::size_t>(width) * height * 4, level)};
  return as_picture(frame);
}

sim::SceneState without_water(sim::SceneState scene) {
  scene.windshield.surface.reset();
  scene.windshield.metaballs.clear();
  scene.windshield.glass_wet_fraction = 0.0;
  return scene;
}

class ClientBackgroundTest : public testing::RenderTest {};

// The picture itself comes through where nothing is added (dry glass, no rain): exactly, in every
// view that takes one.
TEST_F(ClientBackgroundTest, ThePictureComesThroughUnchanged) {
  sim::SceneState scene = without_water(testing::parked_in_rain(10.0, 3.0, 40.0, 0.3));
  const RgbaImage world = render(view_spec(sim::View::kCockpit, 320, 180), scene);
  for (const sim::View v : {sim::View::kCockpit, sim::View::kRoad, sim::View::kWindshield}) {
    const sim::ViewSpec spec = picture_view(v, 320, 180);
    scene.client_images = {};
    scene.client_images[static_cast<int>(v)] = as_picture(world);
    const RgbaImage out = render(spec, scene);
    EXPECT_GT(testing::psnr(out, world), 45.0) << sim::view_name(v);
  }
  // Before the first picture: black.
  scene.client_images = {};
  const RgbaImage none = render(picture_view(sim::View::kCockpit, 320, 180), scene);
  EXPECT_LT(testing::mean_luma(none), 0.01);
}

// The server's haze over a picture, asked for (ViewSpec::haze): what lies 400 m away takes the
// fog's colour, what lies 20 m away little of it, and the picture's sky and a view that does not
// ask stay as they are. With depth, and without one (the ground under the car).
TEST_F(ClientBackgroundTest, HazeHidesWhatThePictureShowsFarAway) {
  constexpr int kW = 320, kH = 180;
  sim::SceneState scene = testing::parked_in_rain(10.0, 0.0, 40.0, 0.8);
  scene.weather.fog_density = 0.3;
  auto picture = flat_picture(kW, kH, 60);
  // Rows bottom-up: the bottom half 20 m (left) and 400 m (right) away, the top half the sky.
  picture->depth_m.assign(static_cast<std::size_t>(kW) * kH, 0.0f);
  for (int y = 0; y < kH / 2; ++y) {
    for (int x = 0; x < kW; ++x)
      picture->depth_m[static_cast<std::size_t>(y) * kW + x] = x < kW / 2 ? 20.0f : 400.0f;
  }
  scene.client_images[static_cast<int>(sim::View::kRoad)] = picture;
  sim::ViewSpec spec = picture_view(sim::View::kRoad, kW, kH);
  const RgbaImage plain = render(spec, scene);
  spec.haze = true;
  const RgbaImage hazed = render(spec, scene);
  testing::write_png(::testing::TempDir() + "client_haze.png", hazed);
  auto change = [&](const RgbaImage& image, int x0, int y0, int x1, int y1) {
    return testing::mean_luma(image, x0, y0, x1, y1) - 60.0 / 255.0;
  };
  const double sky = change(hazed, 0, 0, kW, kH / 2), near = change(hazed, 0, kH / 2, kW / 2, kH),
               far = change(hazed, kW / 2, kH / 2, kW, kH);
  std::printf("haze over a picture of 60: the sky %+.1f levels, 20 m %+.1f, 400 m %+.1f\n",
              sky * 255, near * 255, far * 255);
  EXPECT_NEAR(change(plain, 0, 0, kW, kH) * 255, 0.0, 0.5) << "a view that does not ask";
  EXPECT_NEAR(sky * 255, 0.0, 0.5);
  EXPECT_GT(std::abs(far) * 255, 20.0);
  EXPECT_LT(std::abs(near) * 4, std::abs(far));
  // Without depth the ground under the car: its far rows (near the horizon) take more haze than
  // the near ones at the bottom.
  picture->depth_m.clear();
  picture->serial += 1000;
  const RgbaImage ground = render(spec, scene);
  const double bottom = change(ground, 0, kH - kH / 8, kW, kH);
  double nearest_horizon = 0.0;
  for (int y = kH / 2; y < kH; ++y) {  // the first rows under the horizon
    const double c = change(ground, 0, y, kW, y + 1);
    if (std::abs(c) * 255 > 1.0) {
      nearest_horizon = c;
      break;
    }
  }
  std::printf("without depth: just under the horizon %+.1f levels, the bottom rows %+.1f\n",
              nearest_horizon * 255, bottom * 255);
  EXPECT_GT(std::abs(nearest_horizon), 2.0 * std::abs(bottom));
}

// A wall 2 m away over the left half of the picture, the sky over the right: the rain falls in
// front of the sky and hardly in front of the wall (only the drops between 1.5 and 2 m).
TEST_F(ClientBackgroundTest, RainIsHiddenBehindANearWall) {
  constexpr int kW = 640, kH = 360;
  sim::SceneState scene = testing::highway_scene(25.0, 0.95, false);
  scene.spray.reset();
  auto picture = flat_picture(kW, kH, 90);
  picture->depth_m.assign(static_cast<std::size_t>(kW) * kH, 0.0f);
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW / 2; ++x) picture->depth_m[static_cast<std::size_t>(y) * kW + x] = 2.0f;
  }
  scene.client_images[static_cast<int>(sim::View::kRoad)] = picture;
  const RgbaImage out = render(picture_view(sim::View::kRoad, kW, kH), scene);
  testing::write_png(::testing::TempDir() + "client_wall.png", out);
  int left = 0, right = 0;
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      if (std::abs(testing::luma(out, x, y) - 90.0) <= 4.0) continue;
      (x < kW / 2 ? left : right) += 1;
    }
  }
  std::printf("streak pixels: %d in front of the wall, %d in front of the sky\n", left, right);
  EXPECT_GT(right, 2000);
  EXPECT_LT(left * 5, right);
}

// Without a depth the ground under the car hides the rain beyond it: the rain over the lower half
// of a ROAD picture (the road ahead, within a few metres) is sparser than over the sky.
TEST_F(ClientBackgroundTest, WithoutDepthTheGroundHidesTheRainBeyondIt) {
  constexpr int kW = 640, kH = 360;
  sim::SceneState scene = testing::highway_scene(25.0, 0.95, false);
  scene.spray.reset();
  scene.client_images[static_cast<int>(sim::View::kRoad)] = flat_picture(kW, kH, 90);
  const sim::ViewSpec spec = picture_view(sim::View::kRoad, kW, kH);
  const RgbaImage out = render(spec, scene);
  // The horizon's row in the chase camera (pitched 11 degrees down).
  const Camera camera = make_camera(spec, scene.vehicle, &scene.weather);
  const PictureCamera c = picture_camera(camera);
  const GroundPlane g = ground_plane(camera, scene.vehicle);
  int above = 0, below = 0, rows_above = 0, rows_below = 0;
  for (int y = 0; y < kH; ++y) {
    const float sy = 1.0f - 2.0f * (y + 0.5f) / kH;
    const float depth = ground_depth_m(c, g, 0.0f, sy);
    const bool near_ground = depth > 0.0f && depth < 6.0f;
    const bool sky = depth == 0.0f;
    if (!near_ground && !sky) continue;
    (sky ? rows_above : rows_below) += 1;
    for (int x = 0; x < kW; ++x) {
      if (std::abs(testing::luma(out, x, y) - 90.0) > 4.0) (sky ? above : below) += 1;
    }
  }
  ASSERT_GT(rows_above, 10);
  ASSERT_GT(rows_below, 10);
  const double a = static_cast<double>(above) / rows_above,
               b = static_cast<double>(below) / rows_below;
  std::printf("streak pixels a row: %.1f over the sky, %.1f over the ground within 6 m\n", a, b);
  EXPECT_LT(b * 2.0, a);
}

// The closed loop: the server's own COCKPIT frame of the dry glass and its depth, sent back as the
// picture, under the same water on the glass, matches the rendered frame over the glass (the cabin
// is the picture's, and its depth keeps the water off it); and the drops over the picture's sky
// show its ground at their top, as they show the world's.
TEST_F(ClientBackgroundTest, DropsTurnThePictureOverAsTheyTurnTheWorldOver) {
  constexpr int kW = 1280, kH = 720;
  const sim::SceneState wet = testing::parked_in_rain(10.0, 3.0, 40.0, 0.3);
  // The rendered frame's ground truth (sim::Outputs): its clean frame (no water on the glass, no
  // rain) and its depth are the picture.
  sim::ViewSpec rendered = view_spec(sim::View::kCockpit, kW, kH);
  rendered.outputs.clean = rendered.outputs.depth = true;
  GroundTruthPixels truth;
  const RgbaImage world{kW, kH, renderer().render_image(rendered, wet, truth)};
  const RgbaImage dry{kW, kH, truth.clean};
  auto dry_picture = as_picture(dry);
  dry_picture->depth_m.resize(truth.depth_m.size());
  for (int y = 0; y < kH; ++y) {  // rows bottom-up, as the server holds a picture's depth
    std::copy_n(&truth.depth_m[static_cast<std::size_t>(kH - 1 - y) * kW], kW,
                &dry_picture->depth_m[static_cast<std::size_t>(y) * kW]);
  }
  sim::SceneState over = wet;
  over.client_images[static_cast<int>(sim::View::kCockpit)] = dry_picture;
  const sim::ViewSpec spec = picture_view(sim::View::kCockpit, kW, kH);
  renderer().set_fixed_environment(std::nullopt);
  const RgbaImage picture = render(spec, over);
  testing::write_png(::testing::TempDir() + "client_drops.png", picture);
  testing::write_png(::testing::TempDir() + "client_drops_world.png", world);
  // Over the glass (the pixels whose rays cross it).
  const Camera camera = make_camera(rendered, wet.vehicle, &wet.weather);
  const GlassView glass(camera, wet.glass, kH);
  double sum = 0.0;
  std::size_t n = 0;
  for (int y = 0; y < kH; ++y) {
    for (int x = 0; x < kW; ++x) {
      const auto g = glass.hit((x + 0.5) / kW * 2.0 - 1.0, 1.0 - (y + 0.5) / kH * 2.0);
      if (!g || !wet.glass.contains(*g)) continue;
      for (int c = 0; c < 3; ++c) {
        const std::size_t at = (static_cast<std::size_t>(y) * kW + x) * 4 + c;
        const double d = static_cast<double>(picture.pixels[at]) - world.pixels[at];
        sum += d * d;
        ++n;
      }
    }
  }
  ASSERT_GT(n, 0u);
  const double psnr = 10.0 * std::log10(255.0 * 255.0 / std::max(sum / n, 1e-9));
  std::vector<testing::Footprint> sky;
  for (const testing::Footprint& f : testing::footprints(wet, spec, picture, dry, 0.5)) {
    if (f.lowest_dry > 120.0 && f.min_elevation > 0.04) sky.push_back(f);
  }
  double inversion = 0.0;
  for (const testing::Footprint& f : sky) inversion += f.inversion();
  inversion /= std::max<std::size_t>(sky.size(), 1);
  std::printf(
      "over the glass %.1f dB against the rendered frame; %zu drops over the sky, %.1f"
      " levels of inversion\n",
      psnr, sky.size(), inversion);
  EXPECT_GT(psnr, 30.0);
  ASSERT_GE(sky.size(), 10u);
  EXPECT_GE(inversion, 8.0);
}

}  // namespace
}  // namespace downpour::render
