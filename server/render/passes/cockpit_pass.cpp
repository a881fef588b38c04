#include "server/render/passes/cockpit_pass.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>

#include <glm/gtc/type_ptr.hpp>
#include <glm/mat3x3.hpp>

#include "server/model/default_models.hpp"
#include "server/render/render_targets.hpp"
#include "server/sim/pose.hpp"

namespace downpour::render {
namespace {

constexpr std::size_t kKeptPictures = 4;  // a view size and a light each: a few sessions' worth
// Draws after keeping a picture that no frame has used yet before another is kept: where the light
// changes every frame (a sharp turn in the sun), keeping would draw the cabin twice a frame.
constexpr std::uint64_t kKeepAgainAfter = 4;

// x rounded to 1/128 of itself (7 bits of its mantissa): a radiance a cached cabin is lit with.
float rounded_relative(float x) {
  if (x == 0.0f || !std::isfinite(x)) return x;
  int e = 0;
  const float m = std::frexp(x, &e);
  return std::ldexp(std::round(std::ldexp(m, 7)), e - 7);
}
glm::vec3 rounded_relative(glm::vec3 v) {
  return {rounded_relative(v.x), rounded_relative(v.y), rounded_relative(v.z)};
}
// A unit direction rounded to 1/64 a component (about a degree) and made unit again.
glm::vec3 rounded_direction(glm::vec3 d) {
  const glm::vec3 r = glm::round(d * 64.0f) / 64.0f;
  const float len = glm::length(r);
  return len > 0.0f ? r / len : d;
}

}  // namespace

// A kept picture: the cabin on a cleared view, colour and depth, and the fence after its draw
// (restored from only once passed, so that the copy never waits for the draw).
struct CockpitPass::Kept {
  Key key;
  Texture colour, depth;
  Framebuffer fbo;
  GLsync drawn = nullptr;
  std::uint64_t serial = 0;  // counts().kept when it was kept
  ~Kept() {
    if (drawn) glDeleteSync(drawn);
  }
  bool ready() {
    if (!drawn) return true;
    GLint status = GL_UNSIGNALED;
    glGetSynciv(drawn, GL_SYNC_STATUS, 1, nullptr, &status);
    if (status != GL_SIGNALED) return false;
    glDeleteSync(drawn);
    drawn = nullptr;
    return true;
  }
};

CockpitPass::CockpitPass(SharedResources&, bool keep_pictures)
    : program_("cabin.vert", "cockpit.frag"),
      uniforms_(program_),
      u_clip_from_car_(program_.uniform("u_clip_from_car")),
      u_eye_(program_.uniform("u_eye")),
      u_up_(program_.uniform("u_up")),
      u_sun_dir_(program_.uniform("u_sun_dir")),
      u_ambient_(program_.uniform("u_ambient")),
      u_sun_radiance_(program_.uniform("u_sun_radiance")),
      u_sky_horizon_(program_.uniform("u_sky_horizon")),
      interior_(model::default_cabin(built_for_)),
      keep_pictures_(keep_pictures) {}

CockpitPass::~CockpitPass() = default;

void CockpitPass::release() { kept_.clear(); }

const ModelMesh& CockpitPass::mesh_of(const FrameContext& frame) {
  // The cabin is built around the scene's glass (remade in the rare case that it changes).
  const sim::GlassConfig& glass = frame.scene.glass;
  if (!model::same_cabin(glass, built_for_)) {
    built_for_ = glass;
    interior_ = ModelMesh(model::default_cabin(built_for_));
  }
  named_.prune();
  const sim::ModelPtr& cabin = frame.scene.ego.cabin_model;
  return cabin ? named_.get(cabin) : interior_;
}

CockpitPass::Key CockpitPass::key_of(const FrameContext& frame, const ModelMesh& mesh) const {
  Key k;
  k.mesh = mesh.serial;
  k.width = frame.spec.width;
  k.height = frame.spec.height;
  const glm::mat4 clip(glm::dmat4(frame.camera.projection) * frame.camera.view_vehicle);
  const glm::dmat3 to_car = glm::transpose(glm::dmat3(sim::vehicle_to_world(frame.scene.vehicle)));
  glm::vec3 light[6] = {glm::vec3(frame.camera.position_vehicle),
                        glm::vec3(to_car * glm::dvec3(0.0, 0.0, 1.0)),
                        glm::vec3(to_car * glm::dvec3(frame.atmosphere.sun_direction)),
                        frame.atmosphere.ambient,
                        frame.atmosphere.sun_radiance,
                        frame.atmosphere.sky_horizon};
  if (keep_pictures_) {
    light[1] = rounded_direction(light[1]);
    light[2] = rounded_direction(light[2]);
    for (int i = 3; i < 6; ++i) light[i] = rounded_relative(light[i]);
  }
  // Without sun (by night), its direction is nothing to the picture: not in the key.
  if (light[4] == glm::vec3(0.0f)) light[2] = glm::vec3(0.0f);
  std::memcpy(k.numbers.data(), glm::value_ptr(clip), 16 * sizeof(float));
  for (int i = 0; i < 6; ++i) std::memcpy(&k.numbers[16 + 3 * i], &light[i], 3 * sizeof(float));
  return k;
}

void CockpitPass::draw(const ModelMesh& mesh, const Key& key) {
  program_.use();
  glm::mat4 clip;
  std::memcpy(glm::value_ptr(clip), key.numbers.data(), 16 * sizeof(float));
  auto at = [&key](int i) {
    return glm::vec3(key.numbers[16 + 3 * i], key.numbers[17 + 3 * i], key.numbers[18 + 3 * i]);
  };
  u_clip_from_car_.set(clip);
  u_eye_.set(at(0));
  u_up_.set(at(1));
  u_sun_dir_.set(at(2));
  u_ambient_.set(at(3));
  u_sun_radiance_.set(at(4));
  u_sky_horizon_.set(at(5));
  mesh.draw(uniforms_, glm::mat4(1.0f), 0.0, false);
}

bool CockpitPass::restore(const FrameContext& frame, const FrameResources& resources) {
  restored_into_ = 0;  // (one left by a frame that failed before its cabin)
  if (!keep_pictures_) return false;
  const ModelMesh& mesh = mesh_of(frame);
  const Key key = key_of(frame, mesh);
  auto it = std::find_if(kept_.begin(), kept_.end(), [&](const auto& k) { return k->key == key; });
  if (it == kept_.end() || !(*it)->ready()) return false;
  const Kept& kept = **it;
  if (kept.serial == counts_.kept) last_kept_used_ = true;
  glCopyImageSubData(kept.colour.id(), GL_TEXTURE_2D, 0, 0, 0, 0, resources.view_colour.texture,
                     GL_TEXTURE_2D, 0, 0, 0, 0, key.width, key.height, 1);
  glCopyImageSubData(kept.depth.id(), GL_TEXTURE_2D, 0, 0, 0, 0, resources.view_depth.texture,
                     GL_TEXTURE_2D, 0, 0, 0, 0, key.width, key.height, 1);
  std::rotate(kept_.begin(), it, it + 1);  // the most recently used first
  restored_into_ = resources.view_colour.texture;
  ++counts_.restored;
  return true;
}

void CockpitPass::execute(const FrameContext& frame, const FrameResources& resources) {
  if (restored_into_ != 0 && restored_into_ == resources.view_colour.texture) {
    restored_into_ = 0;
    return;
  }
  restored_into_ = 0;
  const ModelMesh& mesh = mesh_of(frame);
  const Key key = key_of(frame, mesh);
  draw(mesh, key);
  ++counts_.drawn;
  if (!keep_pictures_ ||
      std::any_of(kept_.begin(), kept_.end(), [&](const auto& k) { return k->key == key; }))
    return;
  if (!last_kept_used_ && counts_.drawn < drawn_at_keep_ + kKeepAgainAfter) return;
  // A picture to keep: the cabin again, on a cleared target of its own, as the view's start has it
  // (in the textures of the least recently used, where they are of its size).
  auto kept = std::make_unique<Kept>();
  if (kept_.size() >= kKeptPictures) {
    Kept& last = *kept_.back();
    if (last.key.width == key.width && last.key.height == key.height) {
      kept->colour = std::move(last.colour);
      kept->depth = std::move(last.depth);
      kept->fbo = std::move(last.fbo);
    }
    kept_.pop_back();
  }
  kept->key = key;
  kept->serial = ++counts_.kept;
  if (!kept->fbo.id()) {
    kept->colour = make_texture_2d(GL_RGBA8, key.width, key.height);
    kept->depth = make_texture_2d(GL_DEPTH_COMPONENT32F, key.width, key.height);
    kept->fbo = framebuffer_with(kept->colour.id(), kept->depth.id());
  }
  glBindFramebuffer(GL_FRAMEBUFFER, kept->fbo.id());
  clear_view(kept->fbo.id());
  apply_own_state();
  draw(mesh, key);
  kept->drawn = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
  glBindFramebuffer(GL_FRAMEBUFFER, resources.view_fbo);
  kept_.insert(kept_.begin(), std::move(kept));
  last_kept_used_ = false;
  drawn_at_keep_ = counts_.drawn;
}

}  // namespace downpour::render
