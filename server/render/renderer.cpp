#include "server/render/renderer.hpp"

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstring>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <tuple>

#include <spdlog/spdlog.h>
#include <glm/trigonometric.hpp>

#include "server/render/cpu/light_set.hpp"
#include "server/render/cpu/procedural_textures.hpp"
#include "server/render/cpu/relief.hpp"
#include "server/render/cpu/shader_interface.hpp"
#include "server/render/environment_probe.hpp"
#include "server/render/frame_context.hpp"
#include "server/render/lamp_map.hpp"
#include "server/render/pass.hpp"
#include "server/render/passes/cockpit_pass.hpp"
#include "server/render/passes/environment_background_pass.hpp"
#include "server/render/passes/glass_composite_pass.hpp"
#include "server/render/passes/glass_water_mask_pass.hpp"
#include "server/render/passes/glass_water_pass.hpp"
#include "server/render/passes/lamp_glow_pass.hpp"
#include "server/render/passes/rain_pass.hpp"
#include "server/render/passes/road_pass.hpp"
#include "server/render/passes/sky_pass.hpp"
#include "server/render/passes/spray_pass.hpp"
#include "server/render/passes/street_light_pass.hpp"
#include "server/render/passes/terrain_pass.hpp"
#include "server/render/passes/vehicle_pass.hpp"
#include "server/render/passes/windshield_pass.hpp"
#include "server/render/world.hpp"
#include "server/sim/glass_water_surface.hpp"
#include "server/sim/pose.hpp"

namespace downpour::render {
namespace {

constexpr int kReadbackSlots = 2;
constexpr int kReflectionScale = 4;  // the road reflection's size, 1 / 4 of the view
constexpr std::size_t kMaxTransients = 12;
constexpr std::chrono::seconds kFenceDeadline{10};

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

// The relief shadows' azimuths (seed 002: 16 or 32).
constexpr int kHorizonDirections = 32;

// The setts' relief and both reliefs' horizon maps: one array, the asphalt's layers first, packed
// (relief::packed_layer).
void upload_reliefs(SharedResources& shared, const std::shared_ptr<const relief::RoadReliefs>& r) {
  std::vector<float> setts_unit = r->setts.height_m;  // back to [0, 1] for the texture
  for (float& h : setts_unit) h /= relief::kSettsDepthM;
  shared.setts = upload_repeating(
      relief_image(setts_unit, r->setts.size, relief::kSettsDepthM / r->setts.texel_m), true);
  const relief::HorizonMaps* maps[] = {&r->asphalt_horizon, &r->setts_horizon};
  const int size = maps[0]->size, n = maps[0]->directions;
  shared.horizon_directions = n;
  shared.reliefs = r;
  shared.horizon = make_texture_2d_array(GL_RGBA8, size, size, 2 * n);
  for (int m = 0; m < 2; ++m) {
    if (maps[m]->size != size || maps[m]->directions != n) {
      throw std::logic_error("the reliefs' horizon maps differ in size");
    }
    for (int k = 0; k < n; ++k) {
      glTextureSubImage3D(shared.horizon.id(), 0, 0, 0, m * n + k, size, size, 1, GL_RGBA,
                          GL_UNSIGNED_BYTE, relief::packed_layer(*maps[m], k).data());
    }
  }
  glTextureParameteri(shared.horizon.id(), GL_TEXTURE_WRAP_S, GL_REPEAT);
  glTextureParameteri(shared.horizon.id(), GL_TEXTURE_WRAP_T, GL_REPEAT);
  glTextureParameteri(shared.horizon.id(), GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTextureParameteri(shared.horizon.id(), GL_TEXTURE_MAG_FILTER, GL_LINEAR);
}

Framebuffer framebuffer_with(GLuint colour, GLuint depth) {
  GLuint fb = 0;
  glCreateFramebuffers(1, &fb);
  Framebuffer fbo(fb);
  if (colour) glNamedFramebufferTexture(fb, GL_COLOR_ATTACHMENT0, colour, 0);
  if (depth) glNamedFramebufferTexture(fb, GL_DEPTH_ATTACHMENT, depth, 0);
  if (glCheckNamedFramebufferStatus(fb, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) {
    throw std::runtime_error("render target framebuffer incomplete");
  }
  return fbo;
}

// A view's colour and depth, and its readback buffers.
struct ViewTarget {
  int width = 0;
  int height = 0;
  Texture colour;
  Texture depth;
  Framebuffer fbo;
  std::array<Buffer, kReadbackSlots> pbo;
  std::array<GLsync, kReadbackSlots> fence{};  // a readback in flight per slot
  int next_slot = 0;

  ViewTarget(int w, int h) : width(w), height(h) {
    colour = make_texture_2d(GL_RGBA8, w, h);
    depth = make_texture_2d(GL_DEPTH_COMPONENT32F, w, h);
    fbo = framebuffer_with(colour.id(), depth.id());
    GLuint ids[kReadbackSlots];
    glCreateBuffers(kReadbackSlots, ids);
    for (int i = 0; i < kReadbackSlots; ++i) {
      pbo[i] = Buffer(ids[i]);
      glNamedBufferStorage(ids[i], static_cast<GLsizeiptr>(w) * h * 4, nullptr, GL_MAP_READ_BIT);
    }
  }
  ~ViewTarget() {
    for (GLsync f : fence) {
      if (f) glDeleteSync(f);
    }
  }
  bool busy() const {
    return std::any_of(fence.begin(), fence.end(), [](GLsync f) { return f != nullptr; });
  }
};

// A target that lives only within a frame (the glass layer, the spray layer, the road
// reflection), kept by size.
struct Transient {
  Texture texture;
  Texture depth;  // the road reflection's
  Framebuffer fbo;
  int width = 0;
  int height = 0;
  std::uint64_t last_frame = 0;  // the last frame that drew into it
};

// The plane the road reflection mirrors the scene in: the road's surface under the car (its grade
// and height; the crown is left to the shader's own normal), as a plane and a reflection matrix.
struct Mirror {
  glm::vec4 plane{0.0f, 0.0f, 1.0f, 0.0f};  // n.p + w = 0
  glm::mat4 matrix{1.0f};
};

// The mirror in the plane n.p + w = 0 (n unit): x' = x - 2 (n.x + w) n.
Mirror mirror_in(const glm::dvec4& plane) {
  const glm::dvec3 n(plane);
  Mirror m;
  m.plane = glm::vec4(plane);
  glm::dmat4 r(1.0);
  for (int c = 0; c < 3; ++c) {
    for (int row = 0; row < 3; ++row) r[c][row] -= 2.0 * n[row] * n[c];
  }
  for (int row = 0; row < 3; ++row) r[3][row] = -2.0 * plane.w * n[row];
  m.matrix = glm::mat4(r);
  return m;
}

Mirror mirror_under(const sim::RoadNetwork& roads, const sim::VehicleState& vehicle) {
  const glm::dvec2 xy(vehicle.position_m);
  const sim::RoadPlace p = roads.project(xy, 50.0);
  const sim::TrackFrame f = roads.frame(p.road, p.s);
  const glm::dvec3 along =
      glm::normalize(glm::dvec3(std::cos(f.heading_rad), std::sin(f.heading_rad), f.grade));
  glm::dvec3 n = glm::normalize(glm::cross(along, glm::dvec3(f.left, 0.0)));
  if (n.z < 0.0) n = -n;
  const glm::dvec3 point(xy, roads.surface_height(p));
  return mirror_in(glm::dvec4(n, -glm::dot(n, point)));
}

// Water on the glass to refract the world outside (the blades alone need none of it).
bool has_water(const sim::WindshieldState& water) {
  return water.surface && !water.surface->bodies.empty();
}

}  // namespace

struct RenderSession::Impl {
  std::vector<std::unique_ptr<ViewTarget>> views;
  // The water's surface on the GPU (bodies, cells, entries: buffers, read as texture buffers) and
  // what it holds.
  std::array<Buffer, 3> glass_surface;
  std::array<Texture, 3> glass_surface_tex;
  std::array<std::size_t, 3> glass_surface_bytes{};
  std::shared_ptr<const sim::GlassWaterSurface> surface_shown;
  // The world outside the glass, shared by the session's views (made on first use).
  std::unique_ptr<EnvironmentProbe> environment;
  // The road's water window on the GPU and the image it shows (held, so that its address names it).
  Texture road_water;
  int road_cells = 0, road_rings = 0;
  std::shared_ptr<const sim::RoadWaterImage> road_shown;
  bool road_dry_shown = false;
};

RenderSession::RenderSession(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
RenderSession::~RenderSession() = default;

struct Renderer::Impl {
  std::unique_ptr<EglContext> context;
  std::unique_ptr<SharedResources> shared;
  Worlds worlds;  // what is drawn of each road network
  Buffer frame_ubo;
  // The frame's lamps: their block (binding kLampBlockBinding), the map of their light on the
  // ground, and the frame block's fields that place it.
  Buffer lamp_ubo;
  LampBlock lamp_block;
  std::unique_ptr<LampMap> lamp_map;
  std::vector<Light> frame_lights;
  bool lamps_on = true;
  glm::vec4 lamp_params{0.0f};
  glm::mat4 lamp_rings{0.0f};
  std::vector<std::unique_ptr<Pass>> passes;
  std::array<std::vector<Pass*>, sim::kViewCount> views;  // each view's passes, in order
  // What draws the environment probe's faces (the world outside the glass); and, with a fixed
  // environment, COCKPIT's passes (the probe as the background, then the glass).
  std::vector<Pass*> environment_passes;
  std::vector<Pass*> fixed_environment_cockpit;
  EnvironmentConfig environment_config;
  std::unique_ptr<EnvironmentPrograms> environment_programs;
  // The water layer's least reduction where the lens blurs at all, and how much wider than tall
  // its pixels are where the blur spans two pixels or more (GlassView): on a CPU rasterizer
  // (llvmpipe), which pays for every pixel of it, 2 and 1.375 (1280x720: a 466x360 layer; the
  // drops' inversion and brightening over the grass kept or better than at 1, and 1.5 lost the
  // brightening); on a GPU 1 and 1 (square, as sharp as the blur).
  int min_glass_layer_scale = 1;
  double glass_layer_widening = 1.0;
  std::optional<std::array<std::vector<glm::vec3>, EnvironmentProbe::kFaces>> fixed_environment;

  std::map<std::tuple<Resource, int, int>, Transient> transients;
  bool profiling = false;
  std::vector<PassTiming> timings;
  std::uint64_t frame = 0;                       // frames rendered, for the transients' use
  std::unique_ptr<RenderSession> image_session;  // render_image's
  RainPass* rain = nullptr;                      // one of passes
  SprayPass* spray = nullptr;                    // likewise
  RoadPass* road = nullptr;                      // likewise
  bool view_drew_relief = false;   // the view's road pass (not the environment's faces)
  std::uint32_t rain_streaks = 0;  // drawn by the last render()
  // What the road reflection draws, mirrored (passes of the views), each clipped to this far above
  // the mirror's plane; and the views that read it.
  struct Reflected {
    Pass* pass = nullptr;
    float clearance_m = 0.0f;
  };
  std::vector<Reflected> reflected;
  std::array<bool, sim::kViewCount> reads_reflection{};

  template <typename Fn>
  void timed(const std::string& name, Fn&& fn) {
    const auto t0 = std::chrono::steady_clock::now();
    fn();
    if (profiling) glFinish();
    timings.push_back(
        {name,
         std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count()});
  }

  template <typename P>
  P* add() {
    passes.push_back(std::make_unique<P>(*shared));
    return static_cast<P*>(passes.back().get());
  }

  // The frame's water and mirror: the window's place, the reflection's matrix and plane.
  struct WaterBlock {
    Mirror mirror;
    glm::vec4 clip_plane{0.0f, 0.0f, 0.0f, 1.0f};
    glm::vec4 road_water{0.0f};
    glm::mat4 road_water_rings{0.0f};
    glm::vec4 road_water_state{0.5f, 0.0f, 0.0f, 0.0f};
  };

  static WaterBlock water_block(const FrameContext& f, const Mirror& mirror, bool reflection) {
    WaterBlock w;
    w.mirror = mirror;
    w.road_water.w = reflection ? 1.0f : 0.0f;
    if (const sim::RoadWaterImage* image = f.scene.road_water.get(); image && image->complete()) {
      w.road_water.x = static_cast<float>(image->levels);
      for (int l = 0; l < image->levels; ++l) {
        const double cell = image->level_cell_m(l);
        w.road_water_rings[l] =
            glm::vec4(static_cast<float>(image->origins[l].x * cell),
                      static_cast<float>(image->origins[l].y * cell),
                      static_cast<float>(1.0 / (image->cells * cell)), static_cast<float>(cell));
      }
      w.road_water_state = glm::vec4(static_cast<float>(image->capacity_mm), image->mean_water_mm,
                                     image->mean_standing_mm, 1.0f);
    }
    return w;
  }

  void upload_frame_block(const FrameContext& f, const WaterBlock& water) {
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
    b.time_s = static_cast<float>(f.scene.sim_time_s);
    b.overcast = f.atmosphere.overcast;
    b.wetness = f.atmosphere.wetness;
    b.rain_rate_mm_h = static_cast<float>(f.scene.weather.rain_rate_mm_h);
    const float wind_dir = glm::radians(static_cast<float>(f.scene.weather.wind_direction_deg));
    b.wind = glm::vec4(std::cos(wind_dir), std::sin(wind_dir), 0.0f, 0.0f) *
             static_cast<float>(f.scene.weather.wind_speed_mps);
    // (In the reflection's own frame, view_proj is already mirrored: the road reads these only in
    // the view's.)
    b.mirror_view_proj = b.view_proj * water.mirror.matrix;
    b.clip_plane = water.clip_plane;
    b.road_water = water.road_water;
    b.road_water_rings = water.road_water_rings;
    b.road_water_state = water.road_water_state;
    b.lamp_map = lamp_params;
    b.lamp_rings = lamp_rings;
    glNamedBufferSubData(frame_ubo.id(), 0, sizeof(b), &b);
  }

  Transient& transient(Resource r, int width, int height) {
    const auto key = std::make_tuple(r, width, height);
    auto it = transients.find(key);
    if (it != transients.end()) {
      it->second.last_frame = frame;
      return it->second;
    }
    Transient t;
    t.last_frame = frame;
    t.width = width;
    t.height = height;
    if (r == Resource::kRoadReflection || r == Resource::kGlassLayer) {
      t.texture = make_texture_2d(GL_RGBA8, width, height);
      t.depth = make_texture_2d(GL_DEPTH_COMPONENT32F, width, height);
      for (GLuint id : {t.texture.id(), t.depth.id()}) {
        glTextureParameteri(id, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
        glTextureParameteri(id, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
      }
      glTextureParameteri(t.depth.id(), GL_TEXTURE_MIN_FILTER, GL_NEAREST);
      glTextureParameteri(t.depth.id(), GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    } else {
      t.texture = make_texture_2d(GL_RGBA8, width, height);
      glTextureParameteri(t.texture.id(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
      glTextureParameteri(t.texture.id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    }
    t.fbo = framebuffer_with(t.texture.id(), t.depth.id());
    return transients.emplace(key, std::move(t)).first->second;
  }

  // Many view sizes at once are rare: past kMaxTransients, the targets unused the longest go (at
  // a frame's start, so never one a pass of this frame has bound).
  void evict_transients() {
    while (transients.size() > kMaxTransients) {
      auto oldest = transients.begin();
      for (auto it = transients.begin(); it != transients.end(); ++it) {
        if (it->second.last_frame < oldest->second.last_frame) oldest = it;
      }
      transients.erase(oldest);
    }
  }

  // The session's water surface on the glass brought up to the frame's (a whole upload for each
  // new one: the step publishes one per tick), bound to its texture buffers.
  void upload_glass_surface(RenderSession::Impl& s,
                            std::shared_ptr<const sim::GlassWaterSurface> surface) {
    // No water (the blades alone): an empty grid, which the optics find dry everywhere.
    static const auto dry = std::make_shared<const sim::GlassWaterSurface>();
    if (!surface) surface = dry;
    if (s.surface_shown != surface) {
      const std::array<std::pair<const void*, std::size_t>, 3> parts{{
          {surface->bodies.data(), surface->bodies.size() * sizeof(sim::WaterBody)},
          {surface->cells.data(), surface->cells.size() * sizeof(std::uint32_t)},
          {surface->entries.data(), surface->entries.size() * sizeof(std::uint32_t)},
      }};
      constexpr GLenum kFormats[3] = {GL_RGBA32F, GL_R32UI, GL_R32UI};
      for (std::size_t k = 0; k < parts.size(); ++k) {
        // Grown as needed (never empty: a texture buffer needs storage), else refilled.
        const std::size_t bytes = std::max<std::size_t>(parts[k].second, 16);
        if (!s.glass_surface[k].id() || s.glass_surface_bytes[k] < bytes) {
          GLuint id = 0;
          glCreateBuffers(1, &id);
          s.glass_surface[k] = Buffer(id);
          s.glass_surface_bytes[k] = std::max(bytes, 2 * s.glass_surface_bytes[k]);
          glNamedBufferStorage(id, static_cast<GLsizeiptr>(s.glass_surface_bytes[k]), nullptr,
                               GL_DYNAMIC_STORAGE_BIT);
          GLuint tex = 0;
          glCreateTextures(GL_TEXTURE_BUFFER, 1, &tex);
          s.glass_surface_tex[k] = Texture(tex);
          glTextureBuffer(tex, kFormats[k], id);
        }
        if (parts[k].second > 0)
          glNamedBufferSubData(s.glass_surface[k].id(), 0, static_cast<GLsizeiptr>(parts[k].second),
                               parts[k].first);
      }
      s.surface_shown = surface;
    }
    const GLuint units[3] = {texture_unit::kGlassBodies, texture_unit::kGlassCells,
                             texture_unit::kGlassEntries};
    for (std::size_t k = 0; k < 3; ++k) glBindTextureUnit(units[k], s.glass_surface_tex[k].id());
  }

  // The session's environment probe brought up to this tick: the faces due, each drawn by the
  // world passes from the probe's centre just outside the glass, then made linear with the sun
  // and the lamps. The first view of a tick refreshes it; the others share it.
  void refresh_environment(const FrameContext& f, RenderSession::Impl& s, const Mirror& mirror,
                           bool complete) {
    if (!s.environment) {
      s.environment = std::make_unique<EnvironmentProbe>(environment_config);
      if (fixed_environment) s.environment->set_fixed(*fixed_environment);
    }
    EnvironmentProbe& probe = *s.environment;
    const std::vector<EnvironmentProbe::Due>& due = probe.faces_due(f.scene.sim_time_s, complete);
    if (due.empty()) return;
    const sim::GlassConfig& glass = f.scene.glass;
    const glm::dvec3 centre_vehicle =
        glass.to_vehicle({0.5 * glass.bottom_width_mm, 0.5 * glass.height_mm}) +
        glass.normal() * static_cast<double>(probe.config().clearance_m);
    const glm::vec3 centre(f.vehicle_to_world * glm::vec4(glm::vec3(centre_vehicle), 1.0f));
    const glm::mat3 axes(f.vehicle_to_world);  // the car's, in the world
    const int size = probe.config().face_size;
    // The faces' spec: the view's, square (the ego car shows its bonnet alone, as from the cabin).
    sim::ViewSpec spec = f.spec;
    spec.width = spec.height = size;
    spec.camera.reset();
    FrameResources r;
    r.view_fbo = probe.face_fbo();
    r.view_colour = {probe.face_colour(), size, size};
    r.view_depth = {probe.face_depth(), size, size};
    // Geometry's detail as far out as a face's texels are wider than the view's pixels.
    const float view_pixel = 2.0f * static_cast<float>(f.camera.tan_half_fov_y) /
                             static_cast<float>(std::max(f.spec.height, 1));
    const float face_texel = 2.0f / static_cast<float>(size);
    const float black[4] = {0.0f, 0.0f, 0.0f, 1.0f};
    const float zero_depth = 0.0f;
    for (const auto [face, world] : due) {
      FrameContext ff{f.scene,
                      spec,
                      EnvironmentProbe::face_camera(face, centre, axes),
                      f.atmosphere,
                      f.vehicle_to_world,
                      GlassView(),
                      f.stepped};
      ff.world = f.world;
      ff.lights = f.lights;
      ff.detail_distance_scale = std::max(face_texel / view_pixel, 1.0f);
      upload_frame_block(ff, water_block(ff, mirror, false));
      apply(RenderState{DepthTest::kOff, true, Blend::kOff});
      glClearNamedFramebufferfv(r.view_fbo, GL_COLOR, 0, black);
      glClearNamedFramebufferfv(r.view_fbo, GL_DEPTH, 0, &zero_depth);
      for (Pass* pass : environment_passes) {
        if (world || pass == environment_passes.back()) run_pass(*pass, ff, s, r);  // (the sky)
      }
      probe.resolve(*environment_programs, face, axes, f.atmosphere,
                    static_cast<int>(lamp_params.w));
    }
  }

  // The session's road water rings brought up to the frame's: a whole upload for each new image
  // (one per road step: 4 rings of 64 x 64 cells, two half floats each).
  void upload_road_water(RenderSession::Impl& s,
                         const std::shared_ptr<const sim::RoadWaterImage>& image) {
    const bool valid = image && image->complete();
    const int n = valid ? image->cells : 1, rings = valid ? image->levels : 1;
    if (!s.road_water.id() || s.road_cells != n || s.road_rings != rings) {
      s.road_water = make_texture_2d_array(GL_RG16F, n, n, rings);
      glTextureParameteri(s.road_water.id(), GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
      glTextureParameteri(s.road_water.id(), GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
      s.road_cells = n;
      s.road_rings = rings;
      s.road_shown.reset();
      s.road_dry_shown = false;
    }
    if (!valid) {
      if (!s.road_dry_shown) {
        const float dry[2] = {0.0f, 0.0f};
        glTextureSubImage3D(s.road_water.id(), 0, 0, 0, 0, 1, 1, 1, GL_RG, GL_FLOAT, dry);
        s.road_dry_shown = true;
        s.road_shown.reset();
      }
      return;
    }
    if (s.road_shown == image) return;
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    glTextureSubImage3D(s.road_water.id(), 0, 0, 0, 0, n, n, rings, GL_RG, GL_FLOAT,
                        image->water_standing_mm.data());
    s.road_shown = image;
    s.road_dry_shown = false;
  }

  // Whether the road's water shows a mirror anywhere: a film standing on it (road.frag's film),
  // or, without the simulation's water, heavy enough rain for the weather's film.
  static bool road_reflects(const FrameContext& f) {
    if (const sim::RoadWaterImage* image = f.scene.road_water.get())
      return image->max_standing_mm > 0.03f;
    return f.atmosphere.wetness > 0.3f;
  }

  // The scene mirrored in the road's plane, from the view's camera, at a quarter of its size:
  // the passes of `reflected` with a mirrored frame block, clipped to above the plane.
  void draw_reflection(const FrameContext& f, const Mirror& mirror, FrameResources& r) {
    const int w = std::max(1, (r.view_colour.width + kReflectionScale - 1) / kReflectionScale);
    const int h = std::max(1, (r.view_colour.height + kReflectionScale - 1) / kReflectionScale);
    Transient& t = transient(Resource::kRoadReflection, w, h);
    Camera mirrored = f.camera;
    mirrored.view = f.camera.view * mirror.matrix;
    mirrored.position = glm::vec3(mirror.matrix * glm::vec4(f.camera.position, 1.0f));
    FrameContext mf{f.scene, f.spec,   mirrored, f.atmosphere, f.vehicle_to_world,
                    f.glass, f.stepped};
    mf.detail_distance_scale = kReflectionScale;
    mf.world = f.world;
    WaterBlock clip;
    upload_frame_block(mf, clip);
    glBindFramebuffer(GL_FRAMEBUFFER, t.fbo.id());
    glViewport(0, 0, w, h);
    apply(RenderState{DepthTest::kOff, true, Blend::kOff});
    const float black[4] = {0.0f, 0.0f, 0.0f, 1.0f};
    const float zero_depth = 0.0f;
    glClearNamedFramebufferfv(t.fbo.id(), GL_COLOR, 0, black);
    glClearNamedFramebufferfv(t.fbo.id(), GL_DEPTH, 0, &zero_depth);
    glEnable(GL_CLIP_DISTANCE0);
    for (const Reflected& pass : reflected) {
      // Above the plane: vehicles from 2 cm under it (what touches the road stays whole), the
      // ground from well over it. The ground under and beside the road lies in the plane: mirrored,
      // it would be a floor over everything the mirror shows.
      glm::vec4 plane = mirror.plane;
      plane.w -= pass.clearance_m;
      glNamedBufferSubData(frame_ubo.id(), offsetof(FrameBlock, clip_plane), sizeof(plane), &plane);
      apply(pass.pass->decl().state);
      pass.pass->execute(mf, r);
    }
    glDisable(GL_CLIP_DISTANCE0);
    r.road_reflection = {t.texture.id(), w, h};
    r.road_reflection_depth = {t.depth.id(), w, h};
  }

  void run_pass(Pass& pass, const FrameContext& f, RenderSession::Impl& session,
                FrameResources& r) {
    if (!pass.wanted(f)) return;
    const PassDecl& d = pass.decl();
    // A transient that no pass of this frame drew (its pass had nothing to draw) leaves its
    // readers nothing to draw either.
    for (Resource res : d.reads) {
      if ((res == Resource::kGlassLayer || res == Resource::kSprayLayer) && !written[index(res)])
        return;
    }
    for (Resource res : d.reads) {
      GLuint texture = 0;
      switch (res) {
        case Resource::kViewColour:
          texture = r.view_colour.texture;
          break;
        case Resource::kViewDepth:
          texture = r.view_depth.texture;
          break;
        case Resource::kGlassLayer:
          texture = r.glass_layer.texture;
          break;
        case Resource::kGlassSurface:
          upload_glass_surface(session, f.water().surface);
          continue;  // bound to their units there
        case Resource::kEnvironment: {
          const EnvironmentProbe* probe = session.environment.get();
          texture = probe ? probe->texture() : 0;
          const int size = probe ? probe->config().face_size : 0;
          r.environment = {texture, size, size};
          r.environment_from_world =
              probe ? probe->from_world(f.vehicle_to_world) : glm::mat3(1.0f);
          break;
        }
        case Resource::kRoadWater:
          upload_road_water(session, f.scene.road_water);
          texture = session.road_water.id();
          break;
        case Resource::kRoadReflection:
          texture = r.road_reflection.texture;
          glBindTextureUnit(texture_unit::kReflectionDepth, r.road_reflection_depth.texture);
          break;
        case Resource::kSprayLayer:
          texture = r.spray_layer.texture;
          break;
      }
      glBindTextureUnit(resource_info(res).texture_unit, texture);
    }
    const Resource out = d.writes.front();
    if (resource_info(out).view_target) {
      glBindFramebuffer(GL_FRAMEBUFFER, r.view_fbo);
      glViewport(0, 0, r.view_colour.width, r.view_colour.height);
    } else {
      const int w = r.view_colour.width, h = r.view_colour.height;
      const bool spray = out == Resource::kSprayLayer;
      const int k = SprayPass::kScale;
      const glm::ivec2 size =
          spray ? glm::ivec2(std::max(1, (w + k - 1) / k), std::max(1, (h + k - 1) / k))
                : f.glass.layer_size(w, h);
      Transient& t = transient(out, size.x, size.y);
      TargetTexture& texture = spray ? r.spray_layer : r.glass_layer;
      GLuint& fbo = spray ? r.spray_layer_fbo : r.glass_layer_fbo;
      texture = {t.texture.id(), t.width, t.height};
      fbo = t.fbo.id();
      glBindFramebuffer(GL_FRAMEBUFFER, t.fbo.id());
      glViewport(0, 0, t.width, t.height);
      if (!written[index(out)]) {  // cleared by its first pass of the frame
        const float clear[4] = {0.0f, 0.0f, 0.0f, 0.0f};
        glClearNamedFramebufferfv(t.fbo.id(), GL_COLOR, 0, clear);
        if (t.depth.id()) {  // (the glass layer's: the nearest, for its mask)
          const float nearest = 1.0f;
          glDepthMask(GL_TRUE);
          glClearNamedFramebufferfv(t.fbo.id(), GL_DEPTH, 0, &nearest);
        }
      }
    }
    apply(d.state);
    pass.execute(f, r);
    // Clears outside the passes heed the colour mask: it is left on.
    if (!d.state.colour_write) glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    for (Resource res : d.writes) written[index(res)] = true;
  }

  // The frame's lamps into their block, and their light on the ground into the lamp map (for the
  // views that show the ground).
  void prepare_lamps(FrameContext& f) {
    frame_lights.clear();
    // By day the lamps' light is lost in the sun's (a low beam's 1,000 lux 4 m ahead shows as
    // 0.014 of white at noon): none is drawn until the exposure makes it count. Their lit lenses
    // still show (vehicle.frag).
    constexpr float kLampsFromExposure = 2e-4f;
    if (lamps_on && f.atmosphere.lux_exposure >= kLampsFromExposure)
      frame_lights = build_lights(f.scene, f.world->street_lights, f.camera.position);
    f.lights = &frame_lights;
    const std::vector<Light>& lights = frame_lights;
    const glm::mat4& view = f.camera.view;
    const glm::vec3 forward(-view[0][2], -view[1][2], -view[2][2]);
    const PackedLamps packed = pack_lamps(lights, f.camera.position, forward, lamp_block);
    const std::size_t bytes = sizeof(glm::vec4) * (1 + 4 * static_cast<std::size_t>(packed.count));
    glNamedBufferSubData(lamp_ubo.id(), 0, static_cast<GLsizeiptr>(bytes), &lamp_block);
    lamp_rings = place_lamp_rings(f.camera.position, forward).windows;
    const bool map = packed.count > 0 && f.spec.view != sim::View::kWindshield &&
                     f.spec.view != sim::View::kRain;
    lamp_params =
        glm::vec4(map ? static_cast<float>(LampRings::kRings) : 0.0f, f.atmosphere.lux_exposure,
                  static_cast<float>(packed.ego), static_cast<float>(packed.count));
    if (!map) return;
    upload_frame_block(f, WaterBlock{});
    lamp_map->draw(packed.ground_boxes);
  }

  static std::size_t index(Resource r) { return static_cast<std::size_t>(r); }
  std::array<bool, kResourceCount> written{};  // this frame's
};

Renderer::Renderer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Renderer::~Renderer() = default;

std::unique_ptr<Renderer> Renderer::create(const RendererOptions& options) {
  auto impl = std::make_unique<Impl>();
  impl->context = EglContext::create(options.platform);
  if (impl->context->renderer().find("llvmpipe") != std::string::npos ||
      impl->context->renderer().find("softpipe") != std::string::npos) {
    impl->min_glass_layer_scale = 2;
    impl->glass_layer_widening = 1.375;
  }
  const SpraySmoothing smoothing = options.spray_smoothing;
#ifndef NDEBUG
  // Debug builds: the driver's own reports of errors and misuse, in the log as they happen.
  glEnable(GL_DEBUG_OUTPUT);
  glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
  glDebugMessageCallback(
      [](GLenum, GLenum type, GLuint id, GLenum severity, GLsizei, const GLchar* message,
         const void*) {
        if (severity == GL_DEBUG_SEVERITY_NOTIFICATION) return;
        spdlog::log(type == GL_DEBUG_TYPE_ERROR ? spdlog::level::err : spdlog::level::warn,
                    "GL debug {}: {}", id, message);
      },
      nullptr);
#endif
  // Reversed-Z: depth 1 at the near plane, 0 at infinity (see camera.cpp).
  glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE);
  glClearDepthf(0.0f);
  glPixelStorei(GL_PACK_ALIGNMENT, 4);

  impl->shared = std::make_unique<SharedResources>(
      SharedResources{upload_repeating(make_noise(256, 1), true),
                      upload_repeating(make_asphalt_relief(512, 2), true), FullscreenTriangle(),
                      Texture(), Texture(), 0, nullptr});
  upload_reliefs(*impl->shared, relief::road_reliefs(kHorizonDirections));
  impl->worlds.get(nullptr);  // the built-in track's, before the first frame
  glBindTextureUnit(texture_unit::kNoise, impl->shared->noise.id());
  glBindTextureUnit(texture_unit::kAsphalt, impl->shared->asphalt.id());
  glBindTextureUnit(texture_unit::kSetts, impl->shared->setts.id());
  glBindTextureUnit(texture_unit::kHorizon, impl->shared->horizon.id());
  GLuint ubo = 0;
  glCreateBuffers(1, &ubo);
  impl->frame_ubo = Buffer(ubo);
  glNamedBufferStorage(ubo, sizeof(FrameBlock), nullptr, GL_DYNAMIC_STORAGE_BIT);
  glBindBufferBase(GL_UNIFORM_BUFFER, kFrameBlockBinding, ubo);
  GLuint lamp_ubo = 0;
  glCreateBuffers(1, &lamp_ubo);
  impl->lamp_ubo = Buffer(lamp_ubo);
  glNamedBufferStorage(lamp_ubo, sizeof(LampBlock), nullptr, GL_DYNAMIC_STORAGE_BIT);
  glBindBufferBase(GL_UNIFORM_BUFFER, kLampBlockBinding, lamp_ubo);
  impl->lamp_map = std::make_unique<LampMap>();
  impl->environment_programs = std::make_unique<EnvironmentPrograms>();

  // The views as lists of passes. Nearest first, sky last: llvmpipe tests depth before shading,
  // so what is hidden costs little, and the sky shades only the pixels left empty.
  Pass* cockpit = impl->add<CockpitPass>();
  Pass* vehicles = impl->add<VehiclePass>();
  Pass* street_lights = impl->add<StreetLightPass>();
  RoadPass* road = impl->add<RoadPass>();
  impl->road = road;
  Pass* terrain = impl->add<TerrainPass>();
  Pass* sky = impl->add<SkyPass>();
  Pass* glow = impl->add<LampGlowPass>();
  RainPass* rain = impl->add<RainPass>();
  impl->rain = rain;
  Pass* rain_mask = impl->add<RainMaskPass>();
  Pass* environment_background = impl->add<EnvironmentBackgroundPass>();
  GlassWaterPass* glass_water = impl->add<GlassWaterPass>();
  impl->passes.push_back(std::make_unique<GlassWaterMaskPass>(*impl->shared, *glass_water));
  Pass* glass_water_mask = impl->passes.back().get();
  Pass* glass_composite = impl->add<GlassCompositePass>();
  Pass* windshield = impl->add<WindshieldPass>();
  SprayPass* spray = impl->add<SprayPass>();
  impl->spray = spray;
  spray->set_smoothing(smoothing);
  impl->passes.push_back(std::make_unique<SprayCompositePass>(*impl->shared, *spray));
  Pass* spray_composite = impl->passes.back().get();
  impl->reflected = {{vehicles, -0.02f}, {street_lights, 0.0f}, {terrain, 0.5f}, {sky, 0.0f}};
  auto& views = impl->views;
  views[static_cast<int>(sim::View::kCockpit)] = {
      cockpit, vehicles,        street_lights,    road,        terrain,        sky, glow, rain,
      spray,   spray_composite, glass_water_mask, glass_water, glass_composite};
  impl->environment_passes = {vehicles, street_lights, road, terrain, sky};  // the sky last
  impl->fixed_environment_cockpit = {environment_background, glass_water_mask, glass_water,
                                     glass_composite};
  check_pass_order("COCKPIT (fixed environment)", impl->fixed_environment_cockpit);
  views[static_cast<int>(sim::View::kRoad)] = {vehicles, street_lights, road,  terrain,        sky,
                                               glow,     rain,          spray, spray_composite};
  views[static_cast<int>(sim::View::kWindshield)] = {windshield};
  // The rain layer alone from the driver's eye: the scene for its depth, then black, then rain and
  // spray.
  views[static_cast<int>(sim::View::kRain)] = {
      cockpit, vehicles, street_lights, road, terrain, rain_mask, rain, spray, spray_composite};
  for (int v = 0; v < sim::kViewCount; ++v) {
    check_pass_order(sim::view_name(static_cast<sim::View>(v)), views[v]);
    for (const Pass* pass : views[v]) {
      const auto& reads = pass->decl().reads;
      if (std::find(reads.begin(), reads.end(), Resource::kRoadReflection) != reads.end())
        impl->reads_reflection[v] = true;
    }
  }
  // RAIN draws the scene for its depth alone: its road needs no mirror.
  impl->reads_reflection[static_cast<int>(sim::View::kRain)] = false;
  if (glGetError() != GL_NO_ERROR) throw std::runtime_error("GL error while creating the renderer");
  return std::unique_ptr<Renderer>(new Renderer(std::move(impl)));
}

const std::string& Renderer::gl_renderer() const { return impl_->context->renderer(); }
const std::string& Renderer::platform() const { return impl_->context->platform(); }
void Renderer::set_profiling(bool on) { impl_->profiling = on; }
void Renderer::set_spray_smoothing(SpraySmoothing smoothing) {
  impl_->spray->set_smoothing(smoothing);
}
SpraySmoothing Renderer::spray_smoothing() const { return impl_->spray->smoothing(); }
void Renderer::set_relief_shadows(bool on) { impl_->road->set_relief_shadows(on); }
void Renderer::set_lamps(bool on) { impl_->lamps_on = on; }
bool Renderer::last_drew_relief() const { return impl_->view_drew_relief; }
void Renderer::set_spray_cpu_splat(bool cpu) { impl_->spray->set_cpu_splat(cpu); }
bool Renderer::spray_cpu_splat() const { return impl_->spray->cpu_splat(); }
std::vector<float> Renderer::smooth_spray_body(int width, int height, float tan_x, float tan_y,
                                               const std::vector<float>& front) {
  if (width <= 0 || height <= 0 || front.size() != static_cast<std::size_t>(width) * height)
    throw std::invalid_argument("smooth_spray_body: the depths do not fill the size");
  return impl_->spray->smooth_body_depth(width, height, glm::vec2(tan_x, tan_y), front);
}
std::array<std::uint32_t, 3> Renderer::last_spray_drawn() const {
  const SprayPass::Drawn& d = impl_->spray->drawn();
  return {d.body, d.spray, d.haze};
}
const std::vector<PassTiming>& Renderer::last_pass_timings() const { return impl_->timings; }
std::uint32_t Renderer::last_rain_streaks() const { return impl_->rain_streaks; }

void Renderer::release_shared_targets() { impl_->transients.clear(); }

void Renderer::set_fixed_environment(std::optional<std::array<std::vector<glm::vec3>, 6>> faces,
                                     int face_size) {
  if (faces && (face_size < 4 || face_size > 2048))
    throw std::invalid_argument("a fixed environment's faces are 4 to 2048 texels a side");
  impl_->fixed_environment = std::move(faces);
  if (impl_->fixed_environment)
    impl_->environment_config.face_size = face_size;
  else
    impl_->environment_config = EnvironmentConfig{};
  if (impl_->image_session) impl_->image_session->impl_->environment.reset();
}

std::unique_ptr<RenderSession> Renderer::open_session() {
  return std::unique_ptr<RenderSession>(new RenderSession(std::make_unique<RenderSession::Impl>()));
}

PendingReadback Renderer::render(RenderSession& session, int view_index, const sim::ViewSpec& spec,
                                 const sim::SceneState& scene) {
  return render(session, view_index, spec, scene,
                [&scene]() -> const sim::SceneState& { return scene; });
}

PendingReadback Renderer::render(RenderSession& session, int view_index, const sim::ViewSpec& spec,
                                 const sim::SceneState& scene, const StepSource& stepped) {
  Impl& m = *impl_;
  RenderSession::Impl& s = *session.impl_;
  m.timings.clear();
  if (view_index < 0) throw std::logic_error("negative view index");
  if (s.views.size() <= static_cast<std::size_t>(view_index)) s.views.resize(view_index + 1);
  auto& target = s.views[view_index];
  if (!target || target->width != spec.width || target->height != spec.height) {
    if (target && target->busy())
      throw std::logic_error("render target resized with a readback in flight");
    target = std::make_unique<ViewTarget>(spec.width, spec.height);
    // The spray's targets and buffers for this size now, not when the first spray shows (a
    // session's memory is taken when its views are).
    const auto& passes = m.views[static_cast<int>(spec.view)];
    if (std::find(passes.begin(), passes.end(), m.spray) != passes.end())
      m.spray->prepare(spec.width, spec.height);
  }
  const int slot = target->next_slot;
  target->next_slot = (slot + 1) % kReadbackSlots;
  if (target->fence[slot]) throw std::logic_error("readback slot reused before finish()");

  const Camera camera = make_camera(spec, scene.vehicle, &scene.weather);
  FrameContext frame{
      scene,
      spec,
      camera,
      atmosphere_from(scene.weather),
      glm::mat4(sim::vehicle_to_world(scene.vehicle)),
      GlassView(camera, scene.glass, spec.height, m.min_glass_layer_scale, m.glass_layer_widening),
      stepped};
  frame.world = &m.worlds.get(scene.roads);
  FrameResources resources;
  resources.view_fbo = target->fbo.id();
  resources.view_colour = {target->colour.id(), spec.width, spec.height};
  resources.view_depth = {target->depth.id(), spec.width, spec.height};
  glBindFramebuffer(GL_FRAMEBUFFER, target->fbo.id());
  glViewport(0, 0, spec.width, spec.height);
  apply(RenderState{DepthTest::kOff, true, Blend::kOff});  // clears obey the depth mask
  const float black[4] = {0.0f, 0.0f, 0.0f, 1.0f};
  const float zero_depth = 0.0f;
  glClearNamedFramebufferfv(target->fbo.id(), GL_COLOR, 0, black);
  glClearNamedFramebufferfv(target->fbo.id(), GL_DEPTH, 0, &zero_depth);
  ++m.frame;
  m.evict_transients();
  m.written.fill(false);
  const Mirror mirror =
      mirror_under(scene.roads ? *scene.roads : *sim::built_in_roads(), scene.vehicle);
  const bool reflection =
      m.reads_reflection[static_cast<int>(spec.view)] && Impl::road_reflects(frame);
  // Profiling: the clears and the frame's uploads finish here, not in the first step's time.
  if (m.profiling) m.timed("clear", [] {});
  m.timed("lamp_map", [&] { m.prepare_lamps(frame); });
  if (reflection) m.timed("road_reflection", [&] { m.draw_reflection(frame, mirror, resources); });
  const int view = static_cast<int>(spec.view);
  const bool fixed = m.fixed_environment && spec.view == sim::View::kCockpit;
  const Impl::WaterBlock view_water = Impl::water_block(frame, mirror, reflection);
  m.upload_frame_block(frame, view_water);
  glBindFramebuffer(GL_FRAMEBUFFER, target->fbo.id());
  glViewport(0, 0, spec.width, spec.height);
  m.rain->take_drawn();
  for (Pass* pass : fixed ? m.fixed_environment_cockpit : m.views[view]) {
    // The world outside the glass, for the first pass that reads it and has something to draw
    // (it waits for the step, as that pass would): then the view's frame block again.
    const auto& reads = pass->decl().reads;
    if (std::find(reads.begin(), reads.end(), Resource::kEnvironment) != reads.end() &&
        pass->wanted(frame) && (fixed || has_water(frame.water()))) {
      m.timed("glass_environment", [&] {
        // render_image's pictures stand alone: their environment is drawn whole.
        const bool picture = m.image_session && &s == m.image_session->impl_.get();
        m.refresh_environment(frame, s, mirror, picture);
      });
      m.upload_frame_block(frame, view_water);
    }
    m.timed(pass->decl().name, [&] { m.run_pass(*pass, frame, s, resources); });
    if (pass == m.road) m.view_drew_relief = m.road->drew_relief();
  }
  const RainPass::Drawn rain = m.rain->take_drawn();
  m.rain_streaks = rain.streaks;
  // The rain pass's CPU layer, beside the whole pass, for the budget table.
  if (m.profiling && rain.streaks > 0) m.timings.push_back({"rain_layer", rain.layer_ms});
  // A GL error here (out of memory for a large target, a lost context) fails this view's frame,
  // and with it only its session (the scheduler's boundary).
  if (const GLenum error = glGetError(); error != GL_NO_ERROR) {
    char text[64];
    std::snprintf(text, sizeof text, "GL error 0x%04x rendering the %s view", error,
                  std::string(sim::view_name(spec.view)).c_str());
    for (int i = 0; i < 16 && glGetError() != GL_NO_ERROR; ++i) {
    }  // bounded: a lost context may report itself on every call
    throw std::runtime_error(text);
  }

  PendingReadback pending{&session, view_index, slot, nullptr, spec.width, spec.height};
  m.timed("readback_start", [&] {
    glNamedFramebufferReadBuffer(target->fbo.id(), GL_COLOR_ATTACHMENT0);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, target->fbo.id());
    glBindBuffer(GL_PIXEL_PACK_BUFFER, target->pbo[slot].id());
    glReadPixels(0, 0, spec.width, spec.height, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    GLsync fence = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
    glFlush();
    target->fence[slot] = fence;
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
  if (!pending.session) throw std::logic_error("finish() of an empty readback");
  RenderSession::Impl& s = *pending.session->impl_;
  if (static_cast<std::size_t>(pending.view_index) >= s.views.size() ||
      !s.views[pending.view_index]) {
    throw std::logic_error("finish() of a readback whose target is gone");
  }
  ViewTarget& target = *s.views[pending.view_index];
  GLsync& fence = target.fence[pending.slot];
  if (!fence || fence != pending.fence)
    throw std::logic_error("finish() of a readback not in flight");
  // A GPU that does not finish a frame in kFenceDeadline is hung or lost: the readback fails (its
  // session with it), rather than the render thread waiting forever.
  GLenum waited = GL_TIMEOUT_EXPIRED;
  const auto deadline = std::chrono::steady_clock::now() + kFenceDeadline;
  while (waited == GL_TIMEOUT_EXPIRED && std::chrono::steady_clock::now() < deadline)
    waited = glClientWaitSync(fence, GL_SYNC_FLUSH_COMMANDS_BIT, 100'000'000);
  glDeleteSync(fence);
  fence = nullptr;
  if (waited == GL_TIMEOUT_EXPIRED || waited == GL_WAIT_FAILED) {
    throw std::runtime_error(waited == GL_WAIT_FAILED
                                 ? "waiting for the GPU failed"
                                 : "the GPU did not finish a frame within " +
                                       std::to_string(kFenceDeadline.count()) + " s");
  }
  const std::size_t bytes = static_cast<std::size_t>(pending.width) * pending.height * 4;
  out.resize(bytes);
  const GLuint pbo = target.pbo[pending.slot].id();
  const void* data = glMapNamedBufferRange(pbo, 0, static_cast<GLsizeiptr>(bytes), GL_MAP_READ_BIT);
  if (!data) throw std::runtime_error("mapping the readback buffer failed");
  std::memcpy(out.data(), data, bytes);
  glUnmapNamedBuffer(pbo);
}

std::vector<std::uint8_t> Renderer::render_image(const sim::ViewSpec& spec,
                                                 const sim::SceneState& scene) {
  if (!impl_->image_session) impl_->image_session = open_session();
  // A picture of this scene alone: the world outside the glass drawn for it, not a session's
  // earlier ticks.
  if (!impl_->fixed_environment) impl_->image_session->impl_->environment.reset();
  const PendingReadback pending = render(*impl_->image_session, 0, spec, scene);
  std::vector<std::uint8_t> bottom_up;
  finish(pending, bottom_up);
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
