// The lamps' glows and the lamp map's rings, on the CPU: a lamp that shines at the camera glares,
// one that points away or cuts its beam off under the camera hardly does; the rings lie ahead of
// the camera on whole cells.
#include <cmath>
#include <vector>

#include <gtest/gtest.h>
#include <glm/trigonometric.hpp>

#include "server/render/cpu/light_set.hpp"
#include "server/render/lamp_map.hpp"
#include "server/render/passes/lamp_glow_pass.hpp"

namespace downpour::render {
namespace {

Light oncoming_beam(float x, bool dipped) {
  Light l;
  l.position = {x, 0.0f, 0.7f};
  const float down = glm::radians(dipped ? 1.0f : 0.0f);
  l.direction = {-std::cos(down), 0.0f, -std::sin(down)};
  l.intensity_cd = glm::vec3(dipped ? 15000.0f : 50000.0f);
  l.cos_inner = std::cos(glm::radians(dipped ? 10.0f : 6.0f));
  l.cos_outer = std::cos(glm::radians(dipped ? 30.0f : 20.0f));
  l.low_beam = dipped;
  return l;
}

TEST(LampGlowTest, ABeamAtTheCameraGlaresAndOneCutOffOrTurnedAwayHardlyDoes) {
  const glm::vec3 eye(0.0f, 0.0f, 1.2f);
  const float tan_half = std::tan(glm::radians(25.0f));
  // An oncoming car 60 m off on high beam, then on low beam (the eye above its cut-off), then a
  // car ahead driving away, all at night's exposure.
  Light away = oncoming_beam(60.0f, true);
  away.direction = -away.direction;
  std::vector<LampGlow> glows;
  lamp_glows({oncoming_beam(60.0f, false), oncoming_beam(60.0f, true), away}, eye, tan_half, 360,
             0.05f, 0.0f, glows);
  ASSERT_EQ(glows.size(), 2u) << "a lamp pointing away shows no lens";
  const LampGlow& high = glows[0];
  const LampGlow& low = glows[1];
  EXPECT_GT(high.colour_strength.w, 0.25f) << "high beams dazzle (14 lux at the eye)";
  EXPECT_LT(low.colour_strength.w, 0.05f * high.colour_strength.w) << "dipped: stray light only";
  EXPECT_GT(high.position_size.w, 3.0f * low.position_size.w);
  EXPECT_GE(low.position_size.w, 1.5f) << "but the lens still shows";
  EXPECT_GT(low.core, 0.9f);
  EXPECT_LT(glm::length(glm::vec3(high.position_size) - eye), 60.0f) << "towards the camera";
  // Fog takes the glare with distance.
  std::vector<LampGlow> fogged;
  lamp_glows({oncoming_beam(60.0f, false)}, eye, tan_half, 360, 0.05f, 0.03f, fogged);
  EXPECT_LT(fogged[0].colour_strength.w, 0.25f * high.colour_strength.w);
}

TEST(LampGlowTest, TheLampMapsRingsLieAheadOfTheCameraOnWholeCells) {
  const glm::vec3 camera(103.3f, -47.9f, 1.2f);
  const glm::vec3 forward = glm::normalize(glm::vec3(1.0f, 1.0f, -0.1f));
  const LampRings r = place_lamp_rings(camera, forward);
  for (int l = 0; l < LampRings::kRings; ++l) {
    const glm::vec4 w = r.windows[l];
    const float side = 1.0f / w.z;
    EXPECT_FLOAT_EQ(w.w, LampRings::kCellM[l]);
    EXPECT_NEAR(side, LampRings::kCellM[l] * LampRings::kCells, 1e-3f);
    EXPECT_NEAR(std::remainder(w.x, w.w), 0.0f, 1e-3f) << "on whole cells";
    EXPECT_NEAR(std::remainder(w.y, w.w), 0.0f, 1e-3f);
    const glm::vec2 uv = (glm::vec2(camera) - glm::vec2(w)) * w.z;
    EXPECT_GT(uv.x, 0.0f);
    EXPECT_LT(uv.x, 0.5f) << "the camera in the ring's back half, looking into it";
    EXPECT_LT(uv.y, 0.5f);
    const glm::vec2 ahead =
        (glm::vec2(camera) + glm::vec2(forward) * 0.5f * side - glm::vec2(w)) * w.z;
    EXPECT_GT(ahead.x, 0.5f);
    EXPECT_LT(ahead.x, 1.0f);
  }
}

}  // namespace
}  // namespace downpour::render
