// The render tests' common fixture: one renderer (a GL context and every shader compiled) per
// test suite, and a way to draw a view of a scene into an RGBA image.
#pragma once

#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>

#include <gtest/gtest.h>

#include "server/render/renderer.hpp"
#include "server/sim/simulation.hpp"
#include "tests/render/windshield_fixture.hpp"
#include "tests/support/png_io.hpp"

namespace downpour::testing {

class RenderTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { renderer_ = render::Renderer::create({}); }
  static void TearDownTestSuite() { renderer_.reset(); }

  static sim::ViewSpec view_spec(sim::View view, int width, int height) {
    return sim::view_spec(view, width, height);
  }
  // A view from a camera of its own: at `position` in the ego car's frame, turned by yaw and
  // pitch (degrees; pitch positive looks down), with a vertical field of view of fov_deg.
  static sim::ViewSpec posed_view(sim::View view, int width, int height, glm::dvec3 position,
                                  double yaw_deg, double pitch_deg, double fov_deg) {
    sim::ViewSpec spec = sim::view_spec(view, width, height);
    sim::CameraPose pose;
    pose.position_m = position;
    pose.rotation.yaw_deg = yaw_deg;
    pose.rotation.pitch_deg = pitch_deg;
    spec.camera = pose;
    spec.fov_deg = fov_deg;
    return spec;
  }
  static RgbaImage render(const sim::ViewSpec& spec, const sim::SceneState& scene) {
    return {spec.width, spec.height, render::render_image(*renderer_, spec, scene)};
  }
  static render::Renderer& renderer() { return *renderer_; }

  // The image against tests/golden/<name>, within 32 dB of PSNR; with DOWNPOUR_UPDATE_GOLDEN set,
  // rewrites the golden file instead (then look at it).
  static void expect_golden(const RgbaImage& image, const std::string& name) {
    const std::string golden = std::string(DOWNPOUR_GOLDEN_DIR) + "/" + name;
    if (std::getenv("DOWNPOUR_UPDATE_GOLDEN")) {
      write_png(golden, image);
      GTEST_SKIP() << "wrote " << golden;
    }
    ASSERT_TRUE(std::filesystem::exists(golden))
        << golden << " is missing; run with DOWNPOUR_UPDATE_GOLDEN=1";
    const double db = psnr(image, read_png(golden));
    if (db < 32.0) {
      const std::string actual = ::testing::TempDir() + "actual_" + name;
      write_png(actual, image);
      ADD_FAILURE() << name << ": PSNR " << db
                    << " dB against the golden image; this render: " << actual;
    }
  }

  // The highway scene with dry glass, its water not simulated: for tests that bring their own.
  // No streaks in the air either: these tests measure the glass against a still background.
  static const sim::SceneState& dry_scene() {
    static const sim::SceneState scene = [] {
      sim::SceneState s = highway_scene(25.0, 0.95, false);
      s.rain.drops.clear();
      s.rain.splashes.clear();
      return s;
    }();
    return scene;
  }
  // The dry scene with this water on its glass (its surface built from the metaballs).
  static RgbaImage render_water(const sim::WindshieldState& water, const sim::ViewSpec& spec) {
    sim::SceneState scene = dry_scene();
    scene.windshield = water;
    build_surface(scene.windshield, scene.glass);
    return render(spec, scene);
  }

 private:
  static inline std::unique_ptr<render::Renderer> renderer_;
};

}  // namespace downpour::testing
