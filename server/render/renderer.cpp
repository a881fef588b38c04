// The renderer: the GL context, the passes and each view as lists of them (view_passes.hpp), and a
// frame: its lamps, its frame block, the frame passes (the lamp map, the road reflection), the
// world outside the glass where a pass reads it, the view's passes, and the readback.
#include "server/render/renderer.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdio>
#include <cstring>
#include <memory>
#include <optional>
#include <stdexcept>

#include <spdlog/spdlog.h>

#include "server/render/cpu/shader_interface.hpp"
#include "server/render/cpu/spray_splat.hpp"
#include "server/render/environment_probe.hpp"
#include "server/render/frame_block.hpp"
#include "server/render/frame_context.hpp"
#include "server/render/frame_lamps.hpp"
#include "server/render/pass.hpp"
#include "server/render/passes/cockpit_pass.hpp"
#include "server/render/passes/glass_composite_pass.hpp"
#include "server/render/passes/lamp_map_pass.hpp"
#include "server/render/passes/rain_pass.hpp"
#include "server/render/passes/road_pass.hpp"
#include "server/render/passes/road_reflection_pass.hpp"
#include "server/render/passes/spray_mirror_pass.hpp"
#include "server/render/passes/spray_pass.hpp"
#include "server/render/render_session.hpp"
#include "server/render/render_targets.hpp"
#include "server/render/sky_table.hpp"
#include "server/render/view_passes.hpp"
#include "server/render/world.hpp"
#include "server/sim/pose.hpp"

namespace downpour::render {
namespace {

constexpr std::chrono::seconds kFenceDeadline{10};

// Water on the glass to refract the world outside (the blades alone need none of it).
bool has_water(const sim::WindshieldState& water) {
  return water.surface && !water.surface->bodies.empty();
}

bool lists(const std::vector<Pass*>& passes, const Pass* pass) {
  return std::find(passes.begin(), passes.end(), pass) != passes.end();
}

std::size_t index(Resource r) { return static_cast<std::size_t>(r); }

// A GL error (out of memory for a large target, a lost context) fails the view's frame, and with
// it only its session (the scheduler's boundary).
void throw_gl_error(sim::View view) {
  const GLenum error = glGetError();
  if (error == GL_NO_ERROR) return;
  char text[64];
  std::snprintf(text, sizeof text, "GL error 0x%04x rendering the %s view", error,
                std::string(sim::view_name(view)).c_str());
  for (int i = 0; i < 16 && glGetError() != GL_NO_ERROR; ++i) {
  }  // bounded: a lost context may report itself on every call
  throw std::runtime_error(text);
}

}  // namespace

// A view between begin() and end(): its frame, its target, and where its passes stand.
struct Renderer::ViewFrame::State {
  explicit State(const sim::ViewSpec& spec) : spec(spec) {}
  // A rain layer still being built for the frame reads its rain: it is waited for, however the
  // frame ends (a throw in a pass, or in the scheduler between begin() and end()).
  ~State() {
    if (rain_pass && frame) rain_pass->finish_build(*frame);
  }
  const sim::ViewSpec& spec;
  RenderSession* session = nullptr;
  int view_index = 0;
  ViewTarget* target = nullptr;
  int slot = 0;
  std::optional<FrameContext> frame;
  FrameResources resources;
  Mirror mirror;
  bool reflection = false;
  bool fixed = false;  // COCKPIT before the fixed environment (tests)
  bool wants_clean = false;
  bool clean_taken = false;
  bool lamp_map_stale = false;  // the lamp map holds another view's
  const std::vector<Pass*>* passes = nullptr;
  std::size_t next_pass = 0;  // the first of `passes` that end() draws
  std::uint64_t begun = 0;    // its serial: Renderer::Impl::views_begun when it began
  std::array<bool, kResourceCount> written{};
  std::vector<PassTiming> timings;
  RainPass::Drawn rain;           // what its rain pass drew
  RainPass* rain_pass = nullptr;  // the pass building its layer (RainPass::start)
  bool ended = false;
};

struct Renderer::Impl {
  std::unique_ptr<EglContext> context;
  std::unique_ptr<SharedResources> shared;
  Worlds worlds;  // what is drawn of each road network
  std::unique_ptr<FrameBlockBuffer> block;
  std::unique_ptr<FrameLamps> lamps;
  bool lamps_on = true;
  ViewPasses passes;
  EnvironmentConfig environment_config;
  std::unique_ptr<EnvironmentPrograms> environment_programs;
  // The water layer's least reduction where the lens blurs at all, and how much wider than tall
  // its pixels are where the blur spans two pixels or more (GlassView): on a CPU rasterizer
  // (llvmpipe), which pays for every pixel of it, 2 and 1.375 (1280x720: a 466x360 layer; the
  // drops' inversion and brightening over the grass kept or better than at 1, and 1.5 lost the
  // brightening); on a GPU 1 and 1 (square, as sharp as the blur).
  int min_glass_layer_scale = 1;
  int view_pictures = 1;  // a view's colour and depth targets (ViewTarget::pictures)
  double glass_layer_widening = 1.0;
  std::optional<std::array<std::vector<glm::vec3>, EnvironmentProbe::kFaces>> fixed_environment;

  std::unique_ptr<SkyTable> sky;
  TransientTargets transients;
  std::array<bool, kResourceCount> written{};  // this frame's
  bool profiling = false;
  std::vector<PassTiming> timings;
  std::uint64_t frame = 0;                       // frames rendered, for the transients' use
  std::unique_ptr<RenderSession> image_session;  // render_image's
  bool view_drew_relief = false;   // the view's road pass (not the environment's faces)
  std::uint32_t rain_streaks = 0;  // drawn by the last render()
  std::uint64_t views_begun = 0;
  // The views (their serials) whose lamps, frame block and sky are set, and whose lamp map the
  // lamp map pass holds.
  std::uint64_t lamps_of = 0, lamp_map_of = 0;

  template <typename Fn>
  void timed(const std::string& name, Fn&& fn) {
    const auto t0 = std::chrono::steady_clock::now();
    fn();
    if (profiling) glFinish();
    timings.push_back(
        {name,
         std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count()});
  }

  // The session's environment probe brought up to this tick: the faces due, each drawn by the
  // world passes from the probe's centre just outside the glass, then made linear with the sun
  // and the lamps. The first view of a tick refreshes it; the others share it. The view's frame
  // block is restored after.
  void refresh_environment(const FrameContext& f, RenderSession::Impl& s, bool complete) {
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
    // Geometry's detail as the faces' texels call for (a 90-degree face of `size` texels).
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
      ff.detail_distance_scale = detail_distance_scale(face_texel);
      ff.picture_camera = &f.camera;
      block->upload(ff, water_block(ff, block->view_water().mirror, false));
      apply(RenderState{DepthTest::kOff, true, Blend::kOff});
      glClearNamedFramebufferfv(r.view_fbo, GL_COLOR, 0, black);
      glClearNamedFramebufferfv(r.view_fbo, GL_DEPTH, 0, &zero_depth);
      if (f.spec.background == sim::Background::kClient) {
        for (Pass* pass : passes.client_environment) run_pass(*pass, ff, s, r);
      } else {
        for (Pass* pass : passes.environment) {
          if (world || pass == passes.environment.back()) run_pass(*pass, ff, s, r);  // (the sky)
        }
      }
      probe.resolve(*environment_programs, face, axes, f.atmosphere,
                    static_cast<int>(lamps->fields().params.w));
    }
    block->restore_view();
  }

  // The texture a pass finds `res` at, where the renderer binds it before the pass runs.
  void bind_read(Resource res, const FrameContext& f, RenderSession::Impl& session,
                 FrameResources& r) {
    GLuint texture = 0;
    switch (res) {
      case Resource::kViewColour:
        texture = r.view_colour.texture;
        break;
      case Resource::kViewDepth:
        texture = r.view_depth.texture;
        break;
      case Resource::kGlassLayer:
      case Resource::kRoadLayer:
      case Resource::kSprayLayer:
      case Resource::kSprayMaps:
      case Resource::kSprayBodyFront:
      case Resource::kSprayHaze:
        texture = r.transient(res).colour.texture;
        break;
      case Resource::kRoadReflection:
        texture = r.transient(res).colour.texture;
        glBindTextureUnit(texture_unit::kReflectionDepth, r.transient(res).depth.texture);
        break;
      case Resource::kGlassSurface:
        session.upload_glass_surface(f.water().surface);
        return;  // bound to their units there
      case Resource::kEnvironment: {
        const EnvironmentProbe* probe = session.environment.get();
        texture = probe ? probe->texture() : 0;
        const int size = probe ? probe->config().face_size : 0;
        r.environment = {texture, size, size};
        r.environment_from_world = probe ? probe->from_world(f.vehicle_to_world) : glm::mat3(1.0f);
        break;
      }
      case Resource::kRoadWater:
        texture = session.upload_road_water(f.scene.road_water);
        break;
      case Resource::kLampMap:
        texture = passes.lamp_map->texture();
        break;
      case Resource::kClientImage: {
        // The picture's depth made the view's reversed-Z with its camera's near plane.
        const Camera& camera = f.picture_camera_or_own();
        const RenderSession::Impl::ClientPicture& p = session.upload_client_image(
            f.spec.view, f.scene.client_images[static_cast<std::size_t>(f.spec.view)],
            camera.near_m);
        r.client_colour = {p.colour.id(), p.width, p.height};
        r.client_depth =
            p.has_depth ? TargetTexture{p.depth.id(), p.width, p.height} : TargetTexture{};
        return;  // bound to their units there
      }
    }
    glBindTextureUnit(resource_info(res).texture_unit, texture);
  }

  // A transient's size for a frame of this view.
  static glm::ivec2 transient_size(const ResourceInfo& info, const FrameContext& f) {
    const int w = f.spec.width, h = f.spec.height, k = info.scale;
    return k == kGlassLayerSize
               ? f.glass.layer_size(w, h)
               : glm::ivec2(std::max(1, (w + k - 1) / k), std::max(1, (h + k - 1) / k));
  }

  // For a view of a new size: the transients its passes write, and the spray's CPU buffers, made
  // now rather than when the first water or spray shows (a session's memory is taken when its
  // views are).
  // The passes of a view: its background's.
  const std::vector<Pass*>& view_list(const sim::ViewSpec& spec) const {
    const int v = static_cast<int>(spec.view);
    return spec.background == sim::Background::kClient ? passes.client_views[v] : passes.views[v];
  }

  void prepare(const FrameContext& f) {
    const auto& list = view_list(f.spec);
    for (const Pass* pass : list) {
      for (Resource res : pass->decl().writes) {
        const ResourceInfo& info = resource_info(res);
        if (info.scale == kNotTransient) continue;
        const glm::ivec2 size = transient_size(info, f);
        transients.get(res, size.x, size.y, frame);
      }
    }
    if (lists(list, passes.spray)) passes.spray->prepare(f.spec.width, f.spec.height);
  }

  // The framebuffer a pass writes: the view's, a transient made as the resource table says
  // (cleared by its first pass of the frame), or the pass's own (it binds them).
  void bind_target(Resource out, const FrameContext& f, FrameResources& r, bool clear = true) {
    const ResourceInfo& info = resource_info(out);
    if (info.view_target) {
      glBindFramebuffer(GL_FRAMEBUFFER, r.view_fbo);
      glViewport(0, 0, r.view_colour.width, r.view_colour.height);
      return;
    }
    if (info.scale == kNotTransient) return;
    const glm::ivec2 size = transient_size(info, f);
    Transient& t = transients.get(out, size.x, size.y, frame);
    GLuint depth = t.depth.id();
    if (info.depth_from && *info.depth_from != out) {  // another's (drawn before: check_pass_order)
      const Transient& owner = transients.get(*info.depth_from, size.x, size.y, frame);
      TransientTargets::attach_depth(t, owner);
      depth = owner.depth.id();
    }
    r.transients[index(out)] = {
        {t.texture.id(), t.width, t.height}, {depth, t.width, t.height}, t.fbo.id()};
    glBindFramebuffer(GL_FRAMEBUFFER, t.fbo.id());
    glViewport(0, 0, t.width, t.height);
    if (written[index(out)] || !clear) return;
    glClearNamedFramebufferfv(t.fbo.id(), GL_COLOR, 0, info.clear_colour.data());
    if (t.depth.id()) {
      glDepthMask(GL_TRUE);  // (a depth clear obeys the depth mask)
      glClearNamedFramebufferfv(t.fbo.id(), GL_DEPTH, 0, &info.clear_depth);
    }
  }

  void run_pass(Pass& pass, const FrameContext& f, RenderSession::Impl& session,
                FrameResources& r) {
    if (!pass.wanted(f)) return;
    const PassDecl& d = pass.decl();
    // A transient of the view's passes that none of them drew this frame (its pass had nothing to
    // draw) leaves its readers nothing to draw either.
    for (Resource res : d.reads) {
      const ResourceInfo& info = resource_info(res);
      if (info.scale != kNotTransient && !info.from_frame && !written[index(res)]) return;
    }
    for (Resource res : d.reads) bind_read(res, f, session, r);
    bind_target(d.writes.front(), f, r, !pass.overwrites_target(f));
    apply(d.state);
    pass.execute(f, r);
    // Clears outside the passes heed the colour mask: it is left on.
    if (!d.state.colour_write) glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    for (Resource res : d.writes) written[index(res)] = true;
  }
  // What view v's passes read of the renderer's own: its lamps (FrameLamps, and the frame block's
  // share), its frame block and its sky.
  void set_view(ViewFrame::State& v) {
    FrameContext& frame = *v.frame;
    timed("lamps", [&] {
      lamps->prepare(frame, lamps_on, lists(frame_passes(v.spec), passes.lamp_map));
      block->set_lamps(lamps->fields());
    });
    block->upload_view(frame, water_block(frame, v.mirror, v.reflection));
    sky->show(frame.atmosphere);
    lamps_of = v.begun;
  }

  // The passes a view draws before its own (none over a client's picture).
  const std::vector<Pass*>& frame_passes(const sim::ViewSpec& spec) const {
    static const std::vector<Pass*> kNone;
    return spec.background == sim::Background::kClient ? kNone
                                                       : passes.frame[static_cast<int>(spec.view)];
  }

  // The ground truth's clean frame: the view as it stands (before its water).
  void take_clean(ViewFrame::State& v) {
    timed("clean_copy", [&] {
      glCopyImageSubData(v.resources.view_colour.texture, GL_TEXTURE_2D, 0, 0, 0, 0,
                         v.target->truth->clean.id(), GL_TEXTURE_2D, 0, 0, 0, 0, v.spec.width,
                         v.spec.height, 1);
    });
    v.clean_taken = true;
  }

  // One of a view's passes, with what comes before it (the clean frame, the world outside the
  // glass) and after it (the clean frame's blades).
  void run_view_pass(ViewFrame::State& v, Pass* pass) {
    FrameContext& frame = *v.frame;
    RenderSession::Impl& s = *v.session->impl_;
    // The clean frame is the view before the first pass that adds water.
    if (v.wants_clean && !v.clean_taken &&
        std::find(passes.water.begin(), passes.water.end(), pass) != passes.water.end())
      take_clean(v);
    // The world outside the glass, for the first pass that reads it and has something to draw
    // (it waits for the step, as that pass would).
    const auto& reads = pass->decl().reads;
    if (std::find(reads.begin(), reads.end(), Resource::kEnvironment) != reads.end() &&
        pass->wanted(frame) && (v.fixed || has_water(frame.water()))) {
      timed("glass_environment", [&] {
        if (v.lamp_map_stale) {  // the faces' ground is lit by this view's lamp map
          run_pass(*passes.lamp_map, frame, s, v.resources);
          v.lamp_map_stale = false;
          lamp_map_of = v.begun;
        }
        // render_image's pictures stand alone: their environment is drawn whole.
        const bool picture = image_session && &s == image_session->impl_.get();
        refresh_environment(frame, s, picture);
      });
    }
    timed(pass->decl().name, [&] { run_pass(*pass, frame, s, v.resources); });
    if (pass == passes.road || pass == passes.road_layer)
      view_drew_relief = static_cast<const RoadPass*>(pass)->drew_relief();
    if (pass == passes.road_far) view_drew_relief |= passes.road_far->drew_relief();
    // The glass without its water keeps its blades.
    if (v.wants_clean && pass == static_cast<Pass*>(passes.glass_composite) &&
        pass->wanted(frame)) {
      timed("clean_blades", [&] {
        glBindFramebuffer(GL_FRAMEBUFFER,
                          v.target->truth->clean_fbo[v.target->picture(v.slot)].id());
        apply(pass->decl().state);
        passes.glass_composite->draw_blades(frame);
        glBindFramebuffer(GL_FRAMEBUFFER, v.resources.view_fbo);
      });
    }
  }
};

Renderer::Renderer(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
Renderer::~Renderer() = default;

std::unique_ptr<Renderer> Renderer::create(const RendererOptions& options) {
  auto impl = std::make_unique<Impl>();
  impl->context = EglContext::create(options.platform);
  const bool cpu_rasterizer = impl->context->renderer().find("llvmpipe") != std::string::npos ||
                              impl->context->renderer().find("softpipe") != std::string::npos;
  if (cpu_rasterizer) {
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

  impl->shared = make_shared_resources();
  impl->sky = std::make_unique<SkyTable>();
  impl->worlds.get(nullptr);  // the built-in track's, before the first frame
  impl->block = std::make_unique<FrameBlockBuffer>();
  impl->lamps = std::make_unique<FrameLamps>();
  impl->environment_programs = std::make_unique<EnvironmentPrograms>();
  impl->passes = make_view_passes(*impl->shared, *impl->block, *impl->lamps, smoothing,
                                  options.road_at_half.value_or(cpu_rasterizer),
                                  options.keep_cabin.value_or(cpu_rasterizer));
  // Kept cabins are copied into a picture of the view's that nothing draws into any longer.
  impl->view_pictures = options.keep_cabin.value_or(cpu_rasterizer) ? kReadbackSlots : 1;
  if (glGetError() != GL_NO_ERROR) throw std::runtime_error("GL error while creating the renderer");
  return std::unique_ptr<Renderer>(new Renderer(std::move(impl)));
}

const std::string& Renderer::gl_renderer() const { return impl_->context->renderer(); }
const std::string& Renderer::platform() const { return impl_->context->platform(); }
Renderer::CabinCounts Renderer::cabin_counts() const {
  const CockpitPass::Counts& c = impl_->passes.cockpit->counts();
  return {c.restored, c.drawn, c.kept};
}
void Renderer::set_profiling(bool on) { impl_->profiling = on; }
void Renderer::set_spray_smoothing(SpraySmoothing smoothing) {
  impl_->passes.spray_smooth->set_smoothing(smoothing);
}
SpraySmoothing Renderer::spray_smoothing() const { return impl_->passes.spray_smooth->smoothing(); }
void Renderer::set_relief_shadows(bool on) {
  impl_->passes.road->set_relief_shadows(on);
  for (RoadPass* part : {impl_->passes.road_layer, impl_->passes.road_far}) {
    if (part) part->set_relief_shadows(on);
  }
}
void Renderer::set_lamps(bool on) { impl_->lamps_on = on; }
void Renderer::set_spray_in_mirror(bool on) { impl_->passes.spray_mirror->set_on(on); }
bool Renderer::last_drew_relief() const { return impl_->view_drew_relief; }
void Renderer::set_spray_cpu_splat(bool cpu) { impl_->passes.spray->set_cpu_splat(cpu); }
bool Renderer::spray_cpu_splat() const { return impl_->passes.spray->cpu_splat(); }
std::vector<float> Renderer::smooth_spray_body(int width, int height, float tan_x, float tan_y,
                                               const std::vector<float>& front) {
  if (width <= 0 || height <= 0 || front.size() != static_cast<std::size_t>(width) * height)
    throw std::invalid_argument("smooth_spray_body: the depths do not fill the size");
  Impl& m = *impl_;
  // The body's front and its mask into the spray's maps, as the spray pass leaves them.
  std::vector<glm::vec4> depth(front.size(), glm::vec4(kSprayFar));
  std::vector<float> mask(front.size(), 0.0f);
  for (std::size_t i = 0; i < front.size(); ++i) {
    depth[i].x = front[i];
    if (front[i] < 0.5f * kSprayFar) mask[i] = kSprayMaskBody;
  }
  Transient& maps = m.transients.get(Resource::kSprayMaps, width, height, m.frame);
  Transient& out = m.transients.get(Resource::kSprayBodyFront, width, height, m.frame);
  TransientTargets::attach_depth(out, maps);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
  glTextureSubImage2D(maps.texture.id(), 0, 0, 0, width, height, GL_RGBA, GL_FLOAT, depth.data());
  glTextureSubImage2D(maps.depth.id(), 0, 0, 0, width, height, GL_DEPTH_COMPONENT, GL_FLOAT,
                      mask.data());
  const float far[4] = {kSprayFar, kSprayFar, kSprayFar, kSprayFar};
  glClearNamedFramebufferfv(out.fbo.id(), GL_COLOR, 0, far);
  const FrameTarget maps_target{
      {maps.texture.id(), width, height}, {maps.depth.id(), width, height}, maps.fbo.id()};
  const FrameTarget out_target{
      {out.texture.id(), width, height}, {maps.depth.id(), width, height}, out.fbo.id()};
  apply(m.passes.spray_smooth->decl().state);
  m.passes.spray_smooth->smooth(maps_target, out_target, {glm::vec4(0.0f, 0.0f, 1.0f, 1.0f)},
                                glm::vec2(tan_x, tan_y));
  std::vector<float> z(front.size());
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glGetTextureImage(out.texture.id(), 0, GL_RED, GL_FLOAT,
                    static_cast<GLsizei>(z.size() * sizeof(float)), z.data());
  return z;
}
std::array<std::uint32_t, 3> Renderer::last_spray_drawn() const {
  const SprayPass::Drawn& d = impl_->passes.spray->drawn();
  return {d.body, d.spray, d.haze};
}
const std::vector<PassTiming>& Renderer::last_pass_timings() const { return impl_->timings; }
std::uint32_t Renderer::last_rain_streaks() const { return impl_->rain_streaks; }

void Renderer::release_shared_targets() {
  impl_->transients.clear();
  impl_->passes.cockpit->release();
}

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

Renderer::ViewFrame::ViewFrame(std::unique_ptr<State> state) : state_(std::move(state)) {}
Renderer::ViewFrame::~ViewFrame() = default;

PendingReadback Renderer::render(RenderSession& session, int view_index, const sim::ViewSpec& spec,
                                 const sim::SceneState& scene, const StepSource& stepped) {
  const std::unique_ptr<ViewFrame> view = begin(session, view_index, spec, scene, stepped);
  return end(*view);
}

std::unique_ptr<Renderer::ViewFrame> Renderer::begin(RenderSession& session, int view_index,
                                                     const sim::ViewSpec& spec,
                                                     const sim::SceneState& scene,
                                                     const StepSource& stepped, bool rain_ahead) {
  Impl& m = *impl_;
  RenderSession::Impl& s = *session.impl_;
  m.timings.clear();
  if (view_index < 0) throw std::logic_error("negative view index");
  if (s.views.size() <= static_cast<std::size_t>(view_index)) s.views.resize(view_index + 1);
  auto& target = s.views[view_index];
  const bool new_target = !target || target->width != spec.width || target->height != spec.height;
  if (new_target) {
    if (target && target->busy())
      throw std::logic_error("render target resized with a readback in flight");
    target = std::make_unique<ViewTarget>(spec.width, spec.height, m.view_pictures);
  }
  const int slot = target->next_slot;
  target->next_slot = (slot + 1) % kReadbackSlots;
  if (target->fence[slot]) throw std::logic_error("readback slot reused before finish()");

  auto view = std::make_unique<ViewFrame::State>(spec);
  ViewFrame::State& v = *view;
  v.session = &session;
  v.view_index = view_index;
  v.target = target.get();
  v.slot = slot;
  v.begun = ++m.views_begun;
  const Camera camera = make_camera(spec, scene.vehicle, &scene.weather);
  // Ground truth: the clean frame (for itself or the water mask) and the depth.
  v.wants_clean = spec.outputs.needs_clean();
  if (spec.outputs.any() && !target->truth) {
    target->truth = std::make_unique<GroundTruthTarget>(spec.width, spec.height, target->depth,
                                                        target->pictures);
  }
  v.frame.emplace(FrameContext{
      scene, spec, camera, atmosphere_from(scene.weather),
      glm::mat4(sim::vehicle_to_world(scene.vehicle)),
      GlassView(camera, scene.glass, spec.height, m.min_glass_layer_scale, m.glass_layer_widening),
      stepped});
  FrameContext& frame = *v.frame;
  frame.world = &m.worlds.get(scene.roads);
  frame.detail_distance_scale =
      detail_distance_scale(2.0 * camera.tan_half_fov_y / std::max(spec.height, 1));
  if (new_target) m.prepare(frame);
  FrameResources& resources = v.resources;
  const int picture = target->picture(slot);
  resources.view_fbo = target->fbo[picture].id();
  resources.view_colour = {target->colour[picture].id(), spec.width, spec.height};
  resources.view_depth = {target->depth[picture].id(), spec.width, spec.height};
  const bool client = spec.background == sim::Background::kClient;
  v.fixed = m.fixed_environment && spec.view == sim::View::kCockpit && !client;
  v.passes = v.fixed ? &m.passes.fixed_environment_cockpit : &m.view_list(spec);
  // A view that starts with the cabin may start from its kept picture, in place of the clear
  // (before the target is bound: a target bound counts as one being drawn into).
  const bool restored = !v.passes->empty() && v.passes->front() == m.passes.cockpit &&
                        m.passes.cockpit->restore(frame, resources);
  glBindFramebuffer(GL_FRAMEBUFFER, resources.view_fbo);
  glViewport(0, 0, spec.width, spec.height);
  if (!restored) clear_view(resources.view_fbo);
  ++m.frame;
  m.transients.evict();
  m.written.fill(false);
  const std::vector<Pass*>& frame_passes = m.frame_passes(spec);
  v.reflection = lists(frame_passes, m.passes.reflection) && m.passes.reflection->wanted(frame);
  // Profiling: the clears and the frame's uploads finish here, not in the first step's time.
  if (m.profiling) m.timed("clear", [] {});
  v.mirror = mirror_under(scene.roads ? *scene.roads : *sim::built_in_roads(), scene.vehicle);
  m.set_view(v);
  for (Pass* pass : frame_passes)
    m.timed(pass->decl().name, [&] { m.run_pass(*pass, frame, s, resources); });
  if (lists(frame_passes, m.passes.lamp_map)) m.lamp_map_of = v.begun;
  // The passes that need only the frame's inputs: those before the first that reads the step.
  // With rain_ahead the rain's layer is built meanwhile, on the CPU, on threads of its own. Where
  // the layer is not built yet when its pass comes, that pass and those after it wait for end(),
  // so that this thread draws the next view's passes meanwhile (each view's passes keep their
  // order).
  m.passes.rain->take_drawn();
  if (rain_ahead && lists(*v.passes, m.passes.rain)) {
    v.rain_pass = m.passes.rain;
    m.passes.rain->start(frame);
  }
  while (v.next_pass < v.passes->size()) {
    Pass* pass = (*v.passes)[v.next_pass];
    if (pass->decl().reads_step || (pass == m.passes.rain && !m.passes.rain->built(frame))) break;
    m.run_view_pass(v, pass);
    ++v.next_pass;
  }
  // To the rasterizer now, before this thread waits for the step or draws another view:
  // llvmpipe bins a frame's draws and rasterizes them only once they are flushed, so a core would
  // otherwise idle through the wait (in the demo, a fifth of the tick).
  glFlush();
  throw_gl_error(spec.view);  // this view's, not the next one's to check
  v.rain = m.passes.rain->take_drawn();
  v.written = m.written;
  v.timings = std::move(m.timings);
  m.timings.clear();
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  return std::unique_ptr<ViewFrame>(new ViewFrame(std::move(view)));
}

PendingReadback Renderer::end(ViewFrame& view) {
  Impl& m = *impl_;
  ViewFrame::State& v = *view.state_;
  if (v.ended) throw std::logic_error("a view ended twice");
  v.ended = true;
  FrameContext& frame = *v.frame;
  const sim::ViewSpec& spec = v.spec;
  ViewTarget& target = *v.target;
  m.written = v.written;
  m.timings = std::move(v.timings);
  glBindFramebuffer(GL_FRAMEBUFFER, v.resources.view_fbo);
  glViewport(0, 0, spec.width, spec.height);
  // Passes left to draw (the glass's, and the rain's and the spray's where begin() left them)
  // after another view began or ended since this one began: this one's lamps, blocks and sky
  // again; its lamp map only if a face of the environment is drawn (run_view_pass). A view with
  // none left only starts its readback.
  if (v.next_pass < v.passes->size()) {
    if (m.lamps_of != v.begun) m.set_view(v);
    v.lamp_map_stale = lists(m.frame_passes(spec), m.passes.lamp_map) && m.lamp_map_of != v.begun;
  }
  m.passes.rain->take_drawn();
  while (v.next_pass < v.passes->size()) m.run_view_pass(v, (*v.passes)[v.next_pass++]);
  if (v.wants_clean && !v.clean_taken) m.take_clean(v);  // a view that adds no water
  // The rain pass, where begin() left it to this.
  if (const RainPass::Drawn late = m.passes.rain->take_drawn(); late.streaks > 0) v.rain = late;
  const RainPass::Drawn& rain = v.rain;
  m.rain_streaks = rain.streaks;
  // The rain pass's CPU layer, beside the whole pass, for the budget table.
  if (m.profiling && rain.streaks > 0) m.timings.push_back({"rain_layer", rain.layer_ms});
  throw_gl_error(spec.view);

  const int slot = v.slot;
  PendingReadback pending{v.session,  v.view_index, slot,         nullptr,
                          spec.width, spec.height,  spec.outputs, frame.camera.near_m};
  m.timed("readback_start", [&] {
    glPixelStorei(GL_PACK_ALIGNMENT, 4);
    glNamedFramebufferReadBuffer(v.resources.view_fbo, GL_COLOR_ATTACHMENT0);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, v.resources.view_fbo);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, target.pbo[slot].id());
    glReadPixels(0, 0, spec.width, spec.height, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
    if (spec.outputs.depth) {
      glBindBuffer(GL_PIXEL_PACK_BUFFER, target.truth->depth_pbo[slot].id());
      glReadPixels(0, 0, spec.width, spec.height, GL_DEPTH_COMPONENT, GL_FLOAT, nullptr);
    }
    if (v.wants_clean) {
      glNamedFramebufferReadBuffer(target.truth->clean_fbo[target.picture(slot)].id(),
                                   GL_COLOR_ATTACHMENT0);
      glBindFramebuffer(GL_READ_FRAMEBUFFER, target.truth->clean_fbo[target.picture(slot)].id());
      glBindBuffer(GL_PIXEL_PACK_BUFFER, target.truth->clean_pbo[slot].id());
      glReadPixels(0, 0, spec.width, spec.height, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
    }
    glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    GLsync fence = glFenceSync(GL_SYNC_GPU_COMMANDS_COMPLETE, 0);
    glFlush();
    target.fence[slot] = fence;
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

namespace {

// A readback buffer's first `bytes`, mapped, handed to `use`.
template <typename Use>
void read_buffer(GLuint pbo, std::size_t bytes, Use&& use) {
  const void* data = glMapNamedBufferRange(pbo, 0, static_cast<GLsizeiptr>(bytes), GL_MAP_READ_BIT);
  if (!data) throw std::runtime_error("mapping the readback buffer failed");
  use(data);
  glUnmapNamedBuffer(pbo);
}

}  // namespace

void Renderer::finish(const PendingReadback& pending, std::vector<std::uint8_t>& out,
                      GroundTruthPixels* truth) {
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
  const std::size_t pixels = static_cast<std::size_t>(pending.width) * pending.height;
  out.resize(pixels * 4);
  read_buffer(target.pbo[pending.slot].id(), out.size(),
              [&](const void* data) { std::memcpy(out.data(), data, out.size()); });
  if (!truth) return;
  if (!pending.outputs.needs_clean()) truth->clean.clear();
  if (!pending.outputs.depth) truth->depth_m.clear();
  if (pending.outputs.needs_clean()) {
    truth->clean.resize(pixels * 4);
    read_buffer(target.truth->clean_pbo[pending.slot].id(), truth->clean.size(),
                [&](const void* data) { std::memcpy(truth->clean.data(), data, pixels * 4); });
  }
  if (pending.outputs.depth) {
    truth->depth_m.resize(pixels);
    read_buffer(target.truth->depth_pbo[pending.slot].id(), pixels * sizeof(float),
                [&](const void* data) {
                  const auto* z = static_cast<const float*>(data);
                  for (std::size_t i = 0; i < pixels; ++i)
                    truth->depth_m[i] = distance_from_reversed_z(pending.near_m, z[i]);
                });
  }
}

std::vector<std::uint8_t> Renderer::render_image(const sim::ViewSpec& spec,
                                                 const sim::SceneState& scene) {
  GroundTruthPixels unused;
  sim::ViewSpec plain = spec;
  plain.outputs = {};
  return render_image(plain, scene, unused);
}

std::vector<std::uint8_t> Renderer::render_image(const sim::ViewSpec& spec,
                                                 const sim::SceneState& scene,
                                                 GroundTruthPixels& truth) {
  if (!impl_->image_session) impl_->image_session = open_session();
  // A picture of this scene alone: the world outside the glass drawn for it, not a session's
  // earlier ticks.
  if (!impl_->fixed_environment) impl_->image_session->impl_->environment.reset();
  const PendingReadback pending = render(*impl_->image_session, 0, spec, scene);
  std::vector<std::uint8_t> bottom_up;
  finish(pending, bottom_up, &truth);
  auto flip = [&spec](auto& image, std::size_t row) {
    for (int y = 0; y < spec.height / 2; ++y) {
      std::swap_ranges(image.begin() + y * row, image.begin() + (y + 1) * row,
                       image.begin() + (spec.height - 1 - y) * row);
    }
  };
  const std::size_t row = static_cast<std::size_t>(spec.width) * 4;
  flip(bottom_up, row);
  if (!truth.clean.empty()) flip(truth.clean, row);
  if (!truth.depth_m.empty()) flip(truth.depth_m, static_cast<std::size_t>(spec.width));
  return bottom_up;
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

float detail_distance_scale(double pixel_rad) {
  static const double reference = 2.0 * std::tan(30.0 * 3.14159265358979 / 180.0) / 720.0;
  return static_cast<float>(std::max(pixel_rad / reference, 1.0));
}

}  // namespace downpour::render
