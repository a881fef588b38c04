#include "server/render/environment_probe.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <stdexcept>

#include <glm/gtc/matrix_transform.hpp>

#include "server/render/cpu/atmosphere.hpp"
#include "server/render/cpu/shader_interface.hpp"
#include "server/render/gl/render_state.hpp"

namespace downpour::render {
namespace {

// The resolve of a face and its mip levels: no depth, no blending.
constexpr RenderState kResolveState{DepthTest::kOff, false, Blend::kOff};
// The lamps over it: spots hidden by the face's depth, added up, their size set by the shader.
constexpr RenderState kLampsState{
    DepthTest::kNearerOrEqual, false, Blend::kAdd, true, false, 0, true};

// GL's cube faces: the direction each looks along and its up, so that a face drawn into a
// framebuffer (rows from the bottom) is the face a lookup along a world direction reads.
struct FaceAxes {
  glm::vec3 forward, up;
};
constexpr std::array<FaceAxes, EnvironmentProbe::kFaces> kFaceAxes{{
    {{1.0f, 0.0f, 0.0f}, {0.0f, -1.0f, 0.0f}},
    {{-1.0f, 0.0f, 0.0f}, {0.0f, -1.0f, 0.0f}},
    {{0.0f, 1.0f, 0.0f}, {0.0f, 0.0f, 1.0f}},
    {{0.0f, -1.0f, 0.0f}, {0.0f, 0.0f, -1.0f}},
    {{0.0f, 0.0f, 1.0f}, {0.0f, -1.0f, 0.0f}},
    {{0.0f, 0.0f, -1.0f}, {0.0f, -1.0f, 0.0f}},
}};

constexpr float kNearM = 0.05f;

// The faces refreshed between the front's turns, in order: the ground (the bonnet and the road,
// which most drops show at their top), left, right and the sky.
constexpr int kBetween[] = {5, 2, 3, 4};
constexpr int kBetweenCount = static_cast<int>(std::size(kBetween));

}  // namespace

EnvironmentPrograms::EnvironmentPrograms()
    : resolve_("fullscreen.vert", "environment_resolve.frag"),
      u_face_(resolve_.uniform("u_face")),
      u_texel_rad_(resolve_.uniform("u_texel_rad")),
      u_sun_energy_(resolve_.uniform("u_sun_energy")),
      lamps_("environment_lamps.vert", "environment_lamps.frag"),
      u_lamp_texel_rad_(lamps_.uniform("u_texel_rad")),
      level_("fullscreen.vert", "environment_level.frag"),
      u_layer_(level_.uniform("u_layer")) {
  empty_vao_ = make_vertex_array();
  // A lookup near a face's edge filters across into its neighbour.
  glEnable(GL_TEXTURE_CUBE_MAP_SEAMLESS);
}

EnvironmentProbe::EnvironmentProbe(EnvironmentConfig config) : config_(config) {
  const int size = config_.face_size;
  if (size < 4 || size > 2048) throw std::invalid_argument("environment face size out of range");
  for (int s = size; s > 1; s /= 2) ++levels_;
  GLuint id = 0;
  glCreateTextures(GL_TEXTURE_CUBE_MAP, 1, &id);
  cube_ = Texture(id);
  glTextureStorage2D(id, levels_, GL_RGBA16F, size, size);
  glTextureParameteri(id, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_LINEAR);
  glTextureParameteri(id, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  GLuint view = 0;
  glGenTextures(1, &view);
  glTextureView(view, GL_TEXTURE_2D_ARRAY, id, GL_RGBA16F, 0, levels_, 0, kFaces);
  levels_view_ = Texture(view);
  face_colour_ = make_texture_2d(GL_RGBA8, size, size);
  face_depth_ = make_texture_2d(GL_DEPTH_COMPONENT32F, size, size);
  glTextureParameteri(face_depth_.id(), GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTextureParameteri(face_depth_.id(), GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  GLuint fbos[2] = {0, 0};
  glCreateFramebuffers(2, fbos);
  face_fbo_ = Framebuffer(fbos[0]);
  resolve_fbo_ = Framebuffer(fbos[1]);
  glNamedFramebufferTexture(fbos[0], GL_COLOR_ATTACHMENT0, face_colour_.id(), 0);
  glNamedFramebufferTexture(fbos[0], GL_DEPTH_ATTACHMENT, face_depth_.id(), 0);
  if (glCheckNamedFramebufferStatus(fbos[0], GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
    throw std::runtime_error("environment face framebuffer incomplete");
}

glm::vec3 EnvironmentProbe::direction(int face, glm::vec2 xy) {
  const FaceAxes& a = kFaceAxes.at(static_cast<std::size_t>(face));
  return a.forward + xy.x * glm::cross(a.forward, a.up) + xy.y * a.up;
}

Camera EnvironmentProbe::face_camera(int face, const glm::vec3& centre, const glm::mat3& axes) {
  const FaceAxes& a = kFaceAxes.at(static_cast<std::size_t>(face));
  Camera c;
  c.position = centre;
  c.fov_y_deg = 90.0f;
  c.near_m = kNearM;
  c.tan_half_fov_x = c.tan_half_fov_y = 1.0;
  c.view = glm::lookAt(centre, centre + axes * a.forward, axes * a.up);
  // Reversed-Z with an infinite far plane, as every view's (camera.cpp).
  c.projection = glm::mat4(0.0f);
  c.projection[0][0] = 1.0f;
  c.projection[1][1] = 1.0f;
  c.projection[2][3] = -1.0f;
  c.projection[3][2] = kNearM;
  return c;
}

glm::mat3 EnvironmentProbe::from_world(const glm::mat4& vehicle_to_world) const {
  return fixed_ ? glm::mat3(1.0f) : glm::transpose(glm::mat3(vehicle_to_world));
}

void EnvironmentProbe::resolve(const EnvironmentPrograms& p, int face, const glm::mat3& axes,
                               const Atmosphere& atmosphere, int lamps) {
  const GLuint fbo = resolve_fbo_.id();
  glNamedFramebufferTextureLayer(fbo, GL_COLOR_ATTACHMENT0, cube_.id(), 0, face);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glViewport(0, 0, config_.face_size, config_.face_size);
  glBindTextureUnit(texture_unit::kViewColour, face_colour_.id());
  glBindTextureUnit(texture_unit::kViewDepth, face_depth_.id());
  apply(kResolveState);
  const FaceAxes& a = kFaceAxes.at(static_cast<std::size_t>(face));
  p.resolve_.use();
  p.u_face_.set(glm::mat4(axes * glm::mat3(glm::cross(a.forward, a.up), a.up, a.forward)));
  const float texel_rad = 2.0f / static_cast<float>(config_.face_size);
  p.u_texel_rad_.set(texel_rad);
  // Irradiance, in the radiance a white card facing it shows (times pi): the sun's disc, less the
  // cloud that hides it.
  p.u_sun_energy_.set(atmosphere.sun_radiance * static_cast<float>(M_PI) *
                      (1.0f - atmosphere.overcast));
  glBindVertexArray(p.empty_vao_.id());
  glDrawArrays(GL_TRIANGLES, 0, 3);

  // The lamps: each a spot a texel wide holding its light at the probe, hidden by what stands in
  // front of it.
  if (lamps > 0) {
    // Their depth test against the face's depth (attached for this draw alone: the resolve above
    // reads it).
    glNamedFramebufferTexture(fbo, GL_DEPTH_ATTACHMENT, face_depth_.id(), 0);
    p.lamps_.use();
    p.u_lamp_texel_rad_.set(texel_rad);
    apply(kLampsState);
    glDrawArrays(GL_POINTS, 0, lamps);
    glNamedFramebufferTexture(fbo, GL_DEPTH_ATTACHMENT, 0, 0);
  }
  apply(kResolveState);
  make_levels(p, face);
}

// A face's mip levels, each texel the mean of the four under it (glGenerateMipmap would redo all
// six faces, and costs llvmpipe some milliseconds at that).
void EnvironmentProbe::make_levels(const EnvironmentPrograms& p, int face) {
  const GLuint fbo = resolve_fbo_.id();
  p.level_.use();
  p.u_layer_.set(face);
  glBindTextureUnit(texture_unit::kEnvironmentLevels, levels_view_.id());
  glBindVertexArray(p.empty_vao_.id());
  for (int level = 1; level < levels_; ++level) {
    // Read the level above alone (no loop between the level read and the level written).
    glTextureParameteri(levels_view_.id(), GL_TEXTURE_BASE_LEVEL, level - 1);
    glTextureParameteri(levels_view_.id(), GL_TEXTURE_MAX_LEVEL, level - 1);
    glNamedFramebufferTextureLayer(fbo, GL_COLOR_ATTACHMENT0, cube_.id(), level, face);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    const int size = std::max(config_.face_size >> level, 1);
    glViewport(0, 0, size, size);
    glDrawArrays(GL_TRIANGLES, 0, 3);
  }
  glTextureParameteri(levels_view_.id(), GL_TEXTURE_BASE_LEVEL, 0);
  glTextureParameteri(levels_view_.id(), GL_TEXTURE_MAX_LEVEL, levels_ - 1);
}

int EnvironmentProbe::ticks_until_each_face_alone(const EnvironmentConfig& config) {
  // The front's first turn on its own is the second (turn 2); the faces between have turns 1, 3,
  // 5, ..., the last of them 2 * kBetweenCount - 1, at its tick_ (the session's tick less one).
  return 1 + (2 * kBetweenCount - 1) * std::max(config.ticks_per_face, 1);
}

const std::vector<EnvironmentProbe::Due>& EnvironmentProbe::faces_due(double time_s,
                                                                      bool complete) {
  std::vector<Due>& due = due_;
  due.clear();
  if (fixed_) return due;
  if (!drawn_) {
    for (int f = 0; f < kFaces; ++f) due.push_back({f, complete || f == 0});
    drawn_ = true;
    tick_ = 1;  // the front's next turn comes after the others' first
  } else if (time_s != last_time_s_) {
    // Every ticks_per_face ticks a face: the front (+x) every other time, kBetween's in turn
    // between.
    const int every = std::max(config_.ticks_per_face, 1);
    if (tick_ % every == 0) {
      const int turn = tick_ / every;
      due.push_back({turn % 2 == 0 ? 0 : kBetween[(turn / 2) % kBetweenCount], true});
    }
    ++tick_;
  }
  last_time_s_ = time_s;
  return due;
}

void EnvironmentProbe::set_fixed(const std::array<std::vector<glm::vec3>, kFaces>& faces) {
  const std::size_t texels = static_cast<std::size_t>(config_.face_size) * config_.face_size;
  std::vector<glm::vec4> rgba(texels);
  for (int f = 0; f < kFaces; ++f) {
    if (faces[f].size() != texels)
      throw std::invalid_argument("environment face of the wrong size");
    for (std::size_t i = 0; i < texels; ++i) rgba[i] = glm::vec4(faces[f][i], 1.0f);
    glTextureSubImage3D(cube_.id(), 0, 0, 0, f, config_.face_size, config_.face_size, 1, GL_RGBA,
                        GL_FLOAT, rgba.data());
  }
  glGenerateTextureMipmap(cube_.id());
  fixed_ = true;
  drawn_ = true;
}

}  // namespace downpour::render
