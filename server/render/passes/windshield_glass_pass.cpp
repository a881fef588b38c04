#include "server/render/passes/windshield_glass_pass.hpp"

#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "server/render/wiper_blades.hpp"
#include "server/sim/pose.hpp"

namespace downpour::render {
namespace {

constexpr int kSceneCopyLevels = 3;

// The screen direction (x right, y up, unit) of a vehicle-frame direction seen by the camera.
glm::vec2 screen_direction(const FrameContext& f, const glm::dvec3& vehicle_dir) {
  const glm::vec3 view_dir =
      glm::mat3(f.camera.view) * glm::mat3(f.vehicle_to_world) * glm::vec3(vehicle_dir);
  const glm::vec2 d(view_dir);
  const float len = glm::length(d);
  return len > 1e-6f ? d / len : glm::vec2(0.0f);
}

// The glass plane's reversed-Z depth over the view as depth = dot(g, (u, v, 1)), u and v in [0, 1]
// across the view: near / t at view distance t, and 1 / t is affine over the image for a plane.
// Where the plane is behind the camera the depth comes out negative: all there is the cabin's side.
glm::vec3 glass_depth_over_view(const FrameContext& f) {
  const sim::GlassConfig& glass = f.scene.glass;
  const glm::dmat4 to_view = glm::dmat4(f.camera.view) * glm::dmat4(f.vehicle_to_world);
  const glm::dvec3 n = glm::dmat3(to_view) * glass.normal();
  const double d = glm::dot(n, glm::dvec3(to_view * glm::dvec4(glass.bottom_left_m, 1.0)));
  // A view point (x, y) in NDC at distance t is t * (x / P00, y / P11, -1): on the plane where
  // t * (n.x x / P00 + n.y y / P11 - n.z) = d.
  const double ax = n.x / f.camera.projection[0][0] / d, ay = n.y / f.camera.projection[1][1] / d;
  const double c = -n.z / d;
  const double near = f.camera.near_m;
  // x = 2u - 1, y = 2v - 1.
  return glm::vec3(near * 2.0 * ax, near * 2.0 * ay, near * (c - ax - ay));
}

}  // namespace

WindshieldGlassPass::WindshieldGlassPass(SharedResources& shared, WindshieldGlassConfig config)
    : shared_(shared),
      config_(config),
      program_("windshield_glass.vert", "windshield_glass.frag"),
      copy_program_("fullscreen.vert", "windshield_scene_copy.frag"),
      blade_program_("windshield_blade.vert", "windshield_blade.frag") {
  GLuint vao = 0;
  glCreateVertexArrays(1, &vao);
  empty_vao_ = VertexArray(vao);
  program_.set("u_background_lod", config_.background_lod);
  program_.set("u_fresnel_r0", config_.fresnel_r0);
  program_.set("u_rim_darkening", config_.rim_darkening);
  program_.set("u_rim_lean", glm::vec2(config_.rim_lean[0], config_.rim_lean[1]));
  program_.set("u_water_ior", config_.water_ior);
}

WindshieldGlassPass::SceneCopy& WindshieldGlassPass::scene_copy_for(int view_width,
                                                                    int view_height) {
  auto it = copies_.find({view_width, view_height});
  if (it == copies_.end()) {
    if (copies_.size() >= 6) copies_.clear();
    SceneCopy c;
    c.width = std::max(1, view_width / 4);  // windshield_scene_copy.frag averages 4 x 4 pixels
    c.height = std::max(1, view_height / 4);
    // Mips up to the background's level and one more: no time spent on smaller ones.
    int levels = 1;
    for (int s = std::max(c.width, c.height); s > 1 && levels < kSceneCopyLevels; s /= 2) ++levels;
    c.colour = make_texture_2d(GL_RGBA8, c.width, c.height, levels);
    glTextureParameteri(c.colour.id(), GL_TEXTURE_WRAP_S, GL_MIRRORED_REPEAT);
    glTextureParameteri(c.colour.id(), GL_TEXTURE_WRAP_T, GL_MIRRORED_REPEAT);
    GLuint fbo = 0;
    glCreateFramebuffers(1, &fbo);
    c.fbo = Framebuffer(fbo);
    glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT0, c.colour.id(), 0);
    it = copies_.emplace(std::pair(view_width, view_height), std::move(c)).first;
  }
  return it->second;
}

double camera_defocus_mm(const sim::ViewSpec& spec, const sim::GlassConfig& glass,
                         const WindshieldGlassConfig& config) {
  if (!spec.camera) return 0.0;
  const glm::dvec3 forward = sim::rotation_matrix(spec.camera->rotation)[0];
  const double facing = glm::dot(forward, glass.normal());
  if (facing <= 1e-6) return 0.0;
  const double distance_m =
      glm::dot(glass.bottom_left_m - spec.camera->position_m, glass.normal()) / facing;
  if (distance_m <= 0.0) return 0.0;
  return config.camera_aperture_mm * std::max(0.0, 1.0 - distance_m / config.camera_focus_m);
}

bool WindshieldGlassPass::needed(const FrameContext& frame) {
  const auto& blades = frame.scene.windshield.blades;
  const bool any_blade = std::any_of(blades.begin(), blades.end(), [](const sim::BladePose& b) {
    return b.length_mm > 0.0f && b.width_mm > 0.0f;
  });
  return !frame.scene.windshield.metaballs.empty() || any_blade;
}

void WindshieldGlassPass::copy_scene(const FrameContext& frame) {
  if (!needed(frame)) return;
  const int width = frame.spec.width, height = frame.spec.height;
  SceneCopy& copy = scene_copy_for(width, height);
  glBindFramebuffer(GL_FRAMEBUFFER, copy.fbo.id());
  glViewport(0, 0, copy.width, copy.height);
  glDisable(GL_DEPTH_TEST);
  copy_program_.use();
  copy_program_.set("u_texel", 1.0f / glm::vec2(width, height));
  copy_program_.set("u_glass_depth", glass_depth_over_view(frame));
  glBindTextureUnit(binding::kViewColour, frame.target_colour);
  glBindTextureUnit(binding::kViewDepth, frame.target_depth);
  shared_.fullscreen.draw();
  glGenerateTextureMipmap(copy.colour.id());
  glBindFramebuffer(GL_FRAMEBUFFER, frame.target_fbo);
  glViewport(0, 0, width, height);
}

void WindshieldGlassPass::draw(const FrameContext& frame, WindshieldWaterPass& water) {
  if (!needed(frame)) return;  // clear glass
  const int width = frame.spec.width, height = frame.spec.height;
  const sim::GlassConfig& glass = frame.scene.glass;

  // A close camera sees the drops out of focus: a mip level of the water map as wide as the blur.
  const float blur_mm =
      static_cast<float>(camera_defocus_mm(frame.spec, frame.scene.glass, config_));
  const WaterMapLayout& layout = water.layout();
  const float texel_mm = layout.extent_mm.x / static_cast<float>(layout.size.width);
  const float water_lod = std::clamp(std::log2(std::max(blur_mm / texel_mm, 1.0f)), 0.0f,
                                     static_cast<float>(water.water_map_levels() - 1));
  if (water_lod > 0.0f) water.build_mipmaps(static_cast<int>(std::ceil(water_lod)));

  const SceneCopy& copy = scene_copy_for(width, height);
  glBindFramebuffer(GL_FRAMEBUFFER, frame.target_fbo);
  glViewport(0, 0, width, height);
  program_.use();
  // The glass's corner and axes in the world.
  const glm::mat3 rotation(frame.vehicle_to_world);
  const glm::vec3 origin =
      glm::vec3(frame.vehicle_to_world * glm::vec4(glm::vec3(glass.bottom_left_m), 1.0f));
  for (ShaderProgram* p : {&program_, &blade_program_}) {
    p->set("u_glass_origin", origin);
    p->set("u_glass_u", rotation * glm::vec3(glass.u_axis()));
    p->set("u_glass_v", rotation * glm::vec3(glass.v_axis()));
  }
  program_.set("u_glass_n", rotation * glm::vec3(glass.normal()));
  program_.set("u_glass_mm", glm::vec3(glass.bottom_width_mm, glass.top_width_mm, glass.height_mm));
  program_.set("u_map_origin_mm", layout.origin_mm);
  program_.set("u_map_extent_mm", layout.extent_mm);
  program_.set("u_water_lod", water_lod);
  program_.set("u_inv_viewport", 1.0f / glm::vec2(width, height));
  // Screen offset of the lookup per unit of the deflection angle's tangent: the focal length in
  // uv units of the view (the image's size and field of view).
  const float focal = frame.camera.projection[1][1];
  const float aspect = static_cast<float>(width) / static_cast<float>(height);
  program_.set("u_refraction", 0.5f * glm::vec2(focal / aspect, focal));
  program_.set("u_screen_axes", glm::vec4(screen_direction(frame, glass.u_axis()),
                                          screen_direction(frame, glass.v_axis())));
  glBindTextureUnit(binding::kWaterMap, water.water_map());
  glBindTextureUnit(binding::kSceneBlur, copy.colour.id());

  // In front of the scene, behind the cabin (reversed-Z: nearer is greater).
  glEnable(GL_DEPTH_TEST);
  glDepthFunc(GL_GREATER);
  glDepthMask(GL_FALSE);
  glEnable(GL_BLEND);
  glBlendEquation(GL_FUNC_ADD);
  glBlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA);  // premultiplied
  glBindVertexArray(empty_vao_.id());
  if (!frame.scene.windshield.metaballs.empty()) glDrawArrays(GL_TRIANGLE_STRIP, 0, 4);
  // The blades on top, over their own footprints only.
  blade_program_.use();
  blade_program_.set("u_blur_mm", blur_mm);
  blade_program_.set("u_glass_mm",
                     glm::vec3(glass.bottom_width_mm, glass.top_width_mm, glass.height_mm));
  blade_program_.set("u_margin_mm", 2.0f * blur_mm + 4.0f);
  set_wiper_blade_uniforms(blade_program_, frame.scene.windshield.blades);
  glDrawArraysInstanced(GL_TRIANGLE_STRIP, 0, 4, 2);
  glDisable(GL_BLEND);
  glDepthMask(GL_TRUE);
}

}  // namespace downpour::render
