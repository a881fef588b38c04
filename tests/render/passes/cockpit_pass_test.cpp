// The cabin's kept pictures (CockpitPass, RendererOptions::keep_cabin): a frame whose cabin is
// copied from a kept picture is the frame that draws it, byte for byte; another light draws (and
// keeps) anew, but not every frame where the light keeps changing; and the light rounded for
// keeping is not seen.
#include <cstdio>
#include <memory>

#include <gtest/gtest.h>

#include "server/model/default_models.hpp"
#include "server/model/gltf_model.hpp"
#include "server/render/renderer.hpp"
#include "tests/render/render_fixture.hpp"
#include "tests/render/windshield_fixture.hpp"
#include "tests/support/png_io.hpp"

namespace downpour::render {
namespace {

using testing::RgbaImage;

constexpr int kWidth = 320;
constexpr int kHeight = 180;

RgbaImage draw(Renderer& renderer, const sim::SceneState& scene) {
  const sim::ViewSpec spec = sim::view_spec(sim::View::kCockpit, kWidth, kHeight);
  return {kWidth, kHeight, render_image(renderer, spec, scene)};
}

// The highway 10 s in under heavy rain, and under a low sun in a nearly clear sky, turned 40
// degrees so that the sun falls across the dashboard from the side.
sim::SceneState rainy() { return testing::highway_scene(25.0, 0.95); }
sim::SceneState sunny() {
  sim::SceneState s = testing::highway_scene(0.0, 0.1, false);
  s.weather.sun_altitude_deg = 20.0;
  s.vehicle.rotation.yaw_deg += 40.0;
  return s;
}

TEST(CockpitPassTest, AKeptCabinIsTheDrawnCabin) {
  auto renderer = Renderer::create({.keep_cabin = true});
  const RgbaImage rain_drawn = draw(*renderer, rainy());
  Renderer::CabinCounts c = renderer->cabin_counts();
  EXPECT_EQ(c.drawn, 1u);
  EXPECT_EQ(c.kept, 1u);
  EXPECT_EQ(c.restored, 0u);
  // The same light: the picture copied back (the frame before has been read back, so its draw of
  // the kept picture is done), and the same bytes.
  const RgbaImage rain_restored = draw(*renderer, rainy());
  c = renderer->cabin_counts();
  EXPECT_EQ(c.restored, 1u);
  EXPECT_EQ(c.drawn, 1u);
  EXPECT_TRUE(rain_restored.pixels == rain_drawn.pixels);
  // Another light: drawn and kept, then restored; the first light's picture is still kept.
  const RgbaImage sun_drawn = draw(*renderer, sunny());
  const RgbaImage sun_restored = draw(*renderer, sunny());
  const RgbaImage rain_again = draw(*renderer, rainy());
  c = renderer->cabin_counts();
  EXPECT_EQ(c.drawn, 2u);
  EXPECT_EQ(c.kept, 2u);
  EXPECT_EQ(c.restored, 3u);
  EXPECT_TRUE(sun_restored.pixels == sun_drawn.pixels);
  EXPECT_TRUE(rain_again.pixels == rain_drawn.pixels);
  EXPECT_FALSE(sun_drawn.pixels == rain_drawn.pixels);
}

// A cabin the session names (a glTF model) is kept apart from the built-in one, and another model
// is drawn anew, even where it takes the place (and the address) of one let go of.
TEST(CockpitPassTest, ANamedCabinIsKeptApartAndAnotherIsDrawnAnew) {
  auto renderer = Renderer::create({.keep_cabin = true});
  sim::SceneState s = rainy();
  draw(*renderer, s);  // the built-in cabin, kept
  draw(*renderer, s);  // and restored
  auto named = [&s] {
    return std::make_shared<const model::VehicleModel>(model::read_gltf(
        model::write_glb(model::default_cabin(s.glass)), model::ModelKind::kCabin));
  };
  s.ego.cabin_model = named();
  const RgbaImage drawn = draw(*renderer, s);
  Renderer::CabinCounts c = renderer->cabin_counts();
  EXPECT_EQ(c.drawn, 2u);
  EXPECT_EQ(c.kept, 2u);
  EXPECT_TRUE(draw(*renderer, s).pixels == drawn.pixels);
  EXPECT_EQ(renderer->cabin_counts().restored, 2u);
  for (int k = 0; k < 3; ++k) {  // a new model each time, the last one let go of first
    s.ego.cabin_model.reset();
    s.ego.cabin_model = named();
    draw(*renderer, s);
  }
  c = renderer->cabin_counts();
  EXPECT_EQ(c.drawn, 5u);
  EXPECT_EQ(c.restored, 2u);
  EXPECT_EQ(c.kept, 3u);  // the first new one; the next two wait for it to be used (four draws)
}

// Where the light changes every frame, a picture is kept at most every few draws, not each frame
// (which would draw the cabin twice a frame).
TEST(CockpitPassTest, WhereTheLightChangesEveryFrameFewPicturesAreKept) {
  auto renderer = Renderer::create({.keep_cabin = true});
  sim::SceneState s = sunny();
  for (int k = 0; k < 8; ++k) {
    s.vehicle.rotation.yaw_deg += 10.0;  // the sun across the dashboard from another side
    draw(*renderer, s);
  }
  const Renderer::CabinCounts c = renderer->cabin_counts();
  EXPECT_EQ(c.drawn, 8u);
  EXPECT_EQ(c.restored, 0u);
  EXPECT_EQ(c.kept, 2u);  // the first frame's and the fifth's
}

// The light rounded for keeping (a sun direction to 1/64, radiances to 1/128) against the light as
// it is, under the low sun across the dashboard: the same picture but for a level here and there.
// Each renderer is made and closed in turn (a context is current on the thread that made it).
TEST(CockpitPassTest, TheRoundedLightIsNotSeen) {
  RgbaImage kept, exact;
  {
    auto renderer = Renderer::create({.keep_cabin = true});
    kept = draw(*renderer, sunny());
  }
  {
    auto renderer = Renderer::create({.keep_cabin = false});
    exact = draw(*renderer, sunny());
    draw(*renderer, sunny());
    const Renderer::CabinCounts c = renderer->cabin_counts();
    EXPECT_EQ(c.restored, 0u);
    EXPECT_EQ(c.kept, 0u);
  }
  testing::write_png(::testing::TempDir() + "cabin_kept.png", kept);
  testing::write_png(::testing::TempDir() + "cabin_exact.png", exact);
  const double db = testing::psnr(kept, exact);
  std::printf("the cabin's light rounded against exact: PSNR %.1f dB\n", db);
  EXPECT_GT(db, 50.0);
}

}  // namespace
}  // namespace downpour::render
