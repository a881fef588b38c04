#include "server/render/renderer.hpp"

#include <chrono>
#include <cstring>
#include <map>
#include <stdexcept>

#include <glm/gtc/type_ptr.hpp>

#include "server/render/frame_context.hpp"
#include "server/render/passes/cockpit_pass.hpp"
#include "server/render/passes/road_pass.hpp"
#include "server/render/passes/sky_pass.hpp"
#include "server/render/passes/terrain_pass.hpp"
#include "server/render/passes/vehicle_pass.hpp"
#include "server/render/passes/windshield_glass_pass.hpp"
#include "server/render/passes/windshield_pass.hpp"
#include "server/render/passes/windshield_water_pass.hpp"
#include "server/render/procedural_textures.hpp"
#include "server/sim/pose.hpp"

namespace downpour::render {
namespace {

constexpr int kReadbackSlots = 2;

// The std140 uniform block `FrameBlock` of common.glsl.
struct FrameBlock {
  glm::mat4 view_proj;
  glm::mat4 inv_view_proj;
  glm::vec4 camera_pos;
  glm::vec4 sun_dir;
  glm::vec4 sun_radiance;
  glm::vec4 sky_zenith;
  glm::vec4 sky_horizon;
  glm::vec4 ambient;
  glm::vec4 fog;     // rgb colour, a extinction per metre
  glm::vec4 params;  // x sim time, y overcast, z wetness, w rain rate (mm/h)
  glm::vec4 wind;    // xy wind velocity (m/s, world)
};

Texture upload_repeating(const Image8& image, bool mipmaps) {
  int levels = 1;
  if (mipmaps) {
    for (int s = image.width; s > 1; s /= 2) ++levels;
  }
  Texture t = make_texture_2d(GL_RGBA8, image.width, image.height, levels);
  glTextureSubImage2D(t.id(), 0, 0, 0, image.width, image.height, GL_RGBA, GL_UNSIGNED_BYTE,
                      image.rgba.data());
  if (mipmaps) glGenerateTextureMipmap(t.id());
  glTextureParameteri(t.id(), GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTextureParameteri(t.id(), GL_TEXTURE_WRAP_T, GL_REPEAT);
  return t;
}

struct ViewTarget {
  int width = 0;
  int height = 0;
  Texture colour;
  Texture depth;
  Framebuffer fbo;
  Buffer pbo[kReadbackSlots];
  int next_slot = 0;

  ViewTarget(int w, int h) : width(w), height(h) {
    colour = make_texture_2d(GL_RGBA8, w, h);
    depth = make_texture_2d(GL_DEPTH_COMPONENT32F, w, h);
    GLuint fb = 0;
    glCreateFramebuffers(1, &fb);
    fbo = Framebuffer(fb);
    glNamedFramebufferTexture(fb, GL_COLOR_ATTACHMENT0, colour.id(), 0);
    glNamedFramebufferTexture(fb, GL_DEPTH_ATTACHMENT, depth.id(), 0);
    if (glCheckNamedFramebufferStatus(fb, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
      throw std::runtime_error("render target framebuffer incomplete");
    }
    GLuint ids[kReadbackSlots];
    glCreateBuffers(kReadbackSlots, ids);
    for (int i = 0; i < kReadbackSlots; ++i) {
      pbo[i] = Buffer(ids[i]);
      glNamedBufferStorage(ids[i], static_cast<GLsizeiptr>(w) * h * 4, nullptr, GL_MAP_READ_BIT);
    }
  }
};

}  // namespace

struct Renderer::Impl {
  std::unique_ptr<EglContext> context;
  std::unique_ptr<SharedResources> shared;
  Buffer frame_ubo;
  std::unique_ptr<SkyPass> sky;
  std::unique_ptr<TerrainPass> terrain;
  std::unique_ptr<RoadPass> road;
  std::unique_ptr<VehiclePass> vehicles;
  std::unique_ptr<CockpitPass> cockpit;
  std::unique_ptr<WindshieldWaterPass> windshield_water;
  std::unique_ptr<WindshieldGlassPass> windshield_glass;
  std::unique_ptr<WindshieldPass> windshield;
  std::map<std::uint64_t, std::unique_ptr<ViewTarget>> targets;
  // A fence per target slot still being read back: a slot is reused only after finish().
  std::map<std::pair<std::uint64_t, int>, GLsync> in_flight;
  bool profiling = false;
  std::vector<PassTiming> timings;

  template <typename Fn>
  void timed(const char* name, Fn&& fn) {
    const auto t0 = std::chrono::steady_clock::now();
    fn();
    if (profiling) glFinish();
    timings.push_back(
        {name,
         std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count()});
  }

  void upload_frame_block(const FrameContext& f) {
    FrameBlock b;
    b.view_proj = f.camera.projection * f.camera.view;
    b.inv_view_proj = glm::inverse(b.view_proj);
    b.camera_pos = glm::vec4(f.camera.position, 1.0f);
    b.sun_dir = glm::vec4(f.atmosphere.sun_direction, 0.0f);
    b.sun_radiance = glm::vec4(f.atmosphere.sun_radiance, 0.0f);
    b.sky_zenith = glm::vec4(f.atmosphere.sky_zenith, 0.0f);
    b.sky_horizon = glm::vec4(f.atmosphere.sky_horizon, 0.0f);
    b.ambient = glm::vec4(f.atmosphere.ambient, 0.0f);
    b.fog = glm::vec4(f.atmosphere.fog_colour, f.atmosphere.fog_density);
    b.params = glm::vec4(static_cast<float>(f.scene.sim_time_s), f.atmosphere.overcast,
                         f.atmosphere.wetness, static_cast<float>(f.scene.weather.rain_rate_mm_h));
    const float wind_dir = glm::radians(static_cast<float>(f.scene.weather.wind_direction_deg));
    b.wind = glm::vec4(std::cos(wind_dir), std::sin(wind_dir), 0.0f, 0.0f) *
             static_cast<float>(f.scene.weather.wind_speed_mps);
    glNamedBufferSubData(frame_ubo.id(), 0, sizeof(b), &b);
  }

  // The water maps in glass space for this view's size, then back to the view's target.
  void draw_windshield_water(const FrameContext& f) {
    const WaterMapLayout layout = water_map_layout(f, windshield_water->config());
    timed("windshield_splat", [&] { windshield_water->splat(f.scene.windshield, layout); });
    timed("windshield_compress", [&] { windshield_water->compress(); });
    glBindFramebuffer(GL_FRAMEBUFFER, f.target_fbo);
    glViewport(0, 0, f.spec.width, f.spec.height);
  }

  void draw_view(const FrameContext& f) {
    switch (f.spec.view) {
      case sim::View::kCockpit:
      case sim::View::kRoad:
        // Nearest first, sky last: llvmpipe tests depth before shading, so what is hidden costs
        // little, and the sky shades only the pixels left empty.
        glEnable(GL_DEPTH_TEST);
        if (f.spec.view == sim::View::kCockpit) timed("cockpit", [&] { cockpit->draw(f); });
        timed("vehicles", [&] { vehicles->draw(f); });
        timed("road", [&] { road->draw(f); });
        timed("terrain", [&] { terrain->draw(f); });
        timed("sky", [&] { sky->draw(f); });
        if (f.spec.view == sim::View::kCockpit) {
          timed("windshield_scene_copy", [&] { windshield_glass->copy_scene(f); });
          draw_windshield_water(f);
          timed("windshield_glass", [&] { windshield_glass->draw(f, *windshield_water); });
        }
        break;
      case sim::View::kWindshield:
        draw_windshield_water(f);
        timed("windshield", [&] { windshield->draw(f, *windshield_water); });
        break;
      case sim::View::kRain:
        break;  // the rain layer over black: streaks and spray come with their passes
    }
  }
};

Renderer::Renderer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Renderer::~Renderer() {
  for (auto& [key, fence] : impl_->in_flight) glDeleteSync(fence);
}

std::unique_ptr<Renderer> Renderer::create(const RendererOptions& options) {
  auto impl = std::make_unique<Impl>();
  impl->context = EglContext::create(options.platform);
  // Reversed-Z: depth 1 at the near plane, 0 at infinity (see camera.cpp).
  glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
  glDepthFunc(GL_GREATER);
  glClearDepthf(0.0f);
  glPixelStorei(GL_PACK_ALIGNMENT, 4);

  impl->shared = std::make_unique<SharedResources>(
      SharedResources{sim::Track::test_track(), upload_repeating(make_noise(256, 1), true),
                      upload_repeating(make_asphalt_relief(512, 2), true), FullscreenTriangle()});
  glBindTextureUnit(binding::kNoise, impl->shared->noise.id());
  glBindTextureUnit(binding::kAsphalt, impl->shared->asphalt.id());
  GLuint ubo = 0;
  glCreateBuffers(1, &ubo);
  impl->frame_ubo = Buffer(ubo);
  glNamedBufferStorage(ubo, sizeof(FrameBlock), nullptr, GL_DYNAMIC_STORAGE_BIT);
  glBindBufferBase(GL_UNIFORM_BUFFER, binding::kFrameBlock, ubo);

  SharedResources& s = *impl->shared;
  impl->sky = std::make_unique<SkyPass>(s);
  impl->terrain = std::make_unique<TerrainPass>(s);
  impl->road = std::make_unique<RoadPass>(s);
  impl->vehicles = std::make_unique<VehiclePass>(s);
  impl->cockpit = std::make_unique<CockpitPass>(s);
  impl->windshield_water = std::make_unique<WindshieldWaterPass>();
  impl->windshield_glass = std::make_unique<WindshieldGlassPass>(s);
  impl->windshield = std::make_unique<WindshieldPass>(s);
  if (glGetError() != GL_NO_ERROR) throw std::runtime_error("GL error while creating the renderer");
  return std::unique_ptr<Renderer>(new Renderer(std::move(impl)));
}

const std::string& Renderer::gl_renderer() const { return impl_->context->renderer(); }
const std::string& Renderer::platform() const { return impl_->context->platform(); }
void Renderer::set_profiling(bool on) { impl_->profiling = on; }
const std::vector<PassTiming>& Renderer::last_pass_timings() const { return impl_->timings; }

PendingReadback Renderer::render(std::uint64_t key, const sim::ViewSpec& spec,
                                 const sim::SceneState& scene) {
  Impl& m = *impl_;
  m.timings.clear();
  auto& target = m.targets[key];
  if (!target || target->width != spec.width || target->height != spec.height) {
    for (int slot = 0; slot < kReadbackSlots; ++slot) {
      if (m.in_flight.count({key, slot}))
        throw std::logic_error("render target resized with a readback in flight");
    }
    target = std::make_unique<ViewTarget>(spec.width, spec.height);
  }
  const int slot = target->next_slot;
  target->next_slot = (slot + 1) % kReadbackSlots;
  if (m.in_flight.count({key, slot}))
    throw std::logic_error("readback slot reused before finish()");

  FrameContext frame{scene,
                     spec,
                     make_camera(spec, scene.vehicle),
                     atmosphere_from(scene.weather),
                     glm::mat4(sim::vehicle_to_world(scene.vehicle)),
                     target->fbo.id(),
                     target->colour.id(),
                     target->depth.id()};
  glBindFramebuffer(GL_FRAMEBUFFER, target->fbo.id());
  glViewport(0, 0, spec.width, spec.height);
  const float black[4] = {0.0f, 0.0f, 0.0f, 1.0f};
  const float zero_depth = 0.0f;
  glClearNamedFramebufferfv(target->fbo.id(), GL_COLOR, 0, black);
  glClearNamedFramebufferfv(target->fbo.id(), GL_DEPTH, 0, &zero_depth);
  m.upload_frame_block(frame);
  m.draw_view(frame);

  PendingReadback pending{key, slot, nullptr, spec.width, spec.height};
  m.timed("readback_start", [&] {
    glNamedFramebufferReadBuffer(target->fbo.id(), GL_COLOR_ATTACHMENT0);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, target->pbo[slot].id());
    glReadPixels(0, 0, spec.width, spec.height, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    GLsync fence = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
    glFlush();
    m.in_flight[{key, slot}] = fence;
    pending.fence = fence;
  });
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  return pending;
}

bool Renderer::is_ready(const PendingReadback& pending) const {
  GLint status = GL_UNSIGNALED;
  glGetSynciv(static_cast<GLsync>(pending.fence), GL_SYNC_STATUS, 1, nullptr, &status);
  return status == GL_SIGNALED;
}

void Renderer::finish(const PendingReadback& pending, std::vector<std::uint8_t>& out) {
  Impl& m = *impl_;
  const auto it = m.in_flight.find({pending.target_key, pending.slot});
  if (it == m.in_flight.end()) throw std::logic_error("finish() of a readback not in flight");
  while (glClientWaitSync(it->second, GL_SYNC_FLUSH_COMMANDS_BIT, 1'000'000'000) ==
         GL_TIMEOUT_EXPIRED) {
  }
  glDeleteSync(it->second);
  m.in_flight.erase(it);
  const ViewTarget& target = *m.targets.at(pending.target_key);
  const std::size_t bytes = static_cast<std::size_t>(pending.width) * pending.height * 4;
  out.resize(bytes);
  const GLuint pbo = target.pbo[pending.slot].id();
  const void* data = glMapNamedBufferRange(pbo, 0, static_cast<GLsizeiptr>(bytes), GL_MAP_READ_BIT);
  if (!data) throw std::runtime_error("mapping the readback buffer failed");
  std::memcpy(out.data(), data, bytes);
  glUnmapNamedBuffer(pbo);
}

void Renderer::release_targets(const std::function<bool(std::uint64_t)>& matches) {
  for (auto it = impl_->targets.begin(); it != impl_->targets.end();) {
    it = matches(it->first) ? impl_->targets.erase(it) : std::next(it);
  }
}

std::vector<std::uint8_t> render_image(Renderer& renderer, const sim::ViewSpec& spec,
                                       const sim::SceneState& scene) {
  constexpr std::uint64_t kImageTarget = ~std::uint64_t{0};
  const PendingReadback pending = renderer.render(kImageTarget, spec, scene);
  std::vector<std::uint8_t> bottom_up;
  renderer.finish(pending, bottom_up);
  std::vector<std::uint8_t> top_down(bottom_up.size());
  const std::size_t row = static_cast<std::size_t>(spec.width) * 4;
  for (int y = 0; y < spec.height; ++y) {
    std::memcpy(&top_down[y * row], &bottom_up[(spec.height - 1 - y) * row], row);
  }
  return top_down;
}

bool box_visible(const glm::mat4& m, const glm::vec3& lo, const glm::vec3& hi) {
  // Planes from the rows of the clip matrix: left, right, bottom, top, near (reversed-Z: w - z).
  const glm::vec4 r0(m[0][0], m[1][0], m[2][0], m[3][0]);
  const glm::vec4 r1(m[0][1], m[1][1], m[2][1], m[3][1]);
  const glm::vec4 r2(m[0][2], m[1][2], m[2][2], m[3][2]);
  const glm::vec4 r3(m[0][3], m[1][3], m[2][3], m[3][3]);
  const glm::vec4 planes[] = {r3 + r0, r3 - r0, r3 + r1, r3 - r1, r3 - r2};
  for (const glm::vec4& p : planes) {
    // The box corner furthest along the plane normal.
    const glm::vec3 c(p.x >= 0 ? hi.x : lo.x, p.y >= 0 ? hi.y : lo.y, p.z >= 0 ? hi.z : lo.z);
    if (p.x * c.x + p.y * c.y + p.z * c.z + p.w < 0.0f) return false;
  }
  return true;
}

}  // namespace downpour::render
