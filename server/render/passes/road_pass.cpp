#include "server/render/passes/road_pass.hpp"

#include <algorithm>
#include <cmath>

#include <glm/trigonometric.hpp>

#include "server/render/cpu/light_set.hpp"
#include "server/render/cpu/relief.hpp"
#include "server/render/world.hpp"

namespace downpour::render {

namespace {

// Standing water (mm) from which road_surface.glsl draws a puddle, and so ripples.
constexpr float kPuddleFromMm = 0.6f;
// Direct sunlight below which the relief's shadows are not drawn: the sun's radiance at the
// ground (frame.sun_radiance's brightest channel: 1.4 under a clear high sun, 0.14 through a
// full overcast, where the sky's light alone shows).
constexpr float kReliefSunFrom = 0.1f;
// The pixel size (m) beyond which the setts' shadows are their mean (road_surface.glsl).
constexpr float kSettsResolvedToM = 0.04f;
// Where the dipped beams come down on the road: about this far ahead of the headlamps (they reach
// full intensity 10 degrees under their axis, 4 m ahead of a lamp 0.7 m up).
constexpr float kBeamsReachRoadM = 4.0f;

}  // namespace

RoadPass::RoadPass(SharedResources& shared) : reliefs_(shared.reliefs) {
  const char* const files[kVariants] = {
      "road.frag",        "road_mirror.frag",        "road_ripples.frag",
      "road_relief.frag", "road_mirror_relief.frag", "road_ripples_relief.frag"};
  programs_.reserve(2 * kVariants);
  for (const std::vector<std::string>& build : kLampBuilds) {
    for (const char* file : files) programs_.emplace_back("road.vert", file, build);
  }
  for (std::size_t p = 0; p < programs_.size(); ++p) {
    programs_[p].uniform("u_model").set(glm::mat4(1.0f));
    mean_lit_[p] = programs_[p].uniform("u_relief_mean_lit");
    near_split_[p] = programs_[p].uniform("u_near_split");
    if (p % kVariants < 3) continue;  // (the relief's)
    programs_[p].uniform("u_horizon_directions").set(shared.horizon_directions);
    programs_[p]
        .uniform("u_relief_depth_m")
        .set(glm::vec2(relief::kAsphaltDepthM, relief::kSettsDepthM));
  }
}

float RoadPass::relief_reach_m(const FrameContext& frame) {
  // A pixel's footprint on the road, d away from a camera h over it, for a pixel angle a, is
  // d a sqrt(1 + d^2 / h^2) along the view: about d^2 a / h where it is long. The setts' shadows
  // fade out from 4 cm (road_surface.glsl), reached at d = sqrt(0.04 h / a); a tenth further for
  // safety (the shader's footprint, the sum of two derivatives, is the longer one, and the split
  // measures d from the camera, not along the ground: both only bring the fade nearer).
  const float pixel_rad = 2.0f * std::tan(glm::radians(frame.camera.fov_y_deg) * 0.5f) /
                          static_cast<float>(std::max(frame.spec.height, 1));
  const float height = std::max(
      frame.camera.position.z - static_cast<float>(frame.scene.vehicle.position_m.z), 0.5f);
  return 1.1f * std::sqrt(kSettsResolvedToM * height / pixel_rad);
}

void RoadPass::execute(const FrameContext& frame, const FrameResources& resources) {
  // The mirror where the renderer drew the reflection (a film stands somewhere); ripples where,
  // besides, it rains on a puddle.
  const bool mirror = resources.transient(Resource::kRoadReflection).colour.texture != 0;
  const sim::RoadWaterImage* water = frame.scene.road_water.get();
  const bool ripples = mirror && frame.scene.weather.rain_rate_mm_h > 0.0 && water &&
                       water->max_standing_mm > kPuddleFromMm;
  const glm::vec3& sun = frame.atmosphere.sun_radiance;
  // Shadows under a sun that casts them, or at night under the ego car's beams where the camera
  // resolves them: the beams reach the road some metres ahead of the car, beyond the near road of
  // the driver's eye (under the bonnet) and of the chase camera, so those views skip it (it cost
  // the chase view 2 ms for nothing to see); a camera nearer to them draws it.
  const float reach = relief_ ? relief_reach_m(frame) : 0.0f;
  const bool beams =
      frame.lights && std::any_of(frame.lights->begin(), frame.lights->end(), [&](const Light& l) {
        if (l.vehicle >= 0 || l.kind != LampKind::kHeadlight) return false;
        const glm::vec2 ahead = glm::normalize(glm::vec2(l.direction) + glm::vec2(1e-6f, 0.0f));
        const glm::vec2 lit = glm::vec2(l.position) + ahead * kBeamsReachRoadM;
        return glm::length(lit - glm::vec2(frame.camera.position)) < reach;
      });
  drew_relief_ = relief_ && (std::max({sun.r, sun.g, sun.b}) > kReliefSunFrom || beams);
  const std::size_t plain =
      static_cast<std::size_t>(lamps_build(frame)) * kVariants + (ripples  ? 2
                                                                  : mirror ? 1
                                                                           : 0);
  const glm::mat4 view_proj = frame.camera.projection * frame.camera.view;
  // Relief shadows: the near road with them, the rest without (llvmpipe would fetch the horizon
  // maps on every pixel of one draw, even where a branch skips them). Where a pixel covers many
  // of the relief's texels the shader takes their shadows' mean; the near part ends where that
  // holds everywhere.
  glm::vec2 mean_lit(1.0f);
  if (drew_relief_) {
    const float elevation = std::asin(std::clamp(frame.atmosphere.sun_direction.z, 0.0f, 1.0f));
    mean_lit = {reliefs_->asphalt_horizon.mean_lit(elevation),
                reliefs_->setts_horizon.mean_lit(elevation)};
    programs_[plain + 3].use();
    mean_lit_[plain + 3].set(mean_lit);
    near_split_[plain + 3].set(glm::vec2(reach, 1.0f));
    // (Only the chunks that reach into the near part, and then those that reach beyond it.)
    frame.world->road.draw_visible(view_proj, frame.camera.position, frame.detail_distance_scale,
                                   0.0f, reach);
  }
  programs_[plain].use();
  mean_lit_[plain].set(mean_lit);
  near_split_[plain].set(glm::vec2(drew_relief_ ? reach : 0.0f, -1.0f));
  frame.world->road.draw_visible(view_proj, frame.camera.position, frame.detail_distance_scale,
                                 drew_relief_ ? reach : 0.0f);
}

}  // namespace downpour::render
