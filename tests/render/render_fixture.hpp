// The render tests' common fixture: one renderer (a GL context and every shader compiled) per
// test suite, and a way to draw a view of a scene into an RGBA image.
#pragma once

#include <memory>

#include <gtest/gtest.h>

#include "server/render/renderer.hpp"
#include "server/sim/simulation.hpp"
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

 private:
  static inline std::unique_ptr<render::Renderer> renderer_;
};

}  // namespace downpour::testing
