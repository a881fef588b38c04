#include "server/render/passes/road_pass.hpp"

#include <algorithm>
#include <cmath>

#include <glm/trigonometric.hpp>

#include "server/render/cpu/camera.hpp"
#include "server/render/cpu/light_set.hpp"
#include "server/render/cpu/relief.hpp"
#include "server/render/renderer.hpp"
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

RoadPass::RoadPass(SharedResources& shared, RoadPart part)
    : decl_{std::string(kRoadPassNames[part == RoadPart::kNearInLayer ? 1
                                       : part == RoadPart::kFar       ? 3
                                                                      : 0]),
            {Resource::kRoadWater, Resource::kRoadReflection, Resource::kLampMap},
            part == RoadPart::kNearInLayer
                ? std::vector<Resource>{Resource::kRoadLayer}
                : std::vector<Resource>{Resource::kViewColour, Resource::kViewDepth},
            {DepthTest::kNearer, true, Blend::kOff, true, false, 0b110}},
      part_(part),
      scale_(part == RoadPart::kNearInLayer ? kRoadLayerScale : 1),
      reliefs_(shared.reliefs) {
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
    depth_clip_[p] = programs_[p].uniform("u_depth_clip");
    if (p % kVariants < 3) continue;  // (the relief's)
    programs_[p].uniform("u_horizon_directions").set(shared.horizon_directions);
    programs_[p]
        .uniform("u_relief_depth_m")
        .set(glm::vec2(relief::kAsphaltDepthM, relief::kSettsDepthM));
  }
}

namespace {

// The plane (xyz . p + w at least 0 is kept: gl_ClipDistance[2]) that keeps what lies nearer than
// depth_m on the view's depth, d(p) = n . p + w0 (the view looks down its -z), or, `beyond`, what
// lies further.
glm::vec4 depth_plane(const glm::mat4& view, float depth_m, bool beyond) {
  const glm::vec3 n = -glm::vec3(view[0][2], view[1][2], view[2][2]);
  const float w0 = -view[3][2];
  return beyond ? glm::vec4(n, w0 - depth_m) : glm::vec4(-n, depth_m - w0);
}

// The pixel angle of a view's rows (rad).
float pixel_rad(const FrameContext& frame) {
  return 2.0f * std::tan(glm::radians(frame.camera.fov_y_deg) * 0.5f) /
         static_cast<float>(std::max(frame.spec.height, 1));
}

}  // namespace

float RoadPass::relief_reach_m(const FrameContext& frame, int scale) {
  // A pixel's footprint on the road, d away from a camera h over it, for a pixel angle a, is
  // d a sqrt(1 + d^2 / h^2) along the view: about d^2 a / h where it is long. The setts' shadows
  // fade out from 4 cm (road_surface.glsl), reached at d = sqrt(0.04 h / a); a tenth further for
  // safety (the shader's footprint, the sum of two derivatives, is the longer one, and the split
  // measures d from the camera, not along the ground: both only bring the fade nearer).
  const float pixel = pixel_rad(frame) * static_cast<float>(scale);
  const float height = std::max(
      frame.camera.position.z - static_cast<float>(frame.scene.vehicle.position_m.z), 0.5f);
  return 1.1f * std::sqrt(kSettsResolvedToM * height / pixel);
}

float RoadPass::near_reach_m(const FrameContext& frame) {
  // A point at the near part's end on the view's depth lies this far at the view's corners.
  const float end = layer_split_m(frame) + kLayerOverlapM;
  const float tan_y = std::tan(glm::radians(frame.camera.fov_y_deg) * 0.5f);
  const float tan_x = tan_y * static_cast<float>(frame.spec.width) /
                      static_cast<float>(std::max(frame.spec.height, 1));
  return end * std::sqrt(1.0f + tan_x * tan_x + tan_y * tan_y);
}

float RoadPass::layer_split_m(const FrameContext& frame) {
  return kLayerTexelM / (static_cast<float>(kRoadLayerScale) * pixel_rad(frame));
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
  const float reach = relief_ ? relief_reach_m(frame, scale_) : 0.0f;
  const bool beams =
      frame.lights && std::any_of(frame.lights->begin(), frame.lights->end(), [&](const Light& l) {
        if (l.vehicle >= 0 || l.kind != LampKind::kHeadlight) return false;
        const glm::vec2 ahead = glm::normalize(glm::vec2(l.direction) + glm::vec2(1e-6f, 0.0f));
        const glm::vec2 lit = glm::vec2(l.position) + ahead * kBeamsReachRoadM;
        return glm::length(lit - glm::vec2(frame.camera.position)) < reach;
      });
  const bool relief_on = relief_ && (std::max({sun.r, sun.g, sun.b}) > kReliefSunFrom || beams);
  const std::size_t plain =
      static_cast<std::size_t>(lamps_build(frame)) * kVariants + (ripples  ? 2
                                                                  : mirror ? 1
                                                                           : 0);
  const glm::mat4 view_proj = frame.camera.projection * frame.camera.view;
  // (The far part's triangles are small, and llvmpipe shades whole blocks of pixels around each:
  // the far part at the coarser levels from a quarter of their distances took 0.84-0.86 of the
  // time in turn with the view's own, in a 640x360 ROAD. The near part takes the same scale. The
  // chunk that reaches across the split is finer in the near part, which goes on from its camera,
  // than in the far one, which takes its levels from the split (ChunkedMesh::draw_visible): on a
  // curve their edges meet a chord's sag apart at the split, 3 cm where 8 m rows bend around
  // 300 m, under a pixel; on a junction's tight turn (20 m) 40 cm, as the far part's chunks
  // beyond 21 m already were.)
  const float detail =
      frame.detail_distance_scale * (part_ == RoadPart::kWhole ? 1.0f : kPartsDetailScale);
  // This part's range of the chunks' distances (m from the camera), and its plane on the view's
  // depth.
  const float split = layer_split_m(frame);
  float from_m = 0.0f, to_m = 1e30f;
  glm::vec4 depth_clip(0.0f, 0.0f, 0.0f, 1.0f);
  if (part_ == RoadPart::kNearInLayer) {
    depth_clip = depth_plane(frame.camera.view, split + kLayerOverlapM, false);
    to_m = near_reach_m(frame);
  } else if (part_ == RoadPart::kFar) {
    depth_clip = depth_plane(frame.camera.view, split, true);
    from_m = split;
  }
  // Relief shadows: the near road with them, the rest without (llvmpipe would fetch the horizon
  // maps on every pixel of one draw, even where a branch skips them). Where a pixel covers many
  // of the relief's texels the shader takes their shadows' mean; the near part ends where that
  // holds everywhere.
  glm::vec2 mean_lit(1.0f);
  if (relief_on) {
    const float elevation = std::asin(std::clamp(frame.atmosphere.sun_direction.z, 0.0f, 1.0f));
    mean_lit = {reliefs_->asphalt_horizon.mean_lit(elevation),
                reliefs_->setts_horizon.mean_lit(elevation)};
  }
  // (This part's: the far part of a view whose relief ends before it draws none.)
  const bool relief_here = relief_on && reach > from_m;
  drew_relief_ = relief_here;
  if (relief_here) {
    programs_[plain + 3].use();
    mean_lit_[plain + 3].set(mean_lit);
    near_split_[plain + 3].set(glm::vec2(reach, 1.0f));
    depth_clip_[plain + 3].set(depth_clip);
    // (Only the chunks that reach into the near part, and then those that reach beyond it.)
    frame.world->road.draw_visible(view_proj, frame.camera.position, detail, from_m,
                                   std::min(reach, to_m), from_m);
  }
  if (relief_here && reach >= to_m) return;  // (the relief's draw held all of this part)
  programs_[plain].use();
  mean_lit_[plain].set(mean_lit);
  near_split_[plain].set(glm::vec2(relief_here ? reach : 0.0f, -1.0f));
  depth_clip_[plain].set(depth_clip);
  // (The part's levels from its own start, as the relief's draw: both meet the same surface.)
  frame.world->road.draw_visible(view_proj, frame.camera.position, detail,
                                 relief_here ? std::max(reach, from_m) : from_m, to_m, from_m);
}

RoadCompositePass::RoadCompositePass()
    : decl_{std::string(kRoadPassNames[2]),
            {Resource::kRoadLayer},
            {Resource::kViewColour, Resource::kViewDepth},
            {DepthTest::kNearer, true, Blend::kOff, true, false, 0b100}},
      program_("road_composite.vert", "road_composite.frag"),
      u_depth_clip_(program_.uniform("u_depth_clip")),
      u_inv_viewport_(program_.uniform("u_inv_viewport")) {}

void RoadCompositePass::execute(const FrameContext& frame, const FrameResources& r) {
  program_.use();
  // The near part's triangles at its levels (the surface the layer holds), up to the split and a
  // hundredth beyond it, under the far part (road_far): no pixel between. (Never past the layer's
  // own end, kLayerOverlapM beyond the split, where a far split of a narrow view lies 200 m out.)
  const float split = RoadPass::layer_split_m(frame);
  u_depth_clip_.set(depth_plane(
      frame.camera.view, split + std::min(0.01f * split, 0.5f * RoadPass::kLayerOverlapM), false));
  u_inv_viewport_.set(1.0f / glm::vec2(r.view_colour.width, r.view_colour.height));
  frame.world->road.draw_visible(frame.camera.projection * frame.camera.view, frame.camera.position,
                                 frame.detail_distance_scale * RoadPass::kPartsDetailScale, 0.0f,
                                 RoadPass::near_reach_m(frame));
}

}  // namespace downpour::render
