// The render tests' common fixture: one renderer (a GL context and every shader compiled) per
// test suite, and a way to draw a view of a scene into an RGBA image.
#pragma once

#include <memory>

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
    return {view, width, height, 85, 0.0, std::nullopt};
  }
  static RgbaImage render(const sim::ViewSpec& spec, const sim::SceneState& scene) {
    return {spec.width, spec.height, render::render_image(*renderer_, spec, scene)};
  }
  static render::Renderer& renderer() { return *renderer_; }

  // The highway scene with dry glass, its water not simulated: for tests that bring their own.
  static const sim::SceneState& dry_scene() {
    static const sim::SceneState scene = highway_scene(25.0, 0.95, false);
    return scene;
  }
  static RgbaImage render_water(const sim::WindshieldState& water, const sim::ViewSpec& spec) {
    sim::SceneState scene = dry_scene();
    scene.windshield = water;
    return render(spec, scene);
  }

 private:
  static inline std::unique_ptr<render::Renderer> renderer_;
};

}  // namespace downpour::testing
